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

}  // namespace
}  // namespace ranger
