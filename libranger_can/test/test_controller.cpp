// The chassis controller's state machine against a recording fake bus and a simulated clock:
// handshake, retries, remote takeover, keep-alive, command timeout, shutdown, mode-switch
// ordering, faults, ultrasonic, link loss. No threads, no sleeping.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "ranger_can/control/controller.hpp"
#include "ranger_can/wire/codec.hpp"
#include "ranger_can/wire/interpretation.hpp"
#include "ranger_can/wire/protocol.hpp"
#include "support/fake_bus.hpp"

namespace ranger {
namespace {

using namespace std::chrono_literals;
using protocol::ControlMode;
using protocol::MotionMode;
using protocol::VehicleStatus;

MotionCommand motion_of(const CanFrame& f) {
  Result<Message> m = decode(f);
  EXPECT_TRUE(m.ok());
  return m.ok() ? std::get<MotionCommand>(*m) : MotionCommand{};
}

bool is_zero(const MotionCommand& c) {
  return c.linear_speed == 0.0 && c.spin_speed == 0.0 && c.steering_angle == 0.0;
}
bool is_moving(const CanFrame& f) {
  return f.id == protocol::kMotionCommandId && motion_of(f).linear_speed != 0.0;
}

// A scripted chassis: what it reports each 20 ms, fed to the controller as encoded frames, while
// the controller is ticked every `tick_period`.
struct Rig {
  explicit Rig(ControllerConfig config = {})
      : ctl(std::make_unique<ChassisController>(bus, config)) {}

  test::FakeBus bus;
  std::unique_ptr<ChassisController> ctl;
  Timestamp now{0};
  std::chrono::nanoseconds tick_period = 1ms;

  // Reported state
  bool alive = true;  // sends feedback at all
  std::uint8_t control = static_cast<std::uint8_t>(ControlMode::kStandby);
  std::uint8_t vehicle = 0;
  std::uint32_t errors = 0;
  MotionMode mode = MotionMode::kAckermann;
  bool send_mode = true;
  bool switching = false;
  double wheel_speed = 0.0;
  std::optional<double> soc;
  std::optional<std::array<double, 4>> wheel_angles;  // 0x271, manual signs
  bool obey_control_requests = false;  // switch to CAN mode when asked (a cooperative chassis)

  Timestamp next_feedback{0};

  void inject(const Message& m) {
    Result<CanFrame> f = encode(m);
    ASSERT_TRUE(f.ok()) << f.error().message;
    f->stamp = now;
    ctl->on_frame(*f, now);
  }

  void feedback() {
    SystemStatus st;
    st.vehicle_status_raw = vehicle;
    st.vehicle_status = static_cast<VehicleStatus>(vehicle);
    st.control_mode_raw = control;
    st.control_mode = static_cast<ControlMode>(control);
    st.battery_voltage = 50.0;
    st.error_bits = errors;
    inject(st);
    MotionFeedback mf;
    mf.speed = wheel_speed;
    inject(mf);
    WheelSpeedsFeedback ws;
    ws.speeds = {wheel_speed, wheel_speed, wheel_speed, wheel_speed};
    inject(ws);
    if (send_mode) {
      MotionModeFeedback mm;
      mm.mode = mode;
      mm.mode_raw = static_cast<std::uint8_t>(mode);
      mm.switching = switching;
      inject(mm);
    }
    if (wheel_angles) {
      SteeringAnglesFeedback a;
      a.angles = *wheel_angles;
      inject(a);
    }
    if (soc) {
      BmsData b;
      b.battery = 0;
      b.soc = *soc;
      b.soh = 100;
      b.voltage = 50;
      inject(b);
    }
  }

  // Advances time by `d`: feedback every 20 ms (if alive), a tick every tick_period.
  void run(std::chrono::nanoseconds d) {
    const Timestamp end = now + d;
    while (now < end) {
      if (alive && now >= next_feedback) {
        feedback();
        next_feedback = now + 20ms;
      }
      ctl->tick(now);
      if (obey_control_requests) {
        for (const CanFrame& f : bus.sent_with_id(protocol::kControlModeCommandId)) {
          if (f.data[0] == 0x01 && control == 0x00) control = 0x01;
        }
      }
      now += tick_period;
    }
  }

  // Connects and reaches CAN mode with the chassis in `m`, then forgets the frames sent so far.
  void connect_in_can_mode(MotionMode m = MotionMode::kAckermann) {
    mode = m;
    control = static_cast<std::uint8_t>(ControlMode::kCan);
    run(100ms);
    bus.clear_sent();
  }

