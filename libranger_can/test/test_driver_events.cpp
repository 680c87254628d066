// The driver's events (control/driver_events.hpp, event_tracker.hpp) in lock-step with the
// virtual chassis under a ManualClock: each kind the driver emits is provoked here and asserted
// with its severity and its words (describe(), the line the ROS node logs), the ring
// (events_since) against the observer, the spacing of reports that could repeat, and that the
// same run gives the same events. No threads, no sleeping.
#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "ranger_can/control/driver.hpp"
#include "ranger_can/sim/chassis_commands.hpp"
#include "ranger_can/sim/sim_bus_source.hpp"
#include "ranger_can/text.hpp"
#include "ranger_can/transport/loopback_bus.hpp"
#include "support/identify_rig.hpp"

namespace ranger {
namespace {

using namespace std::chrono_literals;
using test::IdentifyRig;
using test::preset;

bool contains(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}

// Every event the driver delivers to its observer, in order.
class Recorder {
 public:
  explicit Recorder(Driver& driver) : driver_(driver) {
    driver.set_event_observer([this](const DriverEvent& e) { events_.push_back(e); });
  }
  // (A driver destroyed after the recorder still reports its stop: to nobody.)
  ~Recorder() { driver_.set_event_observer(nullptr); }
  Recorder(const Recorder&) = delete;
  Recorder& operator=(const Recorder&) = delete;
  const std::vector<DriverEvent>& all() const { return events_; }
  std::vector<DriverEvent> of(EventKind kind) const {
    std::vector<DriverEvent> out;
    for (const DriverEvent& e : events_)
      if (e.kind == kind) out.push_back(e);
    return out;
  }
  // The first event of `kind` (whose text holds `part`) from index `from` on; nullptr if none.
  const DriverEvent* find(EventKind kind, const std::string& part = "",
                          std::size_t from = 0) const {
    for (std::size_t i = from; i < events_.size(); ++i) {
      if (events_[i].kind == kind && contains(describe(events_[i]), part)) return &events_[i];
    }
    return nullptr;
  }
  std::size_t size() const { return events_.size(); }
  std::string dump() const {
    std::string out;
    for (const DriverEvent& e : events_)
      out += std::string(to_string(e.kind)) + " " + std::string(to_string(e.severity)) + ": " +
             describe(e) + "\n";
    return out;
  }

