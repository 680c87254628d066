// What the vendor's revisions add, through the driver runtime in lock-step with the virtual
// chassis (sim:agx_v2, sim:mini_v1, sim:mini_v3, sim): park, lights, the remote state, the
// firmware version, the MINI 3.0's drive mode, rear odometry and BMS alarms, and their refusals by
// name where the revision or the model lacks them. The tests of a mode switch (park) run against
// both reports of it, the manual's and the field's.
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "ranger_can/control/driver.hpp"
#include "ranger_can/control/model.hpp"
#include "ranger_can/sim/chassis_commands.hpp"
#include "ranger_can/sim/sim_bus_source.hpp"
#include "support/driver_sim_rig.hpp"

namespace ranger {
namespace {

using namespace std::chrono_literals;

// The shared lock-step rig (support/driver_sim_rig.hpp) with the driver the variant's `driver`
// options give (or `config`), the chassis answering 0x4A1 with `firmware`, and a switch report.
class Rig : public test::DriverSimRig {
 public:
  explicit Rig(const std::string& variant, const std::string& firmware = "",
               std::optional<DriverConfig> config = std::nullopt,
               test::SwitchReportUnderTest report = test::SwitchReportUnderTest::kVariants)
      : DriverSimRig(variant, config.value_or(test::driver_config_for(variant)),
                     options_with(firmware), report) {}

  // CAN mode, a known motion mode, and whether the chassis sends the vendor's frames decided.
  bool ready() {
    return DriverSimRig::ready(
        [](const DriverSnapshot& s) { return s.vendor_frames != VendorFrames::kUnknown; });
  }
  // Waits for request `id` to end (answered or failed).
  RequestOutcome outcome(std::uint64_t id, std::chrono::nanoseconds timeout = 8s) {
    run_until(
        [&] {
          const RequestOutcome* r = driver().snapshot()->request(id);
          return r && (r->state == RequestOutcome::State::kAnswered ||
                       r->state == RequestOutcome::State::kFailed);
        },
        timeout);
    const RequestOutcome* r = driver().snapshot()->request(id);
    return r ? *r : RequestOutcome{};
  }
  std::shared_ptr<const DriverSnapshot> snap() const { return snapshot(); }
  bool sent(std::uint32_t id) const {
    const auto& all = DriverSimRig::sent();
    return std::any_of(all.begin(), all.end(),
                       [id](const SentEvent& e) { return e.sent.frame.id == id; });
  }