  std::vector<CanFrame> motion_frames() const {
    return bus.sent_with_id(protocol::kMotionCommandId);
  }
  const ControllerState& state() const { return ctl->state(); }
};

// ---- link and control-mode handshake -----------------------------------------------------------

TEST(ControllerHandshake, SendsNothingBeforeTheChassisIsHeard) {
  Rig rig;
  rig.alive = false;
  ASSERT_TRUE(rig.ctl->set_command(BodyTwist{0.5, 0, 0}, rig.now).ok());
  rig.run(1s);
  EXPECT_TRUE(rig.bus.sent.empty());
  EXPECT_EQ(rig.state().link, LinkState::kNeverConnected);
  EXPECT_EQ(rig.state().refusal, MotionRefusal::kLinkLost);
}

TEST(ControllerHandshake, StandbyRequestConfirmed) {
  Rig rig;
  rig.run(1ms);  // first 0x211: standby
  ASSERT_EQ(rig.state().link, LinkState::kConnected);
  const auto requests = rig.bus.sent_with_id(protocol::kControlModeCommandId);
  ASSERT_EQ(requests.size(), 1u);
  EXPECT_EQ(requests[0].dlc, 1);
  EXPECT_EQ(requests[0].data[0], 0x01);  // CAN command mode
  EXPECT_TRUE(rig.state().awaiting_command_mode);
  EXPECT_EQ(rig.state().refusal, MotionRefusal::kStandby);
  EXPECT_EQ(rig.bus.count(protocol::kMotionCommandId), 0u);  // nothing to say in standby

  rig.control = 0x01;  // the chassis obeys
  rig.run(500ms);
  EXPECT_EQ(rig.bus.count(protocol::kControlModeCommandId), 1u);  // no further requests
  EXPECT_FALSE(rig.state().awaiting_command_mode);
  EXPECT_EQ(rig.state().control_mode, ControlMode::kCan);
  EXPECT_GE(rig.bus.count(protocol::kMotionCommandId), 20u);  // keep-alive runs
  EXPECT_EQ(rig.state().refusal, MotionRefusal::kNone);
}

TEST(ControllerHandshake, RetriesAtABoundedRateUntilConfirmed) {
  Rig rig;
  rig.run(1000ms);  // the chassis ignores the requests
  const auto requests = rig.bus.sent_with_id(protocol::kControlModeCommandId);
  ASSERT_EQ(requests.size(), 10u);  // every 100 ms, t = 0, 100, ..., 900 ms
  for (std::size_t i = 1; i < requests.size(); ++i) {
    EXPECT_EQ(requests[i].stamp - requests[i - 1].stamp, 100ms);
  }
  EXPECT_EQ(rig.state().counters.control_mode_requests, 10u);
  rig.obey_control_requests = true;
  rig.run(200ms);
  EXPECT_EQ(rig.state().control_mode, ControlMode::kCan);
  const std::size_t total = rig.bus.count(protocol::kControlModeCommandId);
  rig.run(1s);
  EXPECT_EQ(rig.bus.count(protocol::kControlModeCommandId), total);
}

TEST(ControllerHandshake, AutoCommandModeOffNeverRequestsByItself) {
  ControllerConfig cfg;
  cfg.auto_command_mode = false;
  Rig rig(cfg);
  rig.run(1s);
  EXPECT_EQ(rig.bus.count(protocol::kControlModeCommandId), 0u);
  EXPECT_EQ(rig.state().refusal, MotionRefusal::kStandby);
  ASSERT_TRUE(rig.ctl->request_control_mode(ControlMode::kCan, rig.now).ok());
  EXPECT_EQ(rig.bus.count(protocol::kControlModeCommandId), 1u);
  EXPECT_FALSE(rig.ctl->request_control_mode(ControlMode::kRemote, rig.now).ok());
}

TEST(ControllerHandshake, RemoteTakeoverIsNeverFoughtAndIsFinal) {
  Rig rig;
  rig.connect_in_can_mode();
  auto drive = [&](std::chrono::nanoseconds d) {
    for (auto t = 0ns; t < d; t += 50ms) {
      ASSERT_TRUE(rig.ctl->set_command(BodyTwist{0.5, 0, 0}, rig.now).ok());
      rig.run(50ms);
    }
  };
  drive(200ms);
  EXPECT_TRUE(is_moving(rig.motion_frames().back()));

  rig.control = 0x03;  // remote control takes over
  rig.run(1ms);        // the next 0x211 reports it
  rig.bus.clear_sent();
  drive(1s);
  EXPECT_TRUE(rig.bus.sent.empty()) << "the host must stay silent under remote control";
  EXPECT_EQ(rig.state().refusal, MotionRefusal::kRemote);
  EXPECT_FALSE(rig.state().awaiting_command_mode);
  EXPECT_TRUE(rig.state().reclaim_blocked);

  // The remote is switched off (or loses its signal): standby. Remote control is final: no
  // 0x421 of the driver's own, whatever the commander keeps publishing.
  rig.control = 0x00;
  drive(2s);
  EXPECT_EQ(rig.bus.count(protocol::kControlModeCommandId), 0u);
  EXPECT_EQ(rig.bus.count(protocol::kMotionCommandId), 0u);
  EXPECT_EQ(rig.state().refusal, MotionRefusal::kRearmRequired);
  EXPECT_TRUE(has(rig.state().latched_causes, StopCause::kRemote));

  // resume() gives control back: CAN mode is requested, and the latch is cleared with it.
  ASSERT_TRUE(rig.ctl->resume(rig.now).ok());
  drive(100ms);
  EXPECT_GE(rig.bus.count(protocol::kControlModeCommandId), 1u);
  EXPECT_EQ(rig.bus.count(protocol::kMotionCommandId), 0u);
  rig.control = 0x01;  // confirmed
  drive(200ms);
  EXPECT_EQ(rig.state().refusal, MotionRefusal::kNone);
  EXPECT_TRUE(is_moving(rig.motion_frames().back()));
}

TEST(ControllerHandshake, OptionalAutomaticReclaimAfterRemote) {
  ControllerConfig cfg;
  cfg.auto_reclaim_after_remote = true;
  Rig rig(cfg);
  rig.connect_in_can_mode();
  rig.control = 0x03;
  rig.run(100ms);
  rig.control = 0x00;  // remote switched off
  rig.bus.clear_sent();
  rig.run(100ms);
  EXPECT_GE(rig.bus.count(protocol::kControlModeCommandId), 1u);
  EXPECT_FALSE(rig.state().reclaim_blocked);
  // Reclaiming the control mode is not a re-arm: motion still needs one.
  rig.control = 0x01;
  ASSERT_TRUE(rig.ctl->set_command(BodyTwist{0.3, 0, 0}, rig.now).ok());
  rig.run(40ms);
  EXPECT_EQ(rig.state().refusal, MotionRefusal::kRearmRequired);
}

TEST(ControllerHandshake, RemoteHandingBackWithSwbStillNeedsTheRearm) {
  Rig rig;
  rig.connect_in_can_mode();
  rig.control = 0x03;
  rig.run(40ms);
  rig.bus.clear_sent();
  rig.control = 0x01;  // SWB up: the chassis itself reports CAN command mode
  for (int i = 0; i < 10; ++i) {
    ASSERT_TRUE(rig.ctl->set_command(BodyTwist{0.3, 0, 0}, rig.now).ok());
    rig.run(20ms);
  }
  EXPECT_EQ(rig.bus.count(protocol::kControlModeCommandId), 0u);
  EXPECT_FALSE(rig.state().reclaim_blocked);
  EXPECT_EQ(rig.state().refusal, MotionRefusal::kRearmRequired);
  for (const CanFrame& f : rig.motion_frames())
    EXPECT_TRUE(is_zero(motion_of(f))) << "moved before the re-arm";
  // A zero twist is no re-arm; resume is: the next twist drives.
  ASSERT_TRUE(rig.ctl->set_command(BodyTwist{}, rig.now).ok());
  rig.run(20ms);
  EXPECT_EQ(rig.state().refusal, MotionRefusal::kRearmRequired);
  ASSERT_TRUE(rig.ctl->resume(rig.now).ok());
  rig.run(20ms);
  EXPECT_EQ(rig.state().refusal, MotionRefusal::kNone);
  ASSERT_TRUE(rig.ctl->set_command(BodyTwist{0.3, 0, 0}, rig.now).ok());
  rig.run(40ms);
  EXPECT_TRUE(is_moving(rig.motion_frames().back()));
  EXPECT_EQ(rig.state().counters.rearms, 1u);
}

TEST(ControllerLink, StaleAfterTimeoutAndReconnectsByItself) {
  Rig rig;
  rig.connect_in_can_mode();
  ASSERT_TRUE(rig.ctl->set_command(BodyTwist{0.5, 0, 0}, rig.now).ok());
  rig.run(40ms);
  rig.alive = false;
  const Timestamp silent_since = rig.now;  // the last 0x211 came at most 20 ms before
  while (rig.state().link == LinkState::kConnected && rig.now < silent_since + 1s) {
    ASSERT_TRUE(rig.ctl->set_command(BodyTwist{0.5, 0, 0}, rig.now).ok());
    rig.run(1ms);
  }
  EXPECT_EQ(rig.state().link, LinkState::kStale);
  EXPECT_LE(rig.now - silent_since, 101ms);
  EXPECT_GE(rig.now - silent_since, 80ms);
  EXPECT_EQ(rig.state().refusal, MotionRefusal::kLinkLost);
  EXPECT_EQ(rig.state().counters.link_losses, 1u);
  EXPECT_NE(std::find(rig.state().faults.begin(), rig.state().faults.end(), "link_lost"),
            rig.state().faults.end());
  rig.bus.clear_sent();
  rig.run(100ms);
  for (const CanFrame& f : rig.motion_frames())
    EXPECT_TRUE(is_zero(motion_of(f)));

  // The chassis is heard again: the link reconnects by itself, but motion does not resume on
  // the stale twist: link loss was an involuntary stop.
  rig.alive = true;
  ASSERT_TRUE(rig.ctl->set_command(BodyTwist{0.5, 0, 0}, rig.now).ok());
  rig.run(40ms);
  EXPECT_EQ(rig.state().link, LinkState::kConnected);
  EXPECT_EQ(rig.state().refusal, MotionRefusal::kRearmRequired);
  EXPECT_TRUE(is_zero(motion_of(rig.motion_frames().back())));
  ASSERT_TRUE(rig.ctl->resume(rig.now).ok());  // the re-arm
  rig.run(20ms);
  ASSERT_TRUE(rig.ctl->set_command(BodyTwist{0.5, 0, 0}, rig.now).ok());
  rig.run(40ms);
  EXPECT_TRUE(is_moving(rig.motion_frames().back()));
}

// ---- keep-alive and command timeout ------------------------------------------------------------

TEST(ControllerKeepAlive, SendsEvery20MsWhileInCanMode) {
  for (auto tick : {1ms, 5ms, 10ms}) {
    SCOPED_TRACE(testing::Message() << "tick " << tick.count() << " ms");
    Rig rig;
    rig.tick_period = tick;
    rig.connect_in_can_mode();
    ASSERT_TRUE(rig.ctl->set_command(BodyTwist{0.4, 0, 0}, rig.now).ok());
    rig.run(rig.tick_period);  // the command goes out at once
    ASSERT_EQ(rig.bus.count(protocol::kMotionCommandId), 1u);
    rig.bus.clear_sent();
    for (int i = 0; i < 10; ++i) {  // refreshed every 40 ms, well within cmd_timeout
      rig.run(40ms);
      ASSERT_TRUE(rig.ctl->set_command(BodyTwist{0.4, 0, 0}, rig.now).ok());
    }
    rig.bus.clear_sent();
    const Timestamp start = rig.now;
    rig.run(400ms);
    const auto frames = rig.motion_frames();
    ASSERT_GE(frames.size(), 19u);
    for (std::size_t i = 1; i < frames.size(); ++i) {
      EXPECT_EQ(frames[i].stamp - frames[i - 1].stamp, 20ms) << "frame " << i;
    }
    EXPECT_LE(frames.front().stamp - start, 20ms);
  }
}

TEST(ControllerKeepAlive, FixedRateScheduleDoesNotDriftWithAnUnalignedLoop) {
  Rig rig;
  rig.tick_period = 7ms;  // the owner's loop does not divide 20 ms
  rig.connect_in_can_mode();
  const Timestamp start = rig.now;
  rig.run(1400ms);
  const auto frames = rig.motion_frames();
  EXPECT_NEAR(static_cast<double>(frames.size()), 70.0, 1.0);  // 1.4 s / 20 ms
  for (std::size_t i = 1; i < frames.size(); ++i) {
    EXPECT_LE(frames[i].stamp - frames[i - 1].stamp, 20ms + rig.tick_period);
  }
  EXPECT_LE(frames.front().stamp - start, 20ms + rig.tick_period);
}

TEST(ControllerKeepAlive, AnOwnerSleepingUntilNextTickDueKeepsThePeriod) {
  Rig rig;
  rig.connect_in_can_mode();
  ASSERT_TRUE(rig.ctl->set_command(BodyTwist{0.4, 0, 0}, rig.now).ok());
  // An event loop: wake at next_tick_due() (or when feedback arrives), tick, sleep again.
  rig.ctl->tick(rig.now);
  rig.bus.clear_sent();
  for (int i = 0; i < 100; ++i) {
    const Timestamp due = rig.ctl->next_tick_due();
    ASSERT_GT(due, rig.now - 1ns);
    ASSERT_LE(due - rig.now, 20ms);
    rig.now = std::min(due, rig.next_feedback);
    if (rig.now == rig.next_feedback) {
      rig.feedback();
      rig.next_feedback = rig.now + 20ms;
    }
    if (i % 10 == 0) ASSERT_TRUE(rig.ctl->set_command(BodyTwist{0.4, 0, 0}, rig.now).ok());
    rig.ctl->tick(rig.now);
  }
  const auto frames = rig.motion_frames();
  ASSERT_GE(frames.size(), 10u);
  for (std::size_t i = 1; i < frames.size(); ++i) {
    EXPECT_LE(frames[i].stamp - frames[i - 1].stamp, 20ms) << "frame " << i;
  }
}

TEST(ControllerKeepAlive, IdleInCanModeStillSendsZeroEvery20Ms) {
  Rig rig;
  rig.connect_in_can_mode();
  rig.run(200ms);
  const auto frames = rig.motion_frames();
  ASSERT_EQ(frames.size(), 10u);
  for (const CanFrame& f : frames)
    EXPECT_TRUE(is_zero(motion_of(f)));
}

TEST(ControllerTimeout, CommandTimeoutSendsZeroWithinOnePeriod) {
  Rig rig;
  rig.connect_in_can_mode();
  ASSERT_TRUE(rig.ctl->set_command(BodyTwist{0.6, 0, 0}, rig.now).ok());
  const Timestamp commanded = rig.now;
  rig.run(1s);
  const auto frames = rig.motion_frames();
  const auto first_zero = std::find_if(frames.begin(), frames.end(),
                                       [](const CanFrame& f) { return is_zero(motion_of(f)); });
  ASSERT_NE(first_zero, frames.end());
  ASSERT_NE(first_zero, frames.begin());
  for (auto it = frames.begin(); it != first_zero; ++it) {
    EXPECT_TRUE(is_moving(*it));
    EXPECT_LT(it->stamp - commanded, 500ms);
  }
  EXPECT_GE(first_zero->stamp - commanded, 500ms);
  EXPECT_LE(first_zero->stamp - commanded, 520ms);
  for (auto it = first_zero; it != frames.end(); ++it)
    EXPECT_TRUE(is_zero(motion_of(*it)));
  EXPECT_TRUE(rig.state().cmd_timed_out);
  EXPECT_EQ(rig.state().refusal, MotionRefusal::kCmdTimeout);
  EXPECT_EQ(rig.state().counters.cmd_timeouts, 1u);

  // A new command resumes at once.
  rig.bus.clear_sent();
  ASSERT_TRUE(rig.ctl->set_command(BodyTwist{0.6, 0, 0}, rig.now).ok());
  rig.run(1ms);
  ASSERT_EQ(rig.bus.count(protocol::kMotionCommandId), 1u);
  EXPECT_TRUE(is_moving(rig.motion_frames()[0]));
  EXPECT_FALSE(rig.state().cmd_timed_out);
  EXPECT_EQ(rig.state().refusal, MotionRefusal::kNone);
}

TEST(ControllerTimeout, ConfigurableTimeout) {
  ControllerConfig cfg;
  cfg.cmd_timeout = 200ms;
  Rig rig(cfg);
  rig.connect_in_can_mode();
  ASSERT_TRUE(rig.ctl->set_command(BodyTwist{0.6, 0, 0}, rig.now).ok());
  rig.run(199ms);
  EXPECT_FALSE(rig.state().cmd_timed_out);
  rig.run(2ms);
  EXPECT_TRUE(rig.state().cmd_timed_out);
}

TEST(ControllerCommand, NaNIsRefusedAndStops) {
  Rig rig;
  rig.connect_in_can_mode();
  ASSERT_TRUE(rig.ctl->set_command(BodyTwist{0.6, 0, 0}, rig.now).ok());
  rig.run(40ms);
  const Status st =
      rig.ctl->set_command(BodyTwist{std::numeric_limits<double>::quiet_NaN(), 0, 0}, rig.now);
  ASSERT_FALSE(st.ok());
  EXPECT_EQ(st.error().code, Errc::kNotFinite);
  rig.bus.clear_sent();
  rig.run(1ms);
  ASSERT_EQ(rig.bus.count(protocol::kMotionCommandId), 1u);
  EXPECT_TRUE(is_zero(motion_of(rig.motion_frames()[0])));
}

// ---- shutdown ----------------------------------------------------------------------------------

TEST(ControllerShutdown, SendsAStopAndThenNothing) {
  Rig rig;
  rig.connect_in_can_mode();
  ASSERT_TRUE(rig.ctl->set_command(BodyTwist{0.8, 0, 0}, rig.now).ok());
  rig.run(60ms);
  ASSERT_TRUE(is_moving(rig.bus.sent.back()));
  rig.ctl->shutdown(rig.now);
  ASSERT_EQ(rig.bus.sent.back().id, protocol::kMotionCommandId);
  EXPECT_TRUE(is_zero(motion_of(rig.bus.sent.back())));
  const std::size_t n = rig.bus.sent.size();
  rig.run(200ms);
  EXPECT_EQ(rig.bus.sent.size(), n);
  EXPECT_FALSE(rig.ctl->set_command(BodyTwist{0.8, 0, 0}, rig.now).ok());
  rig.ctl->shutdown(rig.now);  // idempotent
  EXPECT_EQ(rig.bus.sent.size(), n);
}

TEST(ControllerShutdown, DestructionSendsAStop) {
  Rig rig;
  rig.connect_in_can_mode();
  ASSERT_TRUE(rig.ctl->set_command(BodyTwist{0.8, 0, 0}, rig.now).ok());
  rig.run(60ms);
  ASSERT_TRUE(is_moving(rig.bus.sent.back()));
  rig.ctl.reset();
  ASSERT_EQ(rig.bus.sent.back().id, protocol::kMotionCommandId);
  EXPECT_TRUE(is_zero(motion_of(rig.bus.sent.back())));
}

// ---- motion-mode switching ---------------------------------------------------------------------

TEST(ControllerModeSwitch, StopsWaitsForStandstillSwitchesAndResumes) {
  Rig rig;
  rig.connect_in_can_mode(MotionMode::kAckermann);
  auto command = [&](BodyTwist t, std::chrono::nanoseconds d) {
    for (auto e = 0ns; e < d; e += 20ms) {
      ASSERT_TRUE(rig.ctl->set_command(t, rig.now).ok());
      rig.run(20ms);
    }
  };
  command({0.5, 0, 0}, 200ms);
  rig.wheel_speed = 0.5;  // the chassis is moving
  command({0.5, 0, 0}, 100ms);
  ASSERT_TRUE(is_moving(rig.motion_frames().back()));

  // Ask for a pure rotation: spin mode is needed.
  command({0, 0, 0.8}, 400ms);  // still moving according to the feedback
  EXPECT_EQ(rig.bus.count(protocol::kMotionModeCommandId), 0u) << "0x141 while moving";
  EXPECT_EQ(rig.state().mode_switch.phase, ModeSwitchPhase::kStopping);
  EXPECT_EQ(rig.state().refusal, MotionRefusal::kSwitching);
  EXPECT_TRUE(is_zero(motion_of(rig.motion_frames().back())));

  rig.wheel_speed = 0.0;  // standstill reached
  command({0, 0, 0.8}, 40ms);
  const auto mode_cmds = rig.bus.sent_with_id(protocol::kMotionModeCommandId);
  ASSERT_EQ(mode_cmds.size(), 1u);
  EXPECT_EQ(mode_cmds[0].data[0], 0x02);  // spin
  EXPECT_EQ(rig.state().mode_switch.phase, ModeSwitchPhase::kAwaitingConfirmation);

  // The chassis switches for 500 ms: first reporting the old mode, then the new one, with
  // switching = 1 throughout; only switching = 0 completes it.
  rig.switching = true;
  command({0, 0, 0.8}, 300ms);
  rig.mode = MotionMode::kSpin;
  command({0, 0, 0.8}, 200ms);
  EXPECT_EQ(rig.state().mode_switch.phase, ModeSwitchPhase::kAwaitingConfirmation);
  rig.switching = false;
  command({0, 0, 0.8}, 100ms);
  EXPECT_EQ(rig.state().mode_switch.phase, ModeSwitchPhase::kIdle);
  EXPECT_EQ(rig.state().motion_mode, MotionMode::kSpin);
  EXPECT_EQ(rig.state().refusal, MotionRefusal::kNone);

  // Ordering over the whole run: after the last moving 0x111 comes the 0x141; between the 0x141
  // and the chassis's confirmation every 0x111 is zero; then spin commands follow.
  const auto& sent = rig.bus.sent;
  const auto mode_it = std::find_if(sent.begin(), sent.end(), [](const CanFrame& f) {
    return f.id == protocol::kMotionModeCommandId;
  });
  ASSERT_NE(mode_it, sent.end());
  const Timestamp confirmed_by = mode_it->stamp + 540ms;
  bool spun = false;
  for (auto it = mode_it; it != sent.end(); ++it) {
    if (it->id != protocol::kMotionCommandId) continue;
    const MotionCommand c = motion_of(*it);
    if (it->stamp < confirmed_by) {
      EXPECT_TRUE(is_zero(c)) << "speed command while switching";
    }
    if (c.spin_speed != 0.0) spun = true;
    EXPECT_EQ(c.linear_speed, 0.0);
  }
  EXPECT_TRUE(spun);
  const auto last_moving =
      std::find_if(sent.rbegin(), sent.rend(), [](const CanFrame& f) { return is_moving(f); });
  ASSERT_NE(last_moving, sent.rend());
  EXPECT_LT(last_moving->stamp, mode_it->stamp);
  EXPECT_GT(rig.motion_frames().back().data[4] | rig.motion_frames().back().data[5], 0);
}

TEST(ControllerModeSwitch, ForcedModeAndRetryThenReportWhenNeverConfirmed) {
  Rig rig;
  rig.connect_in_can_mode(MotionMode::kAckermann);
  const Timestamp start = rig.now;
  for (int i = 0; i < 250; ++i) {  // 5 s
    MotionRequest req;
    req.twist = {0.4, 0, 0};
    req.mode = MotionMode::kOblique;
    ASSERT_TRUE(rig.ctl->set_command(req, rig.now).ok());
    rig.run(20ms);
  }
  // Standstill at once (wheel speed 0): 0x141 at the start, then every 1.5 s.
  const auto mode_cmds = rig.bus.sent_with_id(protocol::kMotionModeCommandId);
  ASSERT_EQ(mode_cmds.size(), 4u);  // t = 0, 1.5, 3.0, 4.5 s
  for (std::size_t i = 0; i < mode_cmds.size(); ++i) {
    EXPECT_EQ(mode_cmds[i].data[0], 0x01);
    EXPECT_LE(mode_cmds[i].stamp - start, 1500ms * static_cast<long>(i) + 1ms);
    if (i > 0) EXPECT_EQ(mode_cmds[i].stamp - mode_cmds[i - 1].stamp, 1500ms);
  }
  EXPECT_TRUE(rig.state().mode_switch.failed);
  EXPECT_NE(
      std::find(rig.state().faults.begin(), rig.state().faults.end(), "motion_mode_switch_failed"),
      rig.state().faults.end());
  for (const CanFrame& f : rig.motion_frames())
    EXPECT_TRUE(is_zero(motion_of(f)));

  EXPECT_EQ(rig.state().refusal, MotionRefusal::kModeSwitchFailed);

  // The chassis finally gets there: the failure clears, but a failed switch was an involuntary
  // stop: the crab drives only after the re-arm.
  rig.mode = MotionMode::kOblique;
  MotionRequest req;
  req.twist = {0.4, 0, 0};
  req.mode = MotionMode::kOblique;
  ASSERT_TRUE(rig.ctl->set_command(req, rig.now).ok());
  rig.run(40ms);
  EXPECT_FALSE(rig.state().mode_switch.failed);
  EXPECT_EQ(rig.state().refusal, MotionRefusal::kRearmRequired);
  EXPECT_TRUE(is_zero(motion_of(rig.motion_frames().back())));
  ASSERT_TRUE(rig.ctl->resume(rig.now).ok());
  ASSERT_TRUE(rig.ctl->set_command(req, rig.now).ok());
  rig.run(40ms);
  EXPECT_TRUE(is_moving(rig.motion_frames().back()));
}

TEST(ControllerModeSwitch, ObliqueCrabWithNoisyVxNeverSwingsTheWheels) {
  Rig rig;
  rig.connect_in_can_mode(MotionMode::kOblique);
  MotionRequest req;
  req.mode = MotionMode::kOblique;
  for (int i = 0; i < 20; ++i) {
    req.twist = {i % 2 == 0 ? 1e-3 : -1e-3, 0.5, 0};  // sideways to the left, noisy vx
    ASSERT_TRUE(rig.ctl->set_command(req, rig.now).ok());
    rig.run(20ms);
  }
  int moving = 0;
  for (const CanFrame& f : rig.motion_frames()) {
    const MotionCommand c = motion_of(f);
    if (c.linear_speed == 0.0) continue;
    ++moving;
    // One wheel line throughout: about 90 deg left, driven forwards.
    EXPECT_GT(interpretation::rep103_from_manual_command_steering(c.steering_angle),
              89.0 * M_PI / 180.0);
    EXPECT_GT(c.linear_speed, 0.0);
  }
  EXPECT_GE(moving, 15);
}

TEST(ControllerModeSwitch, ChassisReportedSwitchingRefusesMotion) {
  Rig rig;
  rig.connect_in_can_mode();
  rig.switching = true;  // e.g. the remote's SWD switch
  ASSERT_TRUE(rig.ctl->set_command(BodyTwist{0.4, 0, 0}, rig.now).ok());
  rig.run(100ms);
  EXPECT_EQ(rig.state().refusal, MotionRefusal::kSwitching);
  for (const CanFrame& f : rig.motion_frames())
    EXPECT_TRUE(is_zero(motion_of(f)));
}

TEST(ControllerModeSwitch, UnknownModeRefusesMotion) {
  Rig rig;
  rig.send_mode = false;
  rig.connect_in_can_mode();
  ASSERT_TRUE(rig.ctl->set_command(BodyTwist{0.4, 0, 0}, rig.now).ok());
  rig.run(100ms);
  EXPECT_EQ(rig.state().refusal, MotionRefusal::kModeUnknown);
  for (const CanFrame& f : rig.motion_frames())
    EXPECT_TRUE(is_zero(motion_of(f)));
}

// ---- faults ------------------------------------------------------------------------------------

bool has_fault(const ControllerState& s, const std::string& name) {
  return std::find(s.faults.begin(), s.faults.end(), name) != s.faults.end();
}

TEST(ControllerFaults, EstopAbnormalAndCriticalBitsAreNamedAndStop) {
  Rig rig;
  rig.connect_in_can_mode();
  auto drive = [&] {
    ASSERT_TRUE(rig.ctl->set_command(BodyTwist{0.4, 0, 0}, rig.now).ok());
    rig.run(40ms);
  };
  drive();
  ASSERT_TRUE(is_moving(rig.motion_frames().back()));

  rig.vehicle = 0x01;  // e-stop (interpretation open point 4)
  drive();
  EXPECT_EQ(rig.state().refusal, MotionRefusal::kEstop);
  EXPECT_TRUE(has_fault(rig.state(), "emergency_stop"));
  EXPECT_TRUE(is_zero(motion_of(rig.motion_frames().back())));

  rig.vehicle = 0x02;
  const std::uint32_t collision = 1u << protocol::error_bit_index(5, 5);
  ASSERT_TRUE(protocol::is_critical_error(collision));
  rig.errors = collision;
  drive();
  EXPECT_EQ(rig.state().refusal, MotionRefusal::kCriticalError);
  EXPECT_TRUE(has_fault(rig.state(), "vehicle_abnormal"));
  for (const std::string& name : protocol::error_bit_names(collision)) {
    EXPECT_TRUE(has_fault(rig.state(), name)) << name;
  }
  EXPECT_TRUE(is_zero(motion_of(rig.motion_frames().back())));

  rig.vehicle = 0x00;
  rig.errors = 0;
  drive();  // the causes cleared by themselves: no restart on the commander's stale twist
  EXPECT_EQ(rig.state().refusal, MotionRefusal::kRearmRequired);
  EXPECT_TRUE(rig.state().faults.empty());
  EXPECT_TRUE(is_zero(motion_of(rig.motion_frames().back())));
  EXPECT_EQ(describe(rig.state().latched_causes), "emergency_stop,critical_error");
  ASSERT_TRUE(rig.ctl->resume(rig.now).ok());
  drive();
  EXPECT_EQ(rig.state().refusal, MotionRefusal::kNone);
  EXPECT_TRUE(is_moving(rig.motion_frames().back()));
}

TEST(ControllerFaults, LowBatteryIsTheReasonMotionIsRefused) {
  Rig rig;
  rig.soc = 8.0;
  rig.connect_in_can_mode();
  ASSERT_TRUE(rig.ctl->set_command(BodyTwist{0.4, 0, 0}, rig.now).ok());
  rig.run(40ms);
  EXPECT_EQ(rig.state().refusal, MotionRefusal::kLowBattery);
  EXPECT_TRUE(rig.state().low_battery());
  EXPECT_TRUE(has_fault(rig.state(), "low_battery"));
  EXPECT_TRUE(is_zero(motion_of(rig.motion_frames().back())));
  rig.soc = 55.0;
  ASSERT_TRUE(rig.ctl->set_command(BodyTwist{0.4, 0, 0}, rig.now).ok());
  rig.run(40ms);
  EXPECT_EQ(rig.state().refusal, MotionRefusal::kRearmRequired);
  EXPECT_DOUBLE_EQ(*rig.state().battery_soc, 55.0);
  ASSERT_TRUE(rig.ctl->resume(rig.now).ok());
  ASSERT_TRUE(rig.ctl->set_command(BodyTwist{0.4, 0, 0}, rig.now).ok());
  rig.run(40ms);
  EXPECT_EQ(rig.state().refusal, MotionRefusal::kNone);
}

TEST(ControllerFaults, ClearErrorsSendsEachCodeAndRejectsUnknownOnes) {
  Rig rig;
  rig.connect_in_can_mode();
  for (std::uint8_t code = 0; code <= protocol::kMaxErrorClearCode; ++code) {
    ASSERT_TRUE(rig.ctl->clear_errors(code, rig.now).ok());
    const CanFrame& f = rig.bus.sent.back();
    EXPECT_EQ(f.id, protocol::kErrorClearCommandId);
    EXPECT_EQ(f.dlc, 1);
    EXPECT_EQ(f.data[0], code);
  }
  const std::size_t n = rig.bus.sent.size();
  const Status bad = rig.ctl->clear_errors(0x11, rig.now);
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().code, Errc::kInvalidArgument);
  EXPECT_EQ(rig.bus.sent.size(), n);
}

TEST(ControllerUltrasonic, ConfirmedVia45A) {
  Rig rig;
  rig.connect_in_can_mode();
  ASSERT_TRUE(rig.ctl->set_ultrasonic(true, rig.now).ok());
  ASSERT_EQ(rig.bus.count(protocol::kUltrasonicSettingId), 1u);
  EXPECT_EQ(rig.bus.sent_with_id(protocol::kUltrasonicSettingId)[0].data[0], 0x01);
  EXPECT_EQ(rig.state().ultrasonic_requested, true);
  rig.run(100ms);
  rig.inject(UltrasonicSettingFeedback{true});
  EXPECT_FALSE(rig.state().ultrasonic_requested.has_value());
  EXPECT_EQ(rig.state().ultrasonic_enabled, true);
  rig.run(2s);
  EXPECT_EQ(rig.bus.count(protocol::kUltrasonicSettingId), 1u);  // no resend once confirmed
  EXPECT_FALSE(rig.state().ultrasonic_failed);
}

TEST(ControllerUltrasonic, UnconfirmedIsResentThenReported) {
  Rig rig;
  rig.connect_in_can_mode();
  ASSERT_TRUE(rig.ctl->set_ultrasonic(false, rig.now).ok());
  rig.run(3s);
  EXPECT_EQ(rig.bus.count(protocol::kUltrasonicSettingId), 3u);
  EXPECT_TRUE(rig.state().ultrasonic_failed);
  EXPECT_TRUE(has_fault(rig.state(), "ultrasonic_setting_unconfirmed"));
}

// ---- limits and feedback snapshot --------------------------------------------------------------

TEST(ControllerLimits, AccelerationIsLimited) {
  ControllerConfig cfg;
  cfg.limit_vx.has_acceleration_limits = true;
  cfg.limit_vx.max_acceleration = 1.0;
  cfg.limit_vx.min_acceleration = -1.0;
  Rig rig(cfg);
  rig.connect_in_can_mode();
  for (int i = 0; i < 30; ++i) {
    ASSERT_TRUE(rig.ctl->set_command(BodyTwist{1.0, 0, 0}, rig.now).ok());
    rig.run(20ms);
  }
  const auto frames = rig.motion_frames();
  double previous = 0.0;
  for (const CanFrame& f : frames) {
    const double v = motion_of(f).linear_speed;
    EXPECT_LE(v - previous, 0.02 + 1e-3);  // 1 m/s^2 over 20 ms (+ 1 mm/s quantisation)
    previous = v;
  }
  EXPECT_NEAR(previous, 0.6, 0.03);  // ~0.6 s of ramping
}

TEST(ControllerFeedback, SnapshotKeepsEveryKindOfFeedback) {
  Rig rig;
  rig.connect_in_can_mode();
  rig.inject(MotorHighSpeedFeedback{3, 120.0, 1.5, 1000});
  rig.inject(MotorLowSpeedFeedback{7, 48.0, 30.0, 35.0, 0});
  BmsAlarm alarm;
  alarm.battery = 2;
  alarm.alarm1 = 0x04;
  rig.inject(alarm);
  UltrasonicFeedback us;
  us.first_sensor = 5;
  us.raw = {100, -1, 300, 400};
  rig.inject(us);
  SteeringAnglesFeedback angles;
  angles.angles = {0.1, 0.2, 0.3, 0.4};
  rig.inject(angles);
  const ChassisFeedback& fb = rig.ctl->feedback();
  ASSERT_TRUE(fb.motor_high_speed[2].has_value());
  EXPECT_DOUBLE_EQ(fb.motor_high_speed[2]->value.rpm, 120.0);
  ASSERT_TRUE(fb.motor_low_speed[6].has_value());
  ASSERT_TRUE(fb.bms_alarm[2].has_value());
  EXPECT_EQ(fb.bms_alarm[2]->value.alarm1, 0x04);
  ASSERT_TRUE(fb.ultrasonic[1].has_value());
  EXPECT_EQ(fb.ultrasonic[1]->value.raw[1], -1);
  ASSERT_TRUE(fb.steering_angles.has_value());
  ASSERT_TRUE(fb.system_status.has_value());
  ASSERT_TRUE(fb.wheel_speeds.has_value());
  ASSERT_TRUE(fb.motion.has_value());
  ASSERT_TRUE(fb.motion_mode.has_value());

  CanFrame garbage;
  garbage.id = 0x7FF;
  garbage.dlc = 2;
  rig.ctl->on_frame(garbage, rig.now);
  EXPECT_EQ(rig.state().counters.decode_errors, 1u);
  EXPECT_FALSE(rig.state().last_error.empty());
}

// ---- re-arm, steer first, small twists, prompt sends ----------------------------

TEST(ControllerRearm, ResumeIsRefusedWhileTheCauseIsActiveAndSendsNothing) {
  Rig rig;
  rig.connect_in_can_mode();
  rig.vehicle = 0x01;  // e-stop pressed
  rig.run(40ms);
  rig.bus.clear_sent();
  const Status st = rig.ctl->resume(rig.now);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.error().message.find("emergency_stop"), std::string::npos) << st.error().message;
  EXPECT_TRUE(rig.bus.sent.empty());
  // A zero twist while the e-stop is still pressed does not re-arm either.
  ASSERT_TRUE(rig.ctl->set_command(BodyTwist{}, rig.now).ok());
  rig.vehicle = 0x00;  // released
  ASSERT_TRUE(rig.ctl->set_command(BodyTwist{0.4, 0, 0}, rig.now).ok());
  rig.run(100ms);
  EXPECT_EQ(rig.state().refusal, MotionRefusal::kRearmRequired);
  for (const CanFrame& f : rig.motion_frames())
    EXPECT_TRUE(is_zero(motion_of(f)));
  EXPECT_TRUE(rig.ctl->resume(rig.now).ok());
  ASSERT_TRUE(rig.ctl->set_command(BodyTwist{0.4, 0, 0}, rig.now).ok());
  rig.run(40ms);
  EXPECT_TRUE(is_moving(rig.motion_frames().back()));
}