 private:
  Driver& driver_;
  std::vector<DriverEvent> events_;
};

void inject(IdentifyRig& rig, const std::string& line) {
  auto action = sim::parse_chassis_command(line);
  ASSERT_TRUE(action.ok()) << line;
  rig.sim().with_chassis(*action);
}

// A driver ready to drive the manual chassis (forced settings), its events recorded.
struct Ready {
  explicit Ready(DriverConfig config = test::forced_config(preset("manual")))
      : rig{"sim", std::move(config)} {
    EXPECT_TRUE(rig.wait_ready());
  }
  IdentifyRig rig;
  Recorder events{rig.driver()};
};

// The owner's opt-in: a zero twist re-arms too (ControllerConfig::rearm_on_zero_twist).
DriverConfig zero_twist_rearms() {
  DriverConfig c = test::forced_config(preset("manual"));
  c.controller.rearm_on_zero_twist = true;
  return c;
}

// ---- names, words, the ring -------------------------------------------------------------------

// Every kind and severity is in its name table: EnumNames.EveryTableHoldsEveryEnumerator
// (test_text.cpp) checks every enum's table.
TEST(DriverEventNames, EveryKindAndSeverityHasItsName) {
  EXPECT_EQ(kEventKindNames.parse("link_silent"), EventKind::kLinkSilent);
  EXPECT_EQ(kSeverityNames.names(), (std::vector<std::string>{"debug", "info", "warn", "error"}));
  EXPECT_EQ(to_string(EventKind::kLinkSilent), "link_silent");
  EXPECT_EQ(to_string(Severity::kWarn), "warn");
}

TEST(DriverEventLog, NumbersEventsAndTellsASlowReaderWhatItMissed) {
  EventLog log(4);
  EXPECT_EQ(log.last_sequence(), 0u);
  std::vector<DriverEvent> batch(3);
  log.append(batch);
  EXPECT_EQ(batch[2].sequence, 3u);
  std::vector<DriverEvent> out;
  EXPECT_EQ(log.read(0, out), 0u);
  ASSERT_EQ(out.size(), 3u);
  EXPECT_EQ(out[0].sequence, 1u);
  out.clear();
  EXPECT_EQ(log.read(3, out), 0u);
  EXPECT_TRUE(out.empty()) << "nothing new";
  std::vector<DriverEvent> more(3);
  log.append(more);  // 4..6; the ring holds 3..6
  EXPECT_EQ(log.last_sequence(), 6u);
  EXPECT_EQ(log.read(3, out), 0u) << "a reader that keeps up misses nothing";
  ASSERT_EQ(out.size(), 3u);
  EXPECT_EQ(out.front().sequence, 4u);
  out.clear();
  EXPECT_EQ(log.read(1, out), 1u) << "event 2 fell out of the ring";
  ASSERT_EQ(out.size(), 4u);
  EXPECT_EQ(out.front().sequence, 3u);
}

TEST(DriverEventText, JsonCarriesTheKindSeverityTextAndFields) {
  DriverEvent e;
  e.sequence = 7;
  e.time = Timestamp(1500ms);
  e.kind = EventKind::kLinkSilent;
  e.severity = Severity::kWarn;
  e.data = LinkEvent{"can0", LinkState::kConnected, LinkState::kStale, 100ms};
  EXPECT_EQ(describe(e),
            "chassis on can0 went silent (no system status for 0.10 s): motion stopped, no "
            "odometry until it is heard again");
  EXPECT_EQ(to_json(e, Timestamp(500ms)),
            "{\"seq\":7,\"t\":1.000,\"event\":\"link_silent\",\"severity\":\"warn\",\"text\":\"" +
                describe(e) + "\",\"bus\":\"can0\",\"from\":\"connected\",\"to\":\"stale\"}");
}

// ---- the bus ---------------------------------------------------------------------------------

TEST(DriverEvents, ABusThatCannotOpenIsSaidOnceWithTheRetryAndCommandsAreRefused) {
  ManualClock clock;
  auto source = open_bus_source("nosuchcan0", clock);
  ASSERT_TRUE(source.ok());
  Driver driver(DriverConfig{}, std::move(*source), clock);
  Recorder events(driver);
  driver.step(clock.now());
  clock.advance(DriverConfig{}.reconnect_interval);
  driver.step(clock.now());  // the same error again: no new event
  const auto failed = events.of(EventKind::kBusOpenFailed);
  ASSERT_EQ(failed.size(), 1u) << events.dump();
  EXPECT_EQ(failed[0].severity, Severity::kError);
  EXPECT_TRUE(contains(describe(failed[0]), "cannot open CAN interface nosuchcan0: "));
  EXPECT_TRUE(contains(describe(failed[0]), "bringup_can2usb.bash"));
  EXPECT_TRUE(contains(describe(failed[0]), "retrying every 1.0 s"));

  EXPECT_FALSE(driver.command(MotionRequest{BodyTwist{0.2, 0, 0}, std::nullopt}).ok());
  driver.step(clock.now());
  const auto refused = events.of(EventKind::kCommandRefused);
  ASSERT_EQ(refused.size(), 1u) << events.dump();
  EXPECT_EQ(refused[0].severity, Severity::kWarn);
  EXPECT_TRUE(contains(describe(refused[0]), "cmd_vel not applied: not connected to nosuchcan0"))
      << describe(refused[0]);

  driver.stop();
  const auto stop = events.of(EventKind::kShutdownStop);
  ASSERT_EQ(stop.size(), 1u);
  EXPECT_EQ(describe(stop[0]), "no stop sent to the chassis: the bus nosuchcan0 was never opened");
}

// A bus that opens but where nobody speaks.
class QuietSource : public BusSource {
 public:
  Result<std::unique_ptr<Bus>> open() override { return std::unique_ptr<Bus>(network_.connect()); }
  std::string name() const override { return "vquiet0"; }

