// The words every front end answers and logs with (frontend/answers.hpp): a request's answer from
// its outcome, resume's and clear_errors' answers, set_motion_mode's numbers and its refusal
// listing the modes valid on the chassis, the start-up protocol lines, the parameter check's
// problems, and the sim/inject lines. The ROS nodes' use of them is their own suites'.
#include <gtest/gtest.h>

#include "ranger_can/frontend/answers.hpp"
#include "ranger_can/wire/profile.hpp"

namespace ranger {
namespace {

using State = RequestOutcome::State;

RequestOutcome outcome(State state, std::string message = "") {
  RequestOutcome o;
  o.state = state;
  o.message = std::move(message);
  return o;
}

TEST(Answers, ARequestIsASuccessOnlyOnceAnsweredAndSaysWhatItReached) {
  const auto answered = answer_of(outcome(State::kAnswered, "park engaged"), "park not confirmed");
  EXPECT_TRUE(answered.success);
  EXPECT_EQ(answered.message, "park engaged");
  const auto sent = answer_of(outcome(State::kSent), "park not confirmed in time");
  EXPECT_FALSE(sent.success);
  EXPECT_EQ(sent.message, "park not confirmed in time (sent)");
  const auto failed = answer_of(outcome(State::kFailed, "park: unsupported"), "x");
  EXPECT_FALSE(failed.success);
  EXPECT_EQ(failed.message, "park: unsupported");
}

TEST(Answers, ResumeIsRefusedOfflineNamingThePortAndSaysReArmedOnceAnswered) {
  DriverSnapshot s;
  s.bus_open = false;
  s.bus_error = "No such device";
  const auto refused = resume_refused_offline(s, "can7");
  ASSERT_TRUE(refused);
  EXPECT_FALSE(refused->success);
  EXPECT_EQ(refused->message, "resume refused: not connected to can7: No such device");
  s.bus_open = true;
  EXPECT_FALSE(resume_refused_offline(s, "can7"));
  EXPECT_EQ(resume_answer(outcome(State::kAnswered)).message,
            "re-armed: cmd_vel drives the chassis again");
  const auto active = resume_answer(outcome(State::kFailed, "resume refused: still active: x"));
  EXPECT_FALSE(active.success);
  EXPECT_EQ(active.message, "resume refused: still active: x");
}

TEST(Answers, ClearErrorsNamesTheWordTheChassisAnsweredWith) {
  auto o = outcome(State::kAnswered);
  o.error_word = 0;
  const auto clean = clear_errors_answer(0, o, ErrorWordLayout::kManual32);
  EXPECT_TRUE(clean.success);
  EXPECT_NE(clean.message.find("the chassis answered with error word 0x00000000 (no errors)"),
            std::string::npos)
      << clean.message;
  EXPECT_EQ(clean.message.rfind("clear_errors code 0 (", 0), 0u) << clean.message;
  const auto silent = clear_errors_answer(3, outcome(State::kSent), ErrorWordLayout::kManual32);
  EXPECT_FALSE(silent.success);
  EXPECT_NE(silent.message.find(": the chassis did not answer"), std::string::npos);
}

TEST(Answers, AnUnknownMotionModeNumberListsTheModesThisChassisDrives) {
  const std::string manual = unknown_motion_mode_number(7, manual_profile());
  EXPECT_EQ(manual.rfind("mode 7 unknown: under protocol manual use 0 (ackermann), 1 (oblique), "
                         "2 (spin) or 255 (automatic)",
                         0),
            0u)
      << manual;
  EXPECT_EQ(manual.find("side_slip"), std::string::npos);  // not valid on the manual's chassis
  EXPECT_EQ(motion_mode_pinned(protocol::MotionMode::kSpin),
            "motion mode pinned to spin (the switch happens at standstill)");
  EXPECT_EQ(motion_mode_pinned(std::nullopt), "automatic motion-mode selection");
  EXPECT_EQ(motion_mode_numbers().back().first, kAutomaticModeNumber);
}

TEST(Answers, TheProtocolSetupSaysAutoForcedOrOverridden) {
  MapParameterSource source;
  auto automatic = load_parameters(source);
  ASSERT_TRUE(automatic.ok()) << automatic.error().message;
  auto lines = describe_protocol_setup(*automatic);
  ASSERT_GE(lines.size(), 2u);
  EXPECT_EQ(lines[0].text.rfind("model ranger (", 0), 0u) << lines[0].text;
  EXPECT_EQ(lines[1].text.rfind("protocol auto: the settings are identified", 0), 0u);
  source.values["spin_sign"] = "cw";
  auto overridden = load_parameters(source);
  ASSERT_TRUE(overridden.ok()) << overridden.error().message;
  lines = describe_protocol_setup(*overridden);
  EXPECT_EQ(lines.back().severity, Severity::kWarn);
  EXPECT_NE(lines.back().text.find("spin_sign: cw"), std::string::npos) << lines.back().text;
  source.values["typo_rate"] = 3.0;
  source.values["publish_rate"] = -1.0;
  const auto problems = parameter_problems(source);
  ASSERT_EQ(problems.size(), 2u);
  EXPECT_EQ(problems[0].rfind("parameter ~typo_rate is not one ranger_base_node reads", 0), 0u)
      << problems[0];
  EXPECT_NE(problems[1].find("publish_rate"), std::string::npos) << problems[1];
}

TEST(Answers, AnInjectionIsLoggedAppliedOrRefusedWithTheValidCommands) {
  const auto applied = describe_injection("estop on", std::string("emergency stop pressed"));
  EXPECT_EQ(applied.severity, Severity::kInfo);
  EXPECT_EQ(applied.text,
            "sim/inject \"estop on\" applied to the virtual chassis: emergency stop pressed");
  const auto refused =
      describe_injection("fly", Result<std::string>(Error{Errc::kInvalidArgument, "unknown"}));
  EXPECT_EQ(refused.severity, Severity::kWarn);
  EXPECT_EQ(refused.text.rfind("sim/inject \"fly\" not applied: unknown (valid commands: ", 0), 0u)
      << refused.text;
  EXPECT_NE(refused.text.find("estop"), std::string::npos);
}

TEST(Answers, EveryRequestKindHasItsWordsForNotConfirmedInTime) {
  using K = RequestOutcome::Kind;
  auto sent = [](K kind, bool on = false) {
    RequestOutcome o = outcome(State::kSent);
    o.kind = kind;
    o.on = on;
    return request_answer(o);
  };
  EXPECT_EQ(sent(K::kPark, true).message, "park not confirmed in time (sent)");
  EXPECT_EQ(sent(K::kPark, false).message, "release not confirmed in time (sent)");
  EXPECT_EQ(sent(K::kLights).message, "the chassis did not report its lights in time (sent)");
  EXPECT_EQ(sent(K::kUltrasonic).message,
            "the chassis did not confirm the ultrasonic setting in time (sent)");
  EXPECT_EQ(sent(K::kDriveMode).message, "drive mode not confirmed in time (sent)");
  EXPECT_EQ(sent(K::kResume).message, "resume not applied (sent)");
  EXPECT_FALSE(sent(K::kClearErrors).success);
  RequestOutcome resumed = outcome(State::kAnswered);
  resumed.kind = K::kResume;
  EXPECT_EQ(request_answer(resumed).message, "re-armed: cmd_vel drives the chassis again");
  RequestOutcome failed = outcome(State::kFailed, "park: unsupported by protocol manual");
  failed.kind = K::kPark;
  EXPECT_EQ(request_answer(failed).message, "park: unsupported by protocol manual");
}

TEST(Answers, TheServicesChecksRefuseBeforeSendingInOneWording) {
  EXPECT_FALSE(ultrasonic_request_refused(true, false));
  EXPECT_EQ(ultrasonic_request_refused(true, true)->message,
            "contradictory request (enable and disable both true): set exactly one of them; "
            "nothing sent");
  EXPECT_EQ(ultrasonic_request_refused(false, false)->message,
            "empty request (neither enable nor disable): set exactly one of them; nothing sent");

  const auto lights = lights_request(2, 77, 3, 40);  // breathing (brightness ignored), custom 40
  ASSERT_TRUE(lights.ok()) << lights.error().message;
  EXPECT_EQ(lights->front, protocol::LightMode::kBreathing);
  EXPECT_EQ(lights->front_brightness, 0);
  EXPECT_EQ(lights->rear, protocol::LightMode::kCustom);
  EXPECT_EQ(lights->rear_brightness, 40);
  EXPECT_EQ(lights_request(7, 0, 1, 0).error().message,
            "front_mode 7 is not one of 0 (OFF), 1 (ON), 2 (BREATHING), 3 (CUSTOM): nothing sent");
  // A brightness is 0..100, in every front end and in the driver alike (one check).
  EXPECT_EQ(lights_request(1, 0, 3, 101).error().message,
            "rear_brightness 101 outside 0..100: nothing sent");
  EXPECT_EQ(lights_request(protocol::LightMode::kCustom, 255, protocol::LightMode::kOn, 0)
                .error()
                .message,
            "front_brightness 255 outside 0..100: nothing sent");
  EXPECT_FALSE(lights_request(1, -1, 1, 0).ok());
  EXPECT_TRUE(lights_request(3, 100, 3, 0).ok());

  EXPECT_EQ(*drive_mode_request(1), protocol::DriveMode::kVoltage);
  EXPECT_EQ(drive_mode_request(2).error().message,
            "drive mode 2 is not one of 0 (CURRENT), 1 (VOLTAGE): nothing sent");
}

TEST(Answers, EachAnswerIsOneLogLineAtItsSeverityNamingTheServiceOnce) {
  const auto ok = answer_line("resume", {true, "re-armed: cmd_vel drives the chassis again"});
  EXPECT_EQ(ok.severity, Severity::kInfo);
  EXPECT_EQ(ok.text, "resume: re-armed: cmd_vel drives the chassis again");
  const auto refused = answer_line("park", {false, "park: unsupported by protocol manual"});
  EXPECT_EQ(refused.severity, Severity::kWarn);
  EXPECT_EQ(refused.text, "park: unsupported by protocol manual");  // not "park: park: ..."
  EXPECT_EQ(answer_line("resume", {false, "resume refused: still active"}).text,
            "resume refused: still active");
  EXPECT_TRUE(is_answer_event(EventKind::kRequestSettled));
  EXPECT_TRUE(is_answer_event(EventKind::kMotionModeRequested));
  EXPECT_FALSE(is_answer_event(EventKind::kCommandRefused));
}

}  // namespace
}  // namespace ranger