TEST(ControllerRearm, TheCommandTimeoutIsTheCommandersOwnStopAndNeedsNoRearm) {
  Rig rig;
  rig.connect_in_can_mode();
  ASSERT_TRUE(rig.ctl->set_command(BodyTwist{0.4, 0, 0}, rig.now).ok());
  rig.run(700ms);
  EXPECT_EQ(rig.state().refusal, MotionRefusal::kCmdTimeout);
  EXPECT_FALSE(rig.state().rearm_required());
  ASSERT_TRUE(rig.ctl->set_command(BodyTwist{0.4, 0, 0}, rig.now).ok());
  rig.run(20ms);
  EXPECT_EQ(rig.state().refusal, MotionRefusal::kNone);
  EXPECT_TRUE(is_moving(rig.motion_frames().back()));
}

// A zero twist is no re-arm (a navigation stack publishes them by itself): only resume, unless
// the owner opted in with rearm_on_zero_twist.
TEST(ControllerRearm, AZeroTwistRearmsOnlyWhereTheOwnerOptedIn) {
  for (const bool opted_in : {false, true}) {
    ControllerConfig cfg;
    cfg.rearm_on_zero_twist = opted_in;
    Rig rig(cfg);
    rig.connect_in_can_mode();
    EXPECT_EQ(rig.state().zero_twist_rearms, opted_in);
    rig.vehicle = 0x01;  // e-stop
    rig.run(40ms);
    rig.vehicle = 0x00;  // released
    rig.run(40ms);
    ASSERT_EQ(rig.state().refusal, MotionRefusal::kRearmRequired);
    for (int i = 0; i < 10; ++i) {
      ASSERT_TRUE(rig.ctl->set_command(BodyTwist{}, rig.now).ok());
      rig.run(20ms);
    }
    rig.bus.clear_sent();
    for (int i = 0; i < 10; ++i) {
      ASSERT_TRUE(rig.ctl->set_command(BodyTwist{0.5, 0, 0}, rig.now).ok());
      rig.run(20ms);
    }
    EXPECT_EQ(rig.state().refusal, opted_in ? MotionRefusal::kNone : MotionRefusal::kRearmRequired)
        << "opted in: " << opted_in;
    EXPECT_EQ(is_moving(rig.motion_frames().back()), opted_in) << "opted in: " << opted_in;
    EXPECT_EQ(rig.state().counters.rearms, opted_in ? 1u : 0u);
  }
}