 private:
  LoopbackNetwork network_;
};

TEST(DriverEvents, StillWaitingForTheChassisEveryThirtySeconds) {
  ManualClock clock;
  Driver driver(DriverConfig{}, std::make_shared<QuietSource>(), clock);
  Recorder events(driver);
  for (int s = 0; s <= 65; ++s) {
    driver.step(clock.now());
    clock.advance(1s);
  }
  ASSERT_TRUE(
      events.find(EventKind::kBusOpened, "vquiet0 open: waiting for the chassis on vquiet0"))
      << events.dump();
  const auto waiting = events.of(EventKind::kStillWaiting);
  ASSERT_EQ(waiting.size(), 2u) << events.dump();
  EXPECT_EQ(describe(waiting[0]),
            "still waiting for the chassis on vquiet0: nothing heard for 30 s (is it powered on, "
            "and the bus at 500 kbit/s?)");
  EXPECT_TRUE(contains(describe(waiting[1]), "nothing heard for 60 s"));
  EXPECT_TRUE(events.of(EventKind::kLinkConnected).empty());
}

// ---- link, control mode, refusal -------------------------------------------------------------

TEST(DriverEvents, StartingUpSaysTheBusTheLinkTheControlModeAndWhenMotionIsAccepted) {
  Ready r;
  const Recorder& ev = r.events;
  const DriverEvent* opened = ev.find(EventKind::kBusOpened, "sim open");
  const DriverEvent* connected = ev.find(EventKind::kLinkConnected, "chassis connected on sim");
  const DriverEvent* can =
      ev.find(EventKind::kControlModeChanged, "control mode can (was standby)");
  const DriverEvent* accepted = ev.find(EventKind::kRefusalChanged, "chassis accepts motion");
  ASSERT_TRUE(opened && connected && can && accepted) << ev.dump();
  EXPECT_LT(opened->sequence, connected->sequence);
  EXPECT_LT(connected->sequence, can->sequence);
  EXPECT_LT(can->sequence, accepted->sequence);
  EXPECT_EQ(connected->severity, Severity::kInfo);
  EXPECT_EQ(accepted->severity, Severity::kInfo);
  EXPECT_EQ(accepted->as<RefusalEvent>()->to, MotionRefusal::kNone);
  // The standby refusal while CAN mode is requested is news, not a warning.
  const DriverEvent* standby = ev.find(EventKind::kRefusalChanged, "standby: requesting CAN");
  ASSERT_TRUE(standby) << ev.dump();
  EXPECT_EQ(standby->severity, Severity::kInfo);
  // Time and sequence increase.
  for (std::size_t i = 1; i < ev.size(); ++i) {
    EXPECT_EQ(ev.all()[i].sequence, ev.all()[i - 1].sequence + 1);
    EXPECT_GE(ev.all()[i].time, ev.all()[i - 1].time);
  }
}

// (With the opt-in: a zero twist is the re-arm here; without it only resume is, below.)
TEST(DriverEvents, ASilentChassisIsSaidThenHeardAgainAndTheLatchNeedsARearm) {
  Ready r(zero_twist_rearms());
  r.rig.command({0.3, 0.0, 0.0});
  r.rig.run_for(300ms);
  const std::size_t before = r.events.size();
  inject(r.rig, "silent on");
  r.rig.run_for(300ms);
  const DriverEvent* silent = r.events.find(EventKind::kLinkSilent, "", before);
  ASSERT_TRUE(silent) << r.events.dump();
  EXPECT_EQ(silent->severity, Severity::kWarn);
  EXPECT_EQ(describe(*silent),
            "chassis on sim went silent (no system status for 0.10 s): motion stopped, no "
            "odometry until it is heard again");
  const DriverEvent* latched = r.events.find(EventKind::kRearmLatched, "link_lost", before);
  ASSERT_TRUE(latched) << r.events.dump();
  EXPECT_EQ(latched->as<RearmEvent>()->causes, static_cast<StopCauses>(StopCause::kLinkLost));
  const DriverEvent* lost = r.events.find(EventKind::kRefusalChanged, "link lost", before);
  ASSERT_TRUE(lost);
  EXPECT_EQ(lost->severity, Severity::kDebug) << "the link's own event says it";

  inject(r.rig, "silent off");
  r.rig.run_for(300ms);
  const DriverEvent* again = r.events.find(EventKind::kLinkHeardAgain, "", before);
  ASSERT_TRUE(again) << r.events.dump();
  EXPECT_EQ(describe(*again), "chassis heard again on sim: odometry resumes from the last pose");
  const DriverEvent* rearm =
      r.events.find(EventKind::kRefusalChanged, "rearm_required after link_lost", before);
  ASSERT_TRUE(rearm) << r.events.dump();
  EXPECT_EQ(rearm->severity, Severity::kWarn);
  EXPECT_TRUE(contains(describe(*rearm), "motion refused: rearm_required after link_lost"));

  r.rig.command({0.0, 0.0, 0.0});
  r.rig.run_for(200ms);
  const DriverEvent* cleared = r.events.find(EventKind::kRearmCleared, "", before);
  ASSERT_TRUE(cleared) << r.events.dump();
  EXPECT_FALSE(cleared->as<RearmEvent>()->by_resume);
  EXPECT_EQ(describe(*cleared), "re-armed (zero twist) after link_lost");
}

TEST(DriverEvents, AnEmergencyStopIsRefusedLatchedAndResumeIsAnswered) {
  Ready r;
  r.rig.command({0.3, 0.0, 0.0});
  r.rig.run_for(300ms);
  const std::size_t before = r.events.size();
  inject(r.rig, "estop on");
  r.rig.run_for(200ms);
  const DriverEvent* estop = r.events.find(EventKind::kRefusalChanged, "", before);
  ASSERT_TRUE(estop) << r.events.dump();
  EXPECT_EQ(estop->severity, Severity::kWarn);
  EXPECT_EQ(describe(*estop),
            "motion refused: emergency stop pressed: release it, then call resume");
  ASSERT_TRUE(
      r.events.find(EventKind::kRearmLatched, "re-arm latched after emergency_stop", before));

  r.rig.driver().resume();  // refused while pressed
  r.rig.run_for(50ms);
  const DriverEvent* refused = r.events.find(EventKind::kRequestSettled, "resume failed", before);
  ASSERT_TRUE(refused) << r.events.dump();
  EXPECT_EQ(refused->severity, Severity::kWarn);
  EXPECT_TRUE(contains(describe(*refused), "emergency_stop")) << describe(*refused);

  inject(r.rig, "estop off");
  r.rig.run_for(200ms);
  ASSERT_TRUE(
      r.events.find(EventKind::kRefusalChanged, "rearm_required after emergency_stop", before));
  const std::size_t released = r.events.size();
  r.rig.driver().resume();
  r.rig.run_for(200ms);
  const DriverEvent* answered = r.events.find(EventKind::kRequestSettled, "", released);
  ASSERT_TRUE(answered) << r.events.dump();
  EXPECT_EQ(describe(*answered), "resume: re-armed");
  EXPECT_EQ(answered->severity, Severity::kInfo);
  const DriverEvent* cleared = r.events.find(EventKind::kRearmCleared, "", released);
  ASSERT_TRUE(cleared);
  EXPECT_TRUE(cleared->as<RearmEvent>()->by_resume);
  EXPECT_TRUE(r.events.find(EventKind::kRefusalChanged, "chassis accepts motion", released));
}

TEST(DriverEvents, ByDefaultAZeroTwistClearsNoLatchAndResumeSaysItDid) {
  Ready r;
  r.rig.command({0.3, 0.0, 0.0});
  r.rig.run_for(300ms);
  inject(r.rig, "silent 0.5");
  r.rig.run_for(1s);
  const std::size_t heard = r.events.size();
  ASSERT_TRUE(r.events.find(EventKind::kRefusalChanged, "rearm_required after link_lost", 0))
      << r.events.dump();
  r.rig.command({0.0, 0.0, 0.0});
  r.rig.run_for(200ms);
  r.rig.command({0.3, 0.0, 0.0});
  r.rig.run_for(500ms);
  EXPECT_FALSE(r.events.find(EventKind::kRearmCleared, "", heard)) << r.events.dump();
  r.rig.driver().resume();
  r.rig.run_for(200ms);
  const DriverEvent* cleared = r.events.find(EventKind::kRearmCleared, "", heard);
  ASSERT_TRUE(cleared) << r.events.dump();
  EXPECT_TRUE(cleared->as<RearmEvent>()->by_resume);
  EXPECT_EQ(describe(*cleared), "re-armed (resume) after link_lost");
}

// A client calling clear_errors at 20 Hz: the first answer is reported, the identical ones after
// it are counted, and the next report (after repeated_request_interval) says how many.
TEST(DriverEvents, RequestsAnsweredAlikeAreReportedOnceThenCounted) {
  Ready r;
  const std::size_t settled_before = r.events.of(EventKind::kRequestSettled).size();
  for (int i = 0; i < 30; ++i) {
    ASSERT_TRUE(r.rig.driver().clear_errors(0x00).ok());
    r.rig.run_for(50ms);
  }
  r.rig.run_for(100ms);
  EXPECT_EQ(r.events.of(EventKind::kRequestSettled).size(), settled_before + 1) << r.events.dump();
  r.rig.run_for(10s);
  ASSERT_TRUE(r.rig.driver().clear_errors(0x00).ok());
  r.rig.run_for(100ms);
  const auto settled = r.events.of(EventKind::kRequestSettled);
  ASSERT_EQ(settled.size(), settled_before + 2) << r.events.dump();
  EXPECT_EQ(settled.back().as<RequestEvent>()->repeated, 29u);
  EXPECT_TRUE(contains(describe(settled.back()), "(29 more answered alike since the last report)"))
      << describe(settled.back());
}

TEST(DriverEvents, TheControlModeUnderTheRemoteControl) {
  Ready r;
  const std::size_t before = r.events.size();
  inject(r.rig, "remote on");
  r.rig.run_for(200ms);
  const DriverEvent* remote = r.events.find(EventKind::kControlModeChanged, "", before);
  ASSERT_TRUE(remote) << r.events.dump();
  EXPECT_EQ(describe(*remote), "control mode remote (was can)");
  EXPECT_EQ(remote->as<ControlModeEvent>()->to, protocol::ControlMode::kRemote);
  ASSERT_TRUE(
      r.events.find(EventKind::kRefusalChanged, "motion refused: remote control has", before));
}

// ---- faults by meaning -----------------------------------------------------------------------

TEST(DriverEvents, FaultsAreRaisedAndClearedByMeaning) {
  Ready r;
  const std::size_t before = r.events.size();
  inject(r.rig, "error over_current");
  r.rig.run_for(100ms);
  inject(r.rig, "error over_current off");
  r.rig.run_for(100ms);
  const DriverEvent* raised = r.events.find(EventKind::kFaultRaised, "", before);
  const DriverEvent* cleared = r.events.find(EventKind::kFaultCleared, "", before);
  ASSERT_TRUE(raised && cleared) << r.events.dump();
  const FaultEvent& f = *raised->as<FaultEvent>();
  EXPECT_EQ(f.name, "over_current");
  EXPECT_EQ(f.fault, protocol::Fault::kOverCurrent);
  EXPECT_TRUE(f.critical);
  EXPECT_EQ(raised->severity, Severity::kWarn);
  EXPECT_TRUE(contains(describe(*raised), "chassis fault: over_current - over-current protection"))
      << describe(*raised);
  EXPECT_EQ(cleared->severity, Severity::kInfo);
  EXPECT_EQ(describe(*cleared), "chassis fault cleared: over_current (error word 0x00000000)");
  EXPECT_EQ(r.events.of(EventKind::kFaultRaised).size(), 1u) << "once, not per frame";
}

// ---- commands ----------------------------------------------------------------------------------

TEST(DriverEvents, NonFiniteCommandsAreReportedAtMostOnceASecondWithTheCount) {
  Ready r;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  // A NaN every 50 ms for 2.5 s: reported at 0, 1 and 2 s.
  for (int i = 0; i < 50; ++i) {
    EXPECT_EQ(
        r.rig.driver().command(MotionRequest{BodyTwist{nan, 0, 0}, std::nullopt}).error().code,
        Errc::kNotFinite);
    for (int k = 0; k < 50; ++k)
      r.rig.step();
  }
  const auto refused = r.events.of(EventKind::kCommandRefused);
  ASSERT_EQ(refused.size(), 3u) << r.events.dump();
  EXPECT_EQ(refused[0].severity, Severity::kError);
  EXPECT_EQ(describe(refused[0]),
            "cmd_vel refused, chassis stopped: command refused (linear.x is NaN): the chassis is "
            "commanded to stop");
  EXPECT_EQ(refused[1].as<CommandRefusedEvent>()->count, 20u);
  EXPECT_TRUE(contains(describe(refused[1]), "(20 refused since the last report)"));
  EXPECT_GE(refused[1].time - refused[0].time, 1s);
}

TEST(DriverEvents, ACommandBeyondTheChassisIsReportedAdjustedAtMostEveryFiveSeconds) {
  Ready r;
  r.rig.command({1e9, 0.0, 0.0});
  r.rig.run_for(12s);
  const auto adjusted = r.events.of(EventKind::kCommandAdjusted);
  ASSERT_EQ(adjusted.size(), 3u) << r.events.dump();
  EXPECT_EQ(adjusted[0].severity, Severity::kWarn);
  EXPECT_TRUE(contains(describe(adjusted[0]), "cmd_vel adjusted to what the chassis can do: "))
      << describe(adjusted[0]);
  EXPECT_GE(adjusted[1].time - adjusted[0].time, 5s);
}

TEST(DriverEvents, SetMotionModeIsSaid) {
  Ready r;
  r.rig.driver().set_motion_mode(protocol::MotionMode::kSpin);
  r.rig.run_for(10ms);
  r.rig.driver().set_motion_mode(std::nullopt);
  r.rig.run_for(10ms);
  const auto modes = r.events.of(EventKind::kMotionModeRequested);
  ASSERT_EQ(modes.size(), 2u);
  EXPECT_EQ(describe(modes[0]),
            "set_motion_mode: motion mode pinned to spin (the switch happens at standstill)");
  EXPECT_EQ(describe(modes[1]), "set_motion_mode: automatic motion-mode selection");
}

TEST(DriverEvents, TheStopAtShutdownIsSaid) {
  Ready r;
  r.rig.driver().stop();
  const auto stop = r.events.of(EventKind::kShutdownStop);
  ASSERT_EQ(stop.size(), 1u);
  EXPECT_EQ(describe(stop[0]), "stop sent to the chassis (zero motion command, frame 0x111)");
  EXPECT_TRUE(stop[0].as<ShutdownEvent>()->sent);
}

// ---- identification and plausibility ----------------------------------------------------------

TEST(DriverEvents, TheIdentificationPhasesAndItsDecision) {
  IdentifyRig rig("sim", test::auto_config());
  Recorder ev(rig.driver());
  rig.command({0.5, 0.0, 0.0});
  ASSERT_TRUE(rig.run_until(
      [&] { return rig.snapshot()->identification && rig.snapshot()->identification->done(); },
      12s));
  rig.run_for(10ms);
  const auto phases = ev.of(EventKind::kIdentificationPhase);
  ASSERT_GE(phases.size(), 3u) << ev.dump();
  EXPECT_EQ(phases[0].as<IdentificationEvent>()->phase, IdentificationPhase::kListening);
  EXPECT_TRUE(contains(describe(phases[0]), "identification: listening"));
  const DriverEvent* decided = ev.find(EventKind::kIdentified);
  ASSERT_TRUE(decided) << ev.dump();
  EXPECT_EQ(decided->severity, Severity::kInfo);
  EXPECT_TRUE(contains(describe(*decided), "chassis identified in ")) << describe(*decided);
  EXPECT_TRUE(contains(describe(*decided), "Evidence: "));
  EXPECT_TRUE(contains(describe(*decided), "Kept at the manual preset's value"));
  const DriverEvent* waits = ev.find(EventKind::kRefusalChanged, "motion waits: ");
  ASSERT_TRUE(waits) << ev.dump();
  EXPECT_EQ(waits->severity, Severity::kInfo);
  EXPECT_LT(decided->sequence, ev.find(EventKind::kRefusalChanged, "accepts motion")->sequence);
  EXPECT_EQ(ev.of(EventKind::kIdentified).size(), 1u);
}

TEST(DriverEvents, AnIdentificationThatFailsSaysWhatToSet) {
  DriverConfig c = test::auto_config();
  c.identification.timeout = 3s;
  IdentifyRig rig("sim", c);
  Recorder ev(rig.driver());
  inject(rig, "silent on");
  rig.run_for(4s);
  const auto failed = ev.of(EventKind::kIdentificationFailed);
  ASSERT_EQ(failed.size(), 1u) << ev.dump();
  EXPECT_EQ(failed[0].severity, Severity::kError);
  EXPECT_TRUE(contains(describe(failed[0]), "protocol: manual")) << describe(failed[0]);
  EXPECT_TRUE(failed[0].as<IdentificationEvent>()->commission.empty()) << "not a SocketCAN port";
}

TEST(DriverEvents, ASettingLearnedWhileDrivingIsSaid) {
  IdentifyRig rig("sim:spin_cw", test::auto_config());
  Recorder ev(rig.driver());
  ASSERT_TRUE(rig.wait_ready());
  rig.drive({0.0, 0.0, 0.6}, protocol::MotionMode::kSpin, 6s);
  const auto learned = ev.of(EventKind::kSettingLearned);
  ASSERT_EQ(learned.size(), 1u) << ev.dump();
  EXPECT_EQ(learned[0].severity, Severity::kWarn);
  EXPECT_TRUE(contains(describe(learned[0]), "learned while driving: spin_sign = cw"))
      << describe(learned[0]);
  EXPECT_TRUE(contains(describe(learned[0]), "protocol settings now manual with spin_sign=cw"));
}

TEST(DriverEvents, APlausibilityWarningIsSaidOnceThenTheStop) {
  ProtocolProfile p = preset("manual");
  p.steering_reference = SteeringReference::kInnerFront;
  IdentifyRig rig("sim", test::forced_config(p));
  Recorder ev(rig.driver());
  ASSERT_TRUE(rig.wait_ready(true));
  ASSERT_TRUE(rig.drive_until_stopped({0.6, 0.0, 0.4}, protocol::MotionMode::kAckermann, 20s));
  rig.run_for(1s);
  const auto warnings = ev.of(EventKind::kPlausibilityWarning);
  const auto stops = ev.of(EventKind::kPlausibilityStop);
  ASSERT_EQ(warnings.size(), 1u) << ev.dump();
  ASSERT_EQ(stops.size(), 1u) << ev.dump();
  EXPECT_LT(warnings[0].sequence, stops[0].sequence);
  EXPECT_EQ(warnings[0].severity, Severity::kWarn);
  EXPECT_TRUE(contains(describe(warnings[0]), "plausibility: steering_reference: try mean_front"))
      << describe(warnings[0]);
  EXPECT_EQ(stops[0].severity, Severity::kError);
  EXPECT_TRUE(
      contains(describe(stops[0]), "plausibility stop: steering_reference: try mean_front"));
  EXPECT_TRUE(contains(describe(stops[0]), "The robot is stopped"));
}

// ---- the vendor's features and padding ---------------------------------------------------------

TEST(DriverEvents, FirmwareParkAndLightsOnTheVendorsChassis) {
  sim::SimSourceOptions o;
  o.chassis.version = "RANGER-FW 1.2";
  DriverConfig c = test::forced_config(preset("agx_v2"));
  IdentifyRig rig("sim:agx_v2", c, o);
  Recorder ev(rig.driver());
  ASSERT_TRUE(rig.wait_ready());
  ASSERT_TRUE(rig.run_until([&] { return ev.find(EventKind::kFirmwareVersion) != nullptr; }, 2s))
      << ev.dump();
  EXPECT_EQ(describe(*ev.find(EventKind::kFirmwareVersion)), "firmware version: RANGER-FW 1.2");

  const std::size_t before = ev.size();
  LightsRequest lights;
  lights.front = protocol::LightMode::kCustom;
  lights.front_brightness = 40;
  lights.rear = protocol::LightMode::kOff;
  ASSERT_TRUE(rig.driver().set_lights(lights).ok());
  ASSERT_TRUE(rig.run_until([&] { return ev.find(EventKind::kRequestSettled, "", before); }, 2s));
  EXPECT_TRUE(ev.find(EventKind::kLightsChanged, "lights: front custom 40, rear off", before))
      << ev.dump();
  EXPECT_TRUE(contains(describe(*ev.find(EventKind::kRequestSettled, "", before)),
                       "lights front custom 40, rear off: the chassis reports"));

  rig.driver().set_park(true);
  ASSERT_TRUE(rig.run_until([&] { return ev.find(EventKind::kParkChanged) != nullptr; }, 10s))
      << ev.dump();
  EXPECT_EQ(describe(*ev.find(EventKind::kParkChanged)), "chassis parked (0x291 reports park)");
  rig.driver().set_park(false);
  ASSERT_TRUE(rig.run_until([&] { return ev.of(EventKind::kParkChanged).size() == 2; }, 10s));
  EXPECT_EQ(describe(ev.of(EventKind::kParkChanged)[1]), "chassis left park");
}

TEST(DriverEvents, PaddedFramesAreSaidOncePerId) {
  IdentifyRig rig("sim:padded", test::forced_config(preset("manual")));
  Recorder ev(rig.driver());
  rig.run_for(2s);
  const auto padded = ev.of(EventKind::kFramesPadded);
  ASSERT_FALSE(padded.empty()) << ev.dump();
  std::vector<std::uint32_t> ids;
  for (const DriverEvent& e : padded)
    ids.push_back(e.as<PaddedFramesEvent>()->id);
  std::sort(ids.begin(), ids.end());
  EXPECT_EQ(std::adjacent_find(ids.begin(), ids.end()), ids.end()) << "each ID once";
  const DriverEvent* mode = ev.find(EventKind::kFramesPadded, "0x291 (motion_mode)");
  ASSERT_TRUE(mode) << ev.dump();
  EXPECT_TRUE(contains(describe(*mode),
                       "frames arrive longer than their layout: decoded from "
                       "their leading bytes, the rest ignored"));
}

// ---- delivery ---------------------------------------------------------------------------------

TEST(DriverEvents, TheRingHoldsWhatTheObserverSawAndTheSameRunGivesTheSameEvents) {
  auto run = [](std::vector<DriverEvent>& ring) {
    Ready r;
    inject(r.rig, "estop on");
    r.rig.run_for(200ms);
    EXPECT_EQ(r.rig.driver().events_since(0, ring), 0u);
    return r.events.all();
  };
  std::vector<DriverEvent> ring1, ring2;
  const auto seen1 = run(ring1);
  const auto seen2 = run(ring2);
  ASSERT_EQ(ring1.size(), seen1.size());
  ASSERT_EQ(seen1.size(), seen2.size());
  for (std::size_t i = 0; i < seen1.size(); ++i) {
    EXPECT_EQ(ring1[i].sequence, seen1[i].sequence);
    EXPECT_EQ(describe(ring1[i]), describe(seen1[i]));
    EXPECT_EQ(to_json(seen1[i]), to_json(seen2[i])) << "deterministic in lock-step";
  }
}

TEST(DriverEvents, AReadOnlyDriverReportsNoRefusalsNorLatches) {
  ManualClock clock;
  auto source = open_bus_source("replay:" RANGER_DATA_DIR "/sample.log", clock);
  ASSERT_TRUE(source.ok());
  Driver driver(DriverConfig{}, std::move(*source), clock);
  Recorder ev(driver);
  for (int i = 0; i < 3000; ++i) {
    driver.step(clock.now());
    clock.advance(1ms);
  }
  EXPECT_TRUE(ev.find(EventKind::kLinkConnected)) << ev.dump();
  EXPECT_TRUE(ev.of(EventKind::kRefusalChanged).empty()) << ev.dump();
  EXPECT_TRUE(ev.of(EventKind::kRearmLatched).empty());
}

}  // namespace
}  // namespace ranger
