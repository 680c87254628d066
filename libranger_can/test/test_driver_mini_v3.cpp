// The RANGER MINI 3.0 (model ranger_mini_v3, protocol mini_v3) through the driver runtime in
// lock-step with sim:mini_v3: the drive mode set (0x423) and reported (0x291 byte 2), the rear
// odometer and the BMS alarms in the snapshot, lights on/off and park, and the refusals that name
// what a reading lacks (drive modes on agx_v2, a rear light and breathing on the MINI 3.0).
#include <gtest/gtest.h>

#include <functional>
#include <memory>
#include <string>

#include "ranger_can/control/driver.hpp"
#include "ranger_can/control/model.hpp"
#include "ranger_can/sim/sim_bus_source.hpp"

namespace ranger {
namespace {

using namespace std::chrono_literals;
using protocol::DriveMode;
using State = RequestOutcome::State;

DriverConfig mini_config(const char* protocol = nullptr) {
  const ModelPreset model = *model_preset("ranger_mini_v3");
  DriverConfig c;
  c.controller.geometry = model.geometry;
  c.controller.limits = model.limits;
  c.controller.profile = protocol ? *protocol_preset(protocol) : model.profile;
  return c;
}

class MiniRig {
 public:
  explicit MiniRig(DriverConfig config, const std::string& spec = "sim:mini_v3") {
    sim::SimSourceOptions options;
    options.lock_step = true;
    auto source = sim::open_bus_source(spec, clock_, options);
    EXPECT_TRUE(source.ok());
    sim_ = std::static_pointer_cast<sim::SimBusSource>(*source);
    driver_ = std::make_unique<Driver>(std::move(config), *source, clock_);
  }
  ~MiniRig() { driver_.reset(); }

  void step() {
    clock_.advance(1ms);
    sim_->step(clock_.now());
    driver_->step(clock_.now());
  }
  bool run_until(const std::function<bool()>& done, std::chrono::nanoseconds timeout) {
    const Timestamp end = clock_.now() + timeout;
    while (!done()) {
      if (clock_.now() >= end) return false;
      step();
    }
    return true;
  }
  bool ready() {
    return run_until(
        [&] {
          const auto s = driver_->snapshot();
          return s->controller.control_mode == protocol::ControlMode::kCan &&
                 s->controller.motion_mode && s->vendor_frames != VendorFrames::kUnknown;
        },
        3s);
  }
  RequestOutcome outcome(std::uint64_t id, std::chrono::nanoseconds timeout = 8s) {
    run_until(
        [&] {
          const RequestOutcome* r = driver_->snapshot()->request(id);
          return r && r->settled();
        },
        timeout);
    const RequestOutcome* r = driver_->snapshot()->request(id);
    return r ? *r : RequestOutcome{};
  }
  void drive(const BodyTwist& twist, std::chrono::nanoseconds d) {
    const Timestamp end = clock_.now() + d;
    while (clock_.now() < end) {
      (void)driver_->command(MotionRequest{twist, std::nullopt});
      for (int i = 0; i < 50; ++i)
        step();
    }
  }
  Driver& driver() { return *driver_; }
  std::shared_ptr<const DriverSnapshot> snap() const { return driver_->snapshot(); }
  sim::SimBusSource& sim() { return *sim_; }