TEST(ControllerCommand, ANonFiniteComponentInAnyOfTheSixIsRefusedByNameWhileItLasts) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  struct Case {
    MotionRequest request;
    const char* named;
  };
  const Case cases[] = {
      {MotionRequest{BodyTwist{nan, 0, 0}}, "linear.x is NaN"},
      {MotionRequest{BodyTwist{0.3, -inf, 0}}, "linear.y is infinite"},
      {MotionRequest{BodyTwist{0.3, 0, 0}, std::nullopt, OutOfPlaneTwist{nan, 0, 0}},
       "linear.z is NaN"},
      {MotionRequest{BodyTwist{0.3, 0, 0}, std::nullopt, OutOfPlaneTwist{0, inf, 0}},
       "angular.x is infinite"},
      {MotionRequest{BodyTwist{0.3, 0, 0}, std::nullopt, OutOfPlaneTwist{0, 0, nan}},
       "angular.y is NaN"},
      {MotionRequest{BodyTwist{0.3, 0, inf}}, "angular.z is infinite"},
  };
  for (const Case& c : cases) {
    Rig rig;
    rig.connect_in_can_mode();
    ASSERT_TRUE(rig.ctl->set_command(BodyTwist{0.3, 0, 0}, rig.now).ok());
    rig.run(40ms);
    ASSERT_TRUE(is_moving(rig.motion_frames().back()));
    // A stream of the bad twist, 1 s: refused, named, stopped the whole time.
    for (int i = 0; i < 20; ++i) {
      const Status st = rig.ctl->set_command(c.request, rig.now);
      ASSERT_FALSE(st.ok());
      EXPECT_EQ(st.error().code, Errc::kNotFinite);
      EXPECT_NE(st.error().message.find(c.named), std::string::npos) << st.error().message;
      rig.run(50ms);
      EXPECT_EQ(rig.state().refusal, MotionRefusal::kInvalidCommand) << c.named;
      EXPECT_EQ(rig.state().invalid_command, c.named);
      EXPECT_TRUE(is_zero(motion_of(rig.motion_frames().back()))) << c.named;
    }
    EXPECT_EQ(rig.state().counters.invalid_commands, 20u);
    // The next valid twist drives again (the commander's own mistake: no re-arm).
    ASSERT_TRUE(rig.ctl->set_command(BodyTwist{0.3, 0, 0}, rig.now).ok());
    rig.run(40ms);
    EXPECT_EQ(rig.state().refusal, MotionRefusal::kNone);
    EXPECT_TRUE(rig.state().invalid_command.empty());
    EXPECT_TRUE(is_moving(rig.motion_frames().back()));
    // A bad stream that stops: the command timeout takes over the naming.
    ASSERT_FALSE(rig.ctl->set_command(c.request, rig.now).ok());
    rig.run(600ms);
    EXPECT_EQ(rig.state().refusal, MotionRefusal::kCmdTimeout);
  }
}