 private:
  static sim::SimSourceOptions options_with(const std::string& firmware) {
    sim::SimSourceOptions options;
    if (!firmware.empty()) options.chassis.version = firmware;
    return options;
  }
};

// The driver's tests of a mode switch (park is one) run against both reports of it: the
// manual's (0x291 the mode being left, switching = 1 throughout) and the field's (the new mode
// at once, the flag on some switches, the wheels at 3.26 rad/s).
class DriverPark : public ::testing::TestWithParam<test::SwitchReportUnderTest> {};

TEST_P(DriverPark, RefusesMotionByNameUntilReleased) {
  Rig rig("agx_v2", "", std::nullopt, GetParam());
  ASSERT_TRUE(rig.ready());
  rig.drive({0.5, 0, 0}, 1s);
  ASSERT_GT(rig.chassis().speed, 0.3);
  // Park while moving: brought to rest first, then switched to park.
  const RequestOutcome on = rig.outcome(rig.driver().set_park(true));
  ASSERT_EQ(on.state, RequestOutcome::State::kAnswered) << on.message;
  EXPECT_EQ(rig.chassis().motion_mode, protocol::MotionMode::kPark);
  EXPECT_NEAR(rig.chassis().speed, 0.0, 1e-9);
  // Motion refused by name; the chassis stays where it is.
  const Pose2D parked_at = rig.chassis().pose;
  rig.drive({0.5, 0, 0}, 1s);
  EXPECT_EQ(rig.snap()->controller.refusal, MotionRefusal::kParked);
  EXPECT_EQ(to_string(rig.snap()->controller.refusal), "parked");
  EXPECT_NEAR(rig.chassis().pose.x, parked_at.x, 1e-6);
  // Released: the chassis leaves park by itself and the next twist drives.
  const RequestOutcome off = rig.outcome(rig.driver().set_park(false));
  ASSERT_EQ(off.state, RequestOutcome::State::kAnswered) << off.message;
  EXPECT_NE(rig.chassis().motion_mode, protocol::MotionMode::kPark);
  rig.drive({0.5, 0, 0}, 2s);
  EXPECT_EQ(rig.snap()->controller.refusal, MotionRefusal::kNone);
  EXPECT_GT(rig.chassis().pose.x, parked_at.x + 0.3);
}

TEST_P(DriverPark, ParkReleasedWithoutATwistLeavesParkAtOnce) {
  Rig rig("agx_v2", "", std::nullopt, GetParam());
  ASSERT_TRUE(rig.ready());
  ASSERT_EQ(rig.outcome(rig.driver().set_park(true)).state, RequestOutcome::State::kAnswered);
  ASSERT_EQ(rig.outcome(rig.driver().set_park(false)).state, RequestOutcome::State::kAnswered);
  EXPECT_EQ(rig.chassis().motion_mode, protocol::MotionMode::kAckermann);
  EXPECT_FALSE(rig.snap()->controller.park_requested);
}

TEST_P(DriverPark, AChassisFoundInParkIsLeftByReleasingIt) {
  Rig rig("agx_v2", "", std::nullopt, GetParam());
  ASSERT_TRUE(rig.ready());
  // Parked by someone else (a previous session): nothing this driver can command in.
  rig.sim().with_chassis([](sim::VirtualChassis& c) {
    auto frame = encode(MotionModeCommand{protocol::MotionMode::kPark}, c.profile());
    ASSERT_TRUE(frame.ok());
    c.on_frame(*frame, c.now());
  });
  ASSERT_TRUE(rig.run_until([&] { return rig.snap()->controller.parked(); }, 2s));
  rig.drive({0.3, 0, 0}, 500ms);
  EXPECT_EQ(rig.snap()->controller.refusal, MotionRefusal::kModeUnknown);
  EXPECT_EQ(rig.chassis().motion_mode, protocol::MotionMode::kPark);
  // Releasing it switches the chassis out, and the twist drives.
  const RequestOutcome off = rig.outcome(rig.driver().set_park(false));
  ASSERT_EQ(off.state, RequestOutcome::State::kAnswered) << off.message;
  rig.drive({0.3, 0, 0}, 2s);
  EXPECT_EQ(rig.snap()->controller.refusal, MotionRefusal::kNone);
  EXPECT_GT(rig.chassis().speed, 0.2);
}

TEST(DriverPark, RefusedByNameWhereTheModeNumberingHasNoPark) {
  for (const std::string variant : {"manual", "mini_v1"}) {
    Rig rig(variant);
    ASSERT_TRUE(rig.ready()) << variant;
    const RequestOutcome r = rig.outcome(rig.driver().set_park(true));
    EXPECT_EQ(r.state, RequestOutcome::State::kFailed) << variant;
    EXPECT_NE(r.message.find("park: unsupported by protocol"), std::string::npos) << r.message;
    EXPECT_FALSE(rig.snap()->controller.park_requested);
    // Releasing a park the chassis does not have is refused all the same, never a success.
    const RequestOutcome off = rig.outcome(rig.driver().set_park(false));
    EXPECT_EQ(off.state, RequestOutcome::State::kFailed) << variant;
    EXPECT_NE(off.message.find("park: unsupported by protocol"), std::string::npos) << off.message;
    rig.drive({0.3, 0, 0}, 1s);
    EXPECT_EQ(rig.snap()->controller.refusal, MotionRefusal::kNone) << variant;
  }
}

TEST(DriverLights, AnsweredWithTheStateTheChassisReports) {
  Rig rig("agx_v2");
  ASSERT_TRUE(rig.ready());
  ASSERT_TRUE(rig.snap()->lights.has_value());
  EXPECT_EQ(rig.snap()->lights->front, protocol::LightMode::kOn) << "lights on at power-on";
  LightsRequest req;
  req.front = protocol::LightMode::kBreathing;
  req.rear = protocol::LightMode::kCustom;
  req.rear_brightness = 40;
  auto id = rig.driver().set_lights(req);
  ASSERT_TRUE(id.ok());
  const RequestOutcome r = rig.outcome(*id);
  ASSERT_EQ(r.state, RequestOutcome::State::kAnswered) << r.message;
  EXPECT_EQ(r.message, "the chassis reports front breathing, rear custom 40");
  const auto& l = *rig.snap()->lights;
  EXPECT_TRUE(l.can_control);
  EXPECT_EQ(l.front, protocol::LightMode::kBreathing);
  EXPECT_EQ(l.rear, protocol::LightMode::kCustom);
  EXPECT_EQ(l.rear_brightness, 40);
  EXPECT_EQ(rig.chassis().lights.rear_custom, 40);
  // A brightness above 100 is refused before anything is posted.
  req.rear_brightness = 101;
  EXPECT_FALSE(rig.driver().set_lights(req).ok());
}

TEST(DriverLights, UnderTheRemoteTheRequestFailsSayingWhatTheChassisReports) {
  Rig rig("agx_v2");
  ASSERT_TRUE(rig.ready());
  rig.sim().with_chassis([](sim::VirtualChassis& c) { c.remote_takeover(); });
  LightsRequest req;
  req.front = req.rear = protocol::LightMode::kOff;
  const RequestOutcome r = rig.outcome(*rig.driver().set_lights(req));
  EXPECT_EQ(r.state, RequestOutcome::State::kFailed);
  EXPECT_NE(r.message.find("front on, rear on"), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("remote control"), std::string::npos) << r.message;
}

TEST(DriverLights, RefusedOnAChassisWithoutTheVendorFrames) {
  Rig rig("manual");
  ASSERT_TRUE(rig.ready());
  EXPECT_EQ(rig.snap()->vendor_frames, VendorFrames::kAbsent);
  const RequestOutcome r = rig.outcome(*rig.driver().set_lights(LightsRequest{}));
  EXPECT_EQ(r.state, RequestOutcome::State::kFailed);
  EXPECT_NE(r.message.find("lights: unsupported by protocol manual"), std::string::npos)
      << r.message;
  EXPECT_FALSE(rig.sent(protocol::kLightCommandId));
  EXPECT_FALSE(rig.snap()->lights.has_value());
  EXPECT_FALSE(rig.snap()->remote.has_value());
}

TEST(DriverFirmware, AskedOnceTheChassisIsHeardAndShown) {
  Rig rig("agx_v2", "RANGER fw 5.7.3 sim");
  ASSERT_TRUE(rig.run_until(
      [&] { return rig.snap()->firmware.state == FirmwareVersion::State::kAnswered; }, 3s));
  EXPECT_EQ(rig.snap()->firmware.text, "RANGER fw 5.7.3 sim");
  EXPECT_EQ(rig.snap()->controller.counters.version_requests, 1u);
  // Asked again after the chassis changed its answer (the control language's `version`).
  rig.sim().with_chassis(
      [](sim::VirtualChassis& c) { return *sim::apply_chassis_command("version 6.0.1", c); });
  const RequestOutcome r = rig.outcome(rig.driver().request_firmware_version());
  ASSERT_EQ(r.state, RequestOutcome::State::kAnswered) << r.message;
  EXPECT_EQ(r.message, "6.0.1");
  EXPECT_EQ(rig.snap()->firmware.text, "6.0.1");
}

TEST(DriverFirmware, NeverAskedOfAManualChassis) {
  Rig rig("manual");
  ASSERT_TRUE(rig.ready());
  rig.drive(BodyTwist{}, 1s);
  EXPECT_EQ(rig.snap()->firmware.state, FirmwareVersion::State::kUnsupported);
  EXPECT_FALSE(rig.sent(protocol::kVersionId));
  const RequestOutcome r = rig.outcome(rig.driver().request_firmware_version());
  EXPECT_EQ(r.state, RequestOutcome::State::kFailed);
  EXPECT_NE(r.message.find("unsupported by protocol manual"), std::string::npos) << r.message;
}

TEST(DriverRemote, TheRemoteStateIsInTheSnapshot) {
  Rig rig("agx_v2");
  ASSERT_TRUE(rig.ready());
  ASSERT_TRUE(rig.snap()->remote.has_value());
  EXPECT_EQ(rig.snap()->remote->swb, protocol::RemoteSwitch::kUp);
  EXPECT_EQ(rig.snap()->vendor_frames, VendorFrames::kPresent);
}

TEST(DriverRemote, SticksAreNormalisedAndSaturated) {
  RemoteControlState rc;
  rc.stick_left_v = 50;
  rc.stick_right_h = -100;
  rc.var_a = 127;
  rc.swd = protocol::RemoteSwitch::kDown;
  const RemoteState r = remote_state_from(rc, Timestamp(1s));
  EXPECT_DOUBLE_EQ(r.left_vertical, 0.5);
  EXPECT_DOUBLE_EQ(r.right_horizontal, -1.0);
  EXPECT_DOUBLE_EQ(r.knob, 1.0);
  EXPECT_EQ(r.swd, protocol::RemoteSwitch::kDown);
}

// ---- the RANGER MINI 3.0 (sim:mini_v3, model ranger_mini_v3, protocol mini_v3) ------------------

TEST(DriverMiniV3, TheDriveModeIsSetAndReported) {
  Rig rig("mini_v3");
  ASSERT_TRUE(rig.ready());
  ASSERT_TRUE(rig.run_until([&] { return rig.snap()->drive_mode.has_value(); }, 1s));
  EXPECT_EQ(*rig.snap()->drive_mode, protocol::DriveMode::kCurrent);
  const RequestOutcome voltage =
      rig.outcome(rig.driver().set_drive_mode(protocol::DriveMode::kVoltage));
  ASSERT_EQ(voltage.state, RequestOutcome::State::kAnswered) << voltage.message;
  EXPECT_EQ(voltage.message, "the chassis reports drive mode voltage");
  EXPECT_EQ(voltage.what, "drive_mode voltage");
  EXPECT_EQ(*rig.snap()->drive_mode, protocol::DriveMode::kVoltage);
  EXPECT_EQ(rig.chassis().drive_mode, protocol::DriveMode::kVoltage);
  const RequestOutcome current =
      rig.outcome(rig.driver().set_drive_mode(protocol::DriveMode::kCurrent));
  EXPECT_EQ(current.state, RequestOutcome::State::kAnswered) << current.message;
  EXPECT_EQ(*rig.snap()->drive_mode, protocol::DriveMode::kCurrent);
}

TEST(DriverMiniV3, NoDriveModeOnTheVendorsReading) {
  // The vendor's revision has no 0x423: refused by name, nothing sent; 0x291's third byte is
  // not read, so no drive mode is reported either.
  Rig rig("agx_v2");
  ASSERT_TRUE(rig.ready());
  const RequestOutcome r = rig.outcome(rig.driver().set_drive_mode(protocol::DriveMode::kVoltage));
  EXPECT_EQ(r.state, RequestOutcome::State::kFailed);
  EXPECT_EQ(r.message,
            "drive modes: unsupported by protocol agx_v2 (its frame layout agx_v2 has no 0x423 "
            "drive mode command)");
  EXPECT_FALSE(rig.snap()->drive_mode.has_value());
  // The same on a MINI 3.0 read the vendor's way.
  DriverConfig agx = test::driver_config_for("mini_v3");
  agx.controller.profile = *protocol_preset("agx_v2");
  Rig agx_on_mini("mini_v3", "", agx);
  ASSERT_TRUE(agx_on_mini.ready());
  agx_on_mini.drive(BodyTwist{}, 200ms);
  EXPECT_FALSE(agx_on_mini.snap()->drive_mode.has_value());
  EXPECT_EQ(
      agx_on_mini.outcome(agx_on_mini.driver().set_drive_mode(protocol::DriveMode::kVoltage)).state,
      RequestOutcome::State::kFailed);
}

TEST(DriverMiniV3, RearOdometryAndTheBmsAlarmsReachTheSnapshot) {
  Rig rig("mini_v3");
  ASSERT_TRUE(rig.ready());
  rig.drive({0.5, 0, 0}, 2s);
  rig.drive(BodyTwist{}, 1s);
  const auto s = rig.snap();
  ASSERT_TRUE(s->feedback.rear_odometer && s->feedback.odometer);
  const OdometerFeedback& rear = s->feedback.rear_odometer->value;
  EXPECT_TRUE(rear.rear);
  ASSERT_TRUE(rear.left_distance && rear.right_distance);
  const double travelled = rig.chassis().distance_travelled;
  EXPECT_GT(travelled, 0.5);
  EXPECT_NEAR(*rear.left_distance, travelled, 0.002);
  EXPECT_NEAR(*s->feedback.odometer->value.right_distance, travelled, 0.002);
  // The pack's alarm frame (0x362, 4 bytes): under-voltage below 10 % SOC.
  rig.sim().with_chassis([](sim::VirtualChassis& c) {
    c.set_battery_soc(8.0);
    return 0;
  });
  rig.run_until(
      [&] {
        const auto& a = rig.snap()->feedback.bms_alarm[0];
        return a && (a->value.alarm1 & protocol::bms_status::kUnderVoltage) != 0;
      },
      2s);
  const auto& alarm = rig.snap()->feedback.bms_alarm[0];
  ASSERT_TRUE(alarm);
  EXPECT_EQ(protocol::bms_status_names(alarm->value.alarm1, alarm->value.alarm2),
            std::vector<std::string>{"under_voltage"});
  // The fault word by meaning: under-voltage is the MINI 3.0's bit 0.
  EXPECT_TRUE(rig.run_until(
      [&] {
        const auto& f = rig.snap()->controller.faults;
        return std::find(f.begin(), f.end(), "battery_under_voltage") != f.end();
      },
      1s));
}

class DriverMiniV3Switching : public ::testing::TestWithParam<test::SwitchReportUnderTest> {};

TEST_P(DriverMiniV3Switching, LightsOnOrOffParkAndTheRefusalsThatNameWhatItLacks) {
  Rig rig("mini_v3", "", std::nullopt, GetParam());
  ASSERT_TRUE(rig.ready());
  LightsRequest off;
  off.front = protocol::LightMode::kOff;
  off.rear = protocol::LightMode::kOff;
  const RequestOutcome lights = rig.outcome(*rig.driver().set_lights(off));
  ASSERT_EQ(lights.state, RequestOutcome::State::kAnswered) << lights.message;
  EXPECT_EQ(rig.snap()->lights->front, protocol::LightMode::kOff);
  LightsRequest rear = off;
  rear.rear = protocol::LightMode::kOn;
  const RequestOutcome no_rear = rig.outcome(*rig.driver().set_lights(rear));
  EXPECT_EQ(no_rear.state, RequestOutcome::State::kFailed);
  EXPECT_EQ(no_rear.message,
            "a rear light: unsupported by protocol mini_v3 (light_modes on_off: the lights on or "
            "off only)");
  LightsRequest breathing = off;
  breathing.front = protocol::LightMode::kBreathing;
  const RequestOutcome no_breathing = rig.outcome(*rig.driver().set_lights(breathing));
  EXPECT_EQ(no_breathing.state, RequestOutcome::State::kFailed);
  EXPECT_NE(no_breathing.message.find("breathing lights: unsupported by protocol mini_v3"),
            std::string::npos)
      << no_breathing.message;
  // Park is the MINI 3.0's mode 3.
  const RequestOutcome park = rig.outcome(rig.driver().set_park(true));
  ASSERT_EQ(park.state, RequestOutcome::State::kAnswered) << park.message;
  EXPECT_EQ(rig.chassis().motion_mode, protocol::MotionMode::kPark);
  EXPECT_EQ(rig.snap()->feedback.motion_mode->value.mode_raw, 3);
  EXPECT_EQ(rig.outcome(rig.driver().set_park(false)).state, RequestOutcome::State::kAnswered);
}

std::string report_name(const ::testing::TestParamInfo<test::SwitchReportUnderTest>& info) {
  return test::to_string(info.param);
}
INSTANTIATE_TEST_SUITE_P(Reports, DriverPark, ::testing::ValuesIn(test::kBothSwitchReports),
                         report_name);
INSTANTIATE_TEST_SUITE_P(Reports, DriverMiniV3Switching,
                         ::testing::ValuesIn(test::kBothSwitchReports), report_name);

}  // namespace
}  // namespace ranger
