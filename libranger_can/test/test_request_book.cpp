// The driver's request book (control/request_book.hpp) on its own: numbering and capacity, what
// applying a request makes of it, and each kind's settle rule against hand-made evidence (the
// controller's state, the feedback, the lights, the firmware) at chosen times.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "ranger_can/control/request_book.hpp"

namespace ranger {
namespace {

using namespace std::chrono_literals;
using Kind = RequestOutcome::Kind;
using State = RequestOutcome::State;

bool contains(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}

// The evidence a settle rule reads, made by hand.
struct Chassis {
  ControllerState controller;
  ChassisFeedback feedback;
  std::optional<LightsState> lights;
  FirmwareVersion firmware;
  RequestEvidence at(Timestamp now) const {
    return RequestEvidence{now,     &controller, &feedback,
                           &lights, &firmware,   ErrorWordLayout::kManual32};
  }
};

// The outcome of `id` as the book shows it.
RequestOutcome outcome(const RequestBook& book, std::uint64_t id) {
  std::vector<RequestOutcome> all;
  book.copy_to(all);
  for (const RequestOutcome& r : all)
    if (r.id == id) return r;
  return RequestOutcome{};
}

TEST(RequestBook, NumbersRequestsAndKeepsTheMostRecentSixteen) {
  RequestBook book;
  for (int i = 0; i < 20; ++i)
    EXPECT_EQ(book.add(Kind::kResume, "resume"), static_cast<std::uint64_t>(i + 1));
  std::vector<RequestOutcome> all;
  book.copy_to(all);
  ASSERT_EQ(all.size(), RequestBook::kCapacity);
  EXPECT_EQ(all.front().id, 5u);
  EXPECT_EQ(all.back().id, 20u);
  EXPECT_EQ(all.back().state, State::kPending);
}

TEST(RequestBook, AppliedRequestsAreSentFailedOrForAResumeAnswered) {
  RequestBook book;
  const auto clear = book.add(Kind::kClearErrors, "clear_errors 0x00");
  const auto resume = book.add(Kind::kResume, "resume");
  const auto park = book.add(Kind::kPark, "park on", true);
  book.applied(clear, Timestamp(1s), ok_status());
  book.applied(resume, Timestamp(1s), ok_status());
  book.applied(park, Timestamp(1s), Error{Errc::kInvalidArgument, "park: unsupported"});
  EXPECT_EQ(outcome(book, clear).state, State::kSent);
  EXPECT_EQ(outcome(book, clear).sent, Timestamp(1s));
  EXPECT_EQ(outcome(book, resume).state, State::kAnswered);
  EXPECT_EQ(outcome(book, resume).message, "re-armed");
  EXPECT_EQ(outcome(book, park).state, State::kFailed);
  EXPECT_EQ(outcome(book, park).message, "park: unsupported");
  // The settled ones, once, in order.
  const auto settled = book.take_settled();
  ASSERT_EQ(settled.size(), 2u);
  EXPECT_EQ(settled[0].id, resume);
  EXPECT_EQ(settled[1].id, park);
  EXPECT_TRUE(book.take_settled().empty());
}

TEST(RequestBook, ClearErrorsIsAnsweredByTheFirst0x211AfterItsDelayElseFails) {
  RequestBook book;
  Chassis ch;
  const auto id = book.add(Kind::kClearErrors, "clear_errors 0x00");
  book.applied(id, Timestamp(1s), ok_status());
  // A 0x211 that may have left the chassis before the request reached it does not answer.
  ch.feedback.system_status = Stamped<SystemStatus>{SystemStatus{}, Timestamp(1s + 10ms), {}};
  book.settle(ch.at(Timestamp(1s + 10ms)));
  EXPECT_EQ(outcome(book, id).state, State::kSent);
  ch.controller.error_bits =
      protocol::fault_bit(protocol::Fault::kOverCurrent, ErrorWordLayout::kManual32);
  ch.feedback.system_status->received = Timestamp(1s + 20ms);
  book.settle(ch.at(Timestamp(1s + 20ms)));
  const RequestOutcome r = outcome(book, id);
  EXPECT_EQ(r.state, State::kAnswered);
  EXPECT_EQ(r.error_word, ch.controller.error_bits);
  EXPECT_EQ(r.message, "the chassis still reports: over_current");

  const auto late = book.add(Kind::kClearErrors, "clear_errors 0x00");
  book.applied(late, Timestamp(2s), ok_status());
  book.settle(ch.at(Timestamp(2s + 500ms)));
  EXPECT_EQ(outcome(book, late).state, State::kSent) << "not later than the timeout yet";
  book.settle(ch.at(Timestamp(2s + 501ms)));
  EXPECT_EQ(outcome(book, late).state, State::kFailed);
  EXPECT_TRUE(contains(outcome(book, late).message, "did not answer (no 0x211) within 0.5"));
}

TEST(RequestBook, LightsAreAnsweredWhen0x231ShowsThemElseFailSayingWhatItShows) {
  RequestBook book(RequestTiming{500ms, 5s});
  Chassis ch;
  LightsRequest want;
  want.front = protocol::LightMode::kCustom;
  want.front_brightness = 40;
  want.rear = protocol::LightMode::kOff;
  const auto id = book.add(Kind::kLights, "lights", false, want);
  book.applied(id, Timestamp(1s), ok_status());
  LightsState shown{true, protocol::LightMode::kCustom, 40, protocol::LightMode::kOff,
                    0,    Timestamp(1s + 20ms)};
  ch.lights = shown;
  book.settle(ch.at(Timestamp(1s + 20ms)));
  EXPECT_EQ(outcome(book, id).state, State::kAnswered);
  EXPECT_EQ(outcome(book, id).message, "the chassis reports front custom 40, rear off");

  const auto other = book.add(Kind::kLights, "lights", false, LightsRequest{});  // both on
  book.applied(other, Timestamp(2s), ok_status());
  ch.lights->received = Timestamp(2s + 100ms);
  ch.controller.control_mode = protocol::ControlMode::kRemote;
  book.settle(ch.at(Timestamp(2s + 501ms)));
  EXPECT_EQ(outcome(book, other).state, State::kFailed);
  EXPECT_EQ(outcome(book, other).message,
            "the chassis reports front custom 40, rear off (the remote control has the chassis)");

  const auto unheard = book.add(Kind::kLights, "lights", false, want);
  book.applied(unheard, Timestamp(3s), ok_status());
  book.settle(ch.at(Timestamp(3s + 501ms)));
  EXPECT_TRUE(contains(outcome(book, unheard).message, "did not report its lights (no 0x231)"));
}

TEST(RequestBook, ParkOnAndOffAreAnsweredByTheChassisModeOrFailNamingWhy) {
  RequestBook book(RequestTiming{500ms, 5s});
  Chassis ch;
  const auto on = book.add(Kind::kPark, "park on", true);
  book.applied(on, Timestamp(1s), ok_status());
  ch.controller.park_requested = true;
  ch.controller.refusal = MotionRefusal::kParked;
  book.settle(ch.at(Timestamp(2s)));
  EXPECT_EQ(outcome(book, on).state, State::kSent);
  ch.controller.chassis_mode = protocol::MotionMode::kPark;
  book.settle(ch.at(Timestamp(3s)));
  EXPECT_EQ(outcome(book, on).state, State::kAnswered);
  EXPECT_TRUE(contains(outcome(book, on).message, "parked (0x291 reports park)"));

  const auto off = book.add(Kind::kPark, "park off", false);
  book.applied(off, Timestamp(4s), ok_status());
  ch.controller.park_requested = false;
  book.settle(ch.at(Timestamp(5s)));
  EXPECT_EQ(outcome(book, off).state, State::kSent) << "the chassis still reports park";
  book.settle(ch.at(Timestamp(9s + 1ms)));
  EXPECT_EQ(outcome(book, off).state, State::kAnswered);
  EXPECT_TRUE(contains(outcome(book, off).message, "the chassis still reports park"));

  const auto never = book.add(Kind::kPark, "park on", true);
  book.applied(never, Timestamp(10s), ok_status());
  ch.controller.park_requested = true;
  ch.controller.chassis_mode = protocol::MotionMode::kAckermann;
  ch.controller.refusal = MotionRefusal::kEstop;
  book.settle(ch.at(Timestamp(15s + 1ms)));
  EXPECT_EQ(outcome(book, never).state, State::kFailed);
  EXPECT_TRUE(contains(outcome(book, never).message, "did not report park (0x291) within 5"));
  EXPECT_TRUE(contains(outcome(book, never).message, "(estop)"));
}

TEST(RequestBook, TheFirmwareAndTheUltrasonicFollowWhatTheDriverAndTheControllerKnow) {
  RequestBook book;
  Chassis ch;
  const auto version = book.add(Kind::kFirmwareVersion, "firmware_version");
  const auto sonar = book.add(Kind::kUltrasonic, "ultrasonic on", true);
  book.applied(version, Timestamp(1s), ok_status());
  book.applied(sonar, Timestamp(1s), ok_status());
  ch.firmware = FirmwareVersion{FirmwareVersion::State::kAnswered, "FW 1.2"};
  ch.controller.ultrasonic_enabled = true;
  book.settle(ch.at(Timestamp(2s)));
  EXPECT_EQ(outcome(book, version).message, "FW 1.2");
  EXPECT_EQ(outcome(book, sonar).state, State::kAnswered);
  EXPECT_EQ(outcome(book, sonar).message,
            "ultrasonic avoidance enabled (confirmed by the chassis)");

  const auto again = book.add(Kind::kUltrasonic, "ultrasonic off", false);
  book.applied(again, Timestamp(3s), ok_status());
  ch.controller.ultrasonic_failed = true;
  book.settle(ch.at(Timestamp(4s)));
  EXPECT_EQ(outcome(book, again).state, State::kFailed);
  EXPECT_EQ(book.take_settled().size(), 3u);
}

}  // namespace
}  // namespace ranger