// A stamped command older than cmd_timeout must not drive: refused, said (kStaleCommand), the
// chassis stopped until a fresh one comes; one within cmd_timeout (or unstamped) drives.
TEST(ControllerCommand, AStampedCommandOlderThanTheCommandTimeoutIsRefusedWhileItLasts) {
  Rig rig;
  rig.connect_in_can_mode();
  MotionRequest fresh{BodyTwist{0.3, 0, 0}};
  fresh.age = 100ms;
  ASSERT_TRUE(rig.ctl->set_command(fresh, rig.now).ok());
  rig.run(40ms);
  ASSERT_TRUE(is_moving(rig.motion_frames().back()));
  MotionRequest stale{BodyTwist{0.3, 0, 0}};
  stale.age = 800ms;  // cmd_timeout: 500 ms
  for (int i = 0; i < 20; ++i) {
    const Status st = rig.ctl->set_command(stale, rig.now);
    ASSERT_FALSE(st.ok());
    EXPECT_EQ(st.error().code, Errc::kTimeout);
    rig.run(50ms);
    EXPECT_EQ(rig.state().refusal, MotionRefusal::kStaleCommand);
    EXPECT_EQ(rig.state().stale_command, "stamped 0.8 s ago, older than cmd_vel_timeout 0.5 s");
    EXPECT_TRUE(is_zero(motion_of(rig.motion_frames().back())));
  }
  EXPECT_EQ(to_string(MotionRefusal::kStaleCommand), "stale_command");
  ASSERT_TRUE(rig.ctl->set_command(fresh, rig.now).ok());
  rig.run(40ms);
  EXPECT_EQ(rig.state().refusal, MotionRefusal::kNone);
  EXPECT_TRUE(rig.state().stale_command.empty());
  EXPECT_TRUE(is_moving(rig.motion_frames().back()));
}