 private:
  ManualClock clock_{Timestamp(1000s)};
  std::shared_ptr<sim::SimBusSource> sim_;
  std::unique_ptr<Driver> driver_;
};

TEST(DriverMiniV3, TheDriveModeIsSetAndReported) {
  MiniRig rig(mini_config());
  ASSERT_TRUE(rig.ready());
  ASSERT_TRUE(rig.run_until([&] { return rig.snap()->drive_mode.has_value(); }, 1s));
  EXPECT_EQ(*rig.snap()->drive_mode, DriveMode::kCurrent);
  const RequestOutcome voltage = rig.outcome(rig.driver().set_drive_mode(DriveMode::kVoltage));
  ASSERT_EQ(voltage.state, State::kAnswered) << voltage.message;
  EXPECT_EQ(voltage.message, "the chassis reports drive mode voltage");
  EXPECT_EQ(voltage.what, "drive_mode voltage");
  EXPECT_EQ(*rig.snap()->drive_mode, DriveMode::kVoltage);
  EXPECT_EQ(rig.sim().snapshot().drive_mode, DriveMode::kVoltage);
  const RequestOutcome current = rig.outcome(rig.driver().set_drive_mode(DriveMode::kCurrent));
  EXPECT_EQ(current.state, State::kAnswered) << current.message;
  EXPECT_EQ(*rig.snap()->drive_mode, DriveMode::kCurrent);
}

TEST(DriverMiniV3, NoDriveModeOnTheVendorsReading) {
  // The vendor's revision has no 0x423: refused by name, nothing sent; 0x291's third byte is
  // not read, so no drive mode is reported either.
  MiniRig rig(mini_config("agx_v2"), "sim:agx_v2");
  ASSERT_TRUE(rig.ready());
  const RequestOutcome r = rig.outcome(rig.driver().set_drive_mode(DriveMode::kVoltage));
  EXPECT_EQ(r.state, State::kFailed);
  EXPECT_EQ(r.message,
            "drive modes: unsupported by protocol agx_v2 (its frame layout agx_v2 has no 0x423 "
            "drive mode command)");
  EXPECT_FALSE(rig.snap()->drive_mode.has_value());
  // The same on a MINI 3.0 read the vendor's way.
  MiniRig agx_on_mini(mini_config("agx_v2"));
  ASSERT_TRUE(agx_on_mini.ready());
  agx_on_mini.drive({}, 200ms);
  EXPECT_FALSE(agx_on_mini.snap()->drive_mode.has_value());
  EXPECT_EQ(agx_on_mini.outcome(agx_on_mini.driver().set_drive_mode(DriveMode::kVoltage)).state,
            State::kFailed);
}

TEST(DriverMiniV3, RearOdometryAndTheBmsAlarmsReachTheSnapshot) {
  MiniRig rig(mini_config());
  ASSERT_TRUE(rig.ready());
  rig.drive({0.5, 0, 0}, 2s);
  rig.drive({}, 1s);
  const auto s = rig.snap();
  ASSERT_TRUE(s->feedback.rear_odometer && s->feedback.odometer);
  const OdometerFeedback& rear = s->feedback.rear_odometer->value;
  EXPECT_TRUE(rear.rear);
  ASSERT_TRUE(rear.left_distance && rear.right_distance);
  const double travelled = rig.sim().snapshot().distance_travelled;
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

TEST(DriverMiniV3, LightsOnOrOffParkAndTheRefusalsThatNameWhatItLacks) {
  MiniRig rig(mini_config());
  ASSERT_TRUE(rig.ready());
  LightsRequest off;
  off.front = protocol::LightMode::kOff;
  off.rear = protocol::LightMode::kOff;
  const RequestOutcome lights = rig.outcome(*rig.driver().set_lights(off));
  ASSERT_EQ(lights.state, State::kAnswered) << lights.message;
  EXPECT_EQ(rig.snap()->lights->front, protocol::LightMode::kOff);
  LightsRequest rear = off;
  rear.rear = protocol::LightMode::kOn;
  const RequestOutcome no_rear = rig.outcome(*rig.driver().set_lights(rear));
  EXPECT_EQ(no_rear.state, State::kFailed);
  EXPECT_EQ(no_rear.message,
            "a rear light: unsupported by protocol mini_v3 (light_modes on_off: the lights on or "
            "off only)");
  LightsRequest breathing = off;
  breathing.front = protocol::LightMode::kBreathing;
  const RequestOutcome no_breathing = rig.outcome(*rig.driver().set_lights(breathing));
  EXPECT_EQ(no_breathing.state, State::kFailed);
  EXPECT_NE(no_breathing.message.find("breathing lights: unsupported by protocol mini_v3"),
            std::string::npos)
      << no_breathing.message;
  // Park is the MINI 3.0's mode 3.
  const RequestOutcome park = rig.outcome(rig.driver().set_park(true));
  ASSERT_EQ(park.state, State::kAnswered) << park.message;
  EXPECT_EQ(rig.sim().snapshot().motion_mode, protocol::MotionMode::kPark);
  EXPECT_EQ(rig.snap()->feedback.motion_mode->value.mode_raw, 3);
  EXPECT_EQ(rig.outcome(rig.driver().set_park(false)).state, State::kAnswered);
}

}  // namespace
}  // namespace ranger