TEST(ControllerCommand, TheModesADriverCanForceAreTheProfilesOwn) {
  using M = MotionMode;
  EXPECT_EQ(drivable_modes(manual_profile()),
            (std::vector<M>{M::kAckermann, M::kOblique, M::kSpin}));
  EXPECT_EQ(drivable_modes(*protocol_preset("agx_v2")),
            (std::vector<M>{M::kAckermann, M::kOblique, M::kSpin, M::kSideSlip}));
  const Status st = check_drivable(M::kSideSlip, manual_profile());
  ASSERT_FALSE(st.ok());
  EXPECT_EQ(st.error().message,
            "side_slip: unsupported by protocol manual (it drives ackermann, oblique, spin)");
  EXPECT_FALSE(check_drivable(M::kPark, *protocol_preset("agx_v2")).ok());
  EXPECT_TRUE(check_drivable(M::kSideSlip, *protocol_preset("agx_v2")).ok());
}

TEST(ControllerRearm, StartUpInStandbyIsNotAnInvoluntaryStop) {
  Rig rig;
  rig.obey_control_requests = true;
  ASSERT_TRUE(rig.ctl->set_command(BodyTwist{0.4, 0, 0}, rig.now).ok());
  for (int i = 0; i < 20; ++i) {
    ASSERT_TRUE(rig.ctl->set_command(BodyTwist{0.4, 0, 0}, rig.now).ok());
    rig.run(20ms);
  }
  EXPECT_EQ(rig.state().refusal, MotionRefusal::kNone);
  EXPECT_TRUE(is_moving(rig.motion_frames().back()));
}

TEST(ControllerSteerFirst, SidewaysFromStraightWaitsForTheWheels) {
  Rig rig;
  rig.wheel_angles = std::array<double, 4>{0, 0, 0, 0};
  rig.connect_in_can_mode(MotionMode::kOblique);
  MotionRequest req;
  req.twist = {0, 0.4, 0};
  for (int i = 0; i < 5; ++i) {
    ASSERT_TRUE(rig.ctl->set_command(req, rig.now).ok());
    rig.run(20ms);
  }
  // Wheels still straight: the 90 deg steering goes out, the speed is held at zero.
  MotionCommand c = motion_of(rig.motion_frames().back());
  EXPECT_EQ(c.linear_speed, 0.0);
  EXPECT_NEAR(interpretation::rep103_from_manual_command_steering(c.steering_angle), M_PI / 2,
              1e-3);
  EXPECT_EQ(rig.state().steer_first_factor, 0.0);
  EXPECT_EQ(rig.state().refusal, MotionRefusal::kNone);
  // Halfway through the threshold band: part of the speed.
  const double at = M_PI / 2 - 15.0 * M_PI / 180.0;              // 15 deg off
  rig.wheel_angles = std::array<double, 4>{-at, -at, -at, -at};  // manual signs: left negative
  ASSERT_TRUE(rig.ctl->set_command(req, rig.now).ok());
  rig.run(40ms);
  c = motion_of(rig.motion_frames().back());
  EXPECT_NEAR(c.linear_speed, 0.2, 0.01);
  // Wheels there: full speed.
  rig.wheel_angles = std::array<double, 4>{-M_PI / 2, -M_PI / 2, -M_PI / 2, -M_PI / 2};
  ASSERT_TRUE(rig.ctl->set_command(req, rig.now).ok());
  rig.run(40ms);
  c = motion_of(rig.motion_frames().back());
  EXPECT_NEAR(c.linear_speed, 0.4, 1e-3);
  EXPECT_EQ(rig.state().steer_first_factor, 1.0);
}

TEST(ControllerSmallTwists, BelowTheResolutionIsRefusedByName) {
  Rig rig;
  rig.connect_in_can_mode();
  ASSERT_TRUE(rig.ctl->set_command(BodyTwist{0.0003, 0, 0}, rig.now).ok());
  rig.run(40ms);
  EXPECT_EQ(rig.state().refusal, MotionRefusal::kBelowMinimum);
  EXPECT_EQ(to_string(MotionRefusal::kBelowMinimum), "below_minimum");
  ASSERT_TRUE(rig.ctl->set_command(BodyTwist{0.05, 0, 0}, rig.now).ok());
  rig.run(20ms);
  EXPECT_EQ(rig.state().refusal, MotionRefusal::kNone);
  EXPECT_TRUE(is_moving(rig.motion_frames().back()));
}

TEST(ControllerLatency, AChangedCommandIsNotHeldBackByAKeepAlive) {
  Rig rig;
  rig.connect_in_can_mode();
  rig.run(100ms);
  // Right after a keep-alive (sent by the tick 1 ms ago), change the command: it goes out at once.
  while (rig.motion_frames().empty() || rig.motion_frames().back().stamp != rig.now - 1ms) {
    rig.run(1ms);
  }
  rig.bus.clear_sent();
  ASSERT_TRUE(rig.ctl->set_command(BodyTwist{0.3, 0, 0}, rig.now).ok());
  EXPECT_EQ(rig.ctl->next_tick_due(), rig.now) << "a pending command is due now";
  const Timestamp posted = rig.now;
  rig.ctl->tick(rig.now);
  ASSERT_EQ(rig.bus.count(protocol::kMotionCommandId), 1u);
  EXPECT_EQ(rig.motion_frames()[0].stamp, posted);
  EXPECT_TRUE(is_moving(rig.motion_frames()[0]));
  // A second change within min_command_interval waits for it, and next_tick_due says when.
  ASSERT_TRUE(rig.ctl->set_command(BodyTwist{0.35, 0, 0}, rig.now).ok());
  EXPECT_EQ(rig.ctl->next_tick_due(), posted + rig.ctl->config().min_command_interval);
}

TEST(ControllerEvents, EveryFrameSentIsReportedTheShutdownStopIncluded) {
  Rig rig;
  std::vector<SentFrame> seen;
  rig.connect_in_can_mode();
  rig.ctl->set_send_observer([&](const SentFrame& f) { seen.push_back(f); });
  ASSERT_TRUE(rig.ctl->set_command(BodyTwist{0.3, 0, 0}, rig.now).ok());
  rig.run(40ms);
  rig.ctl->shutdown(rig.now);
  ASSERT_EQ(seen.size(), rig.bus.sent.size() + 0u);
  for (std::size_t i = 0; i < seen.size(); ++i)
    EXPECT_EQ(seen[i].frame, rig.bus.sent[i]);
  EXPECT_TRUE(seen.back().shutdown);
  EXPECT_EQ(seen.back().frame.id, protocol::kMotionCommandId);
  EXPECT_EQ(seen.back().achieved.vx, 0.0);
  const auto moving =
      std::find_if(seen.begin(), seen.end(), [](const SentFrame& f) { return is_moving(f.frame); });
  ASSERT_NE(moving, seen.end());
  EXPECT_NEAR(moving->achieved.vx, 0.3, 1e-9);
}

TEST(ControllerConfig, Validation) {
  ControllerConfig cfg;
  EXPECT_TRUE(cfg.validate().ok());
  cfg.keep_alive_period = 600ms;
  EXPECT_FALSE(cfg.validate().ok());
  cfg = ControllerConfig{};
  cfg.cmd_timeout = 0ms;
  EXPECT_FALSE(cfg.validate().ok());
  cfg = ControllerConfig{};
  cfg.limit_vx.has_acceleration_limits = true;
  cfg.limit_vx.max_acceleration = -1;
  EXPECT_FALSE(cfg.validate().ok());
  EXPECT_EQ(to_string(MotionRefusal::kLowBattery), "low_battery");
  EXPECT_EQ(to_string(LinkState::kStale), "stale");
}

}  // namespace
}  // namespace ranger

// ---- the vendor's revision on the wire ----------------------------------------------

namespace ranger {
namespace {

TEST(ControllerProfile, SendsAndReadsTheProfilesWire) {
  ControllerConfig cfg;
  cfg.profile = *protocol_preset("agx_v2");
  test::FakeBus bus;
  ChassisController ctl(bus, cfg);
  Timestamp now{0};
  auto feed = [&](const Message& m) {
    auto f = encode(m, cfg.profile);
    ASSERT_TRUE(f.ok()) << f.error().message;
    ctl.on_frame(*f, now);
  };
  SystemStatus st;
  st.control_mode_raw = 1;
  st.control_mode = protocol::ControlMode::kCan;
  st.battery_voltage = 48.0;
  MotionModeFeedback mm;
  mm.mode = MotionMode::kAckermann;
  mm.mode_known = true;
  for (int i = 0; i < 5; ++i, now += 20ms) {
    st.counter = static_cast<std::uint8_t>(i);  // the agx_v2 counter: never a fault
    feed(st);
    feed(mm);
    ctl.tick(now);
  }
  ASSERT_TRUE(ctl.set_command(BodyTwist{0.3, 0, 0.1}, now).ok());
  ctl.tick(now);
  ASSERT_FALSE(bus.sent.empty());
  const CanFrame& f = bus.sent.back();
  EXPECT_EQ(f.id, protocol::kMotionCommandId);
  EXPECT_EQ(f.dlc, 8);
  auto m = decode(f, cfg.profile);
  ASSERT_TRUE(m.ok());
  EXPECT_NEAR(std::get<MotionCommand>(*m).linear_speed, 0.3, 1e-3);
  EXPECT_TRUE(ctl.state().faults.empty()) << "the counter in byte 7 is no fault";
  EXPECT_EQ(ctl.state().refusal, MotionRefusal::kNone);

  // A 16-bit error word: motor 1 communication is critical; its name is the agx_v2 table's.
  st.error_bits =
      protocol::fault_bit(protocol::Fault::kMotorCommunication, ErrorWordLayout::kAgxV2_16, 1);
  ASSERT_NE(st.error_bits, 0u);
  feed(st);
  ctl.tick(now);
  EXPECT_EQ(ctl.state().refusal, MotionRefusal::kCriticalError);
  EXPECT_FALSE(ctl.state().faults.empty());

  // Park mode (agx_v2 mode 3) is known to the protocol but cannot be driven in: no motion.
  st.error_bits = 0;
  feed(st);
  ASSERT_TRUE(ctl.resume(now).ok());  // the re-arm after the critical error
  ASSERT_TRUE(ctl.set_command(BodyTwist{0.3, 0, 0.1}, now).ok());
  mm.mode = MotionMode::kPark;
  feed(mm);
  ctl.tick(now);
  EXPECT_EQ(ctl.state().refusal, MotionRefusal::kModeUnknown);
}

}  // namespace
}  // namespace ranger
