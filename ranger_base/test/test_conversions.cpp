// libranger_can types -> ROS messages.
#include <gtest/gtest.h>

#include <tf2/utils.h>

#include <chrono>
#include <cmath>
#include <limits>
#include <set>

#include <ranger_can/control/geometry.hpp>
#include <ranger_can/sim/sim_bus_source.hpp>
#include <ranger_can/sim/virtual_chassis.hpp>
#include <ranger_can/transport/loopback_bus.hpp>
#include <ranger_can/wire/codec.hpp>
#include <ranger_can/wire/protocol.hpp>

#include "ranger_base/conversions.hpp"

namespace ranger_base {
namespace {

namespace protocol = ranger::protocol;
using namespace std::chrono_literals;

template <typename Map>
std::set<std::string> keys(const Map& m) {
  std::set<std::string> out;
  for (const auto& kv : m)
    out.emplace(kv.first);
  return out;
}

std::set<std::string> names(const std::vector<protocol::NamedBit>& bits) {
  std::set<std::string> out;
  for (const auto& b : bits)
    out.emplace(b.name);
  return out;
}

// ---- named bits: the messages name every bit libranger_can defines, and nothing else ----------

TEST(NamedBits, SystemErrorsHaveAFieldForEveryFaultOfTheTable) {
  std::set<std::string> table;
  for (const auto& f : protocol::kFaultTable)
    table.emplace(f.name);
  EXPECT_EQ(keys(system_error_fields()), table);
  // Every name a layout's bits carry is a field of the message.
  for (const auto layout :
       {ranger::ErrorWordLayout::kManual32, ranger::ErrorWordLayout::kAgxV2_16}) {
    for (const auto& n : names(protocol::system_error_bits(layout)))
      EXPECT_EQ(table.count(n), 1u) << n;
  }
}

TEST(NamedBits, DriverStatusHasAFieldForEveryLibraryBit) {
  EXPECT_EQ(keys(driver_status_fields()), names(protocol::driver_status_bits()));
}

TEST(NamedBits, BmsFlagsHaveAFieldForEveryLibraryBit) {
  auto expected = names(protocol::bms_status1_bits());
  for (const auto& n : names(protocol::bms_status2_bits()))
    expected.insert(n);
  EXPECT_EQ(keys(bms_flag_fields()), expected);
}

TEST(NamedBits, EachErrorBitSetsExactlyItsField) {
  const auto& fields = system_error_fields();
  for (const auto& bit : protocol::system_error_bits()) {
    ranger_msgs::SystemErrors msg;
    fill_system_errors(1u << bit.index, ranger::ErrorWordLayout::kManual32, msg);
    for (const auto& [name, field] : fields) {
      EXPECT_EQ(msg.*field != 0, name == bit.name) << "bit " << bit.name << ", field " << name;
    }
  }
}

// Every bit of every layout, raised on the virtual chassis of that layout and read from the 0x211
// frame it sends, sets the message field of its meaning and no other; a reserved bit sets none.
TEST(NamedBits, EveryErrorBitOfEveryLayoutOnTheVirtualChassisSetsTheFieldOfItsMeaning) {
  const auto& fields = system_error_fields();
  for (const char* variant : {"manual", "agx_v2"}) {
    auto config = ranger::sim::apply_variant(variant, {});
    ASSERT_TRUE(config.ok()) << variant;
    const ranger::ErrorWordLayout layout = config->profile.error_word;
    int defined = 0;
    for (int bit = 0; bit < protocol::error_word_bits(layout); ++bit) {
      ranger::LoopbackNetwork net;
      auto chassis_bus = net.connect();
      auto host_bus = net.connect();
      ranger::sim::VirtualChassis chassis(*chassis_bus, *config, ranger::Timestamp{});
      chassis.set_error_bit(bit, true);
      chassis.step(ranger::Timestamp{} + 100ms);
      std::optional<ranger::SystemStatus> status;
      while (auto f = host_bus->receive(std::chrono::nanoseconds(0))) {
        if (f->id != protocol::kSystemStatusId) continue;
        if (auto m = ranger::decode(*f, config->profile)) {
          if (auto* s = std::get_if<ranger::SystemStatus>(&*m)) status = *s;
        }
      }
      ASSERT_TRUE(status.has_value()) << variant << " bit " << bit;
      ASSERT_EQ(status->error_bits & (1u << bit), 1u << bit) << variant << " bit " << bit;
      ranger_msgs::SystemErrors msg;
      fill_system_errors(1u << bit, layout, msg);
      const protocol::FaultInfo* meaning = protocol::fault_at(layout, bit);
      if (meaning != nullptr) ++defined;
      for (const auto& [name, field] : fields) {
        EXPECT_EQ(msg.*field != 0, meaning != nullptr && name == meaning->name)
            << variant << " bit " << bit << ", field " << name;
      }
      // The same word through the whole state message.
      ranger::DriverSnapshot snap;
      snap.profile = config->profile;
      snap.controller.error_bits = status->error_bits;
      const auto state = to_system_state(snap, ros::Time(1.0));
      if (meaning != nullptr) {
        EXPECT_TRUE(state.errors.*(fields.at(meaning->name))) << variant << " bit " << bit;
      }
    }
    EXPECT_EQ(defined, static_cast<int>(protocol::system_error_bits(layout).size())) << variant;
  }
}

// The faults both layouts have set the same field on either.
TEST(NamedBits, AFaultOfBothLayoutsSetsTheSameFieldOnEither) {
  for (const auto& f : protocol::kFaultTable) {
    if (f.manual_bit == protocol::kNoBit || f.agx16_bit == protocol::kNoBit) continue;
    ranger_msgs::SystemErrors manual;
    ranger_msgs::SystemErrors agx;
    fill_system_errors(1u << f.manual_bit, ranger::ErrorWordLayout::kManual32, manual);
    fill_system_errors(1u << f.agx16_bit, ranger::ErrorWordLayout::kAgxV2_16, agx);
    EXPECT_EQ(manual, agx) << f.name;
    EXPECT_TRUE(agx.*(system_error_fields().at(f.name))) << f.name;
  }
}

TEST(NamedBits, BmsStatusBytesMapToTheirOwnFields) {
  for (const auto& bit : protocol::bms_status2_bits()) {
    const auto flags = to_bms_flags(0, static_cast<std::uint8_t>(1u << bit.index));
    EXPECT_TRUE(flags.*(bms_flag_fields().at(bit.name))) << bit.name;
    EXPECT_FALSE(flags.over_voltage);
  }
  const auto all1 = to_bms_flags(0xFF, 0x00);
  EXPECT_TRUE(all1.over_voltage);
  EXPECT_TRUE(all1.discharge_over_current);
  EXPECT_FALSE(all1.charge_over_current);
}

// ---- system state ----------------------------------------------------------------------------

TEST(SystemState, CarriesModesRawWordAndActiveNames) {
  ranger::DriverSnapshot snap;
  ranger::ControllerState& st = snap.controller;
  ranger::ChassisFeedback& fb = snap.feedback;
  st.link = ranger::LinkState::kConnected;
  ranger::SystemStatus status;
  status.control_mode = protocol::ControlMode::kRemote;
  status.control_mode_raw = 3;
  status.vehicle_status = protocol::VehicleStatus::kEmergencyStop;
  status.vehicle_status_raw = 1;
  status.battery_voltage = 51.2;
  fb.system_status = ranger::Stamped<ranger::SystemStatus>{status, 1s, 1s};
  ranger::MotionModeFeedback mode;
  mode.mode = protocol::MotionMode::kSpin;
  mode.mode_raw = 2;
  mode.switching = true;
  fb.motion_mode = ranger::Stamped<ranger::MotionModeFeedback>{mode, 1s, 1s};
  const auto& bits = protocol::system_error_bits();
  st.error_bits = (1u << bits.front().index) | (1u << bits.back().index);
  st.refusal = ranger::MotionRefusal::kRemote;

  const auto msg = to_system_state(snap, ros::Time(10.0));
  EXPECT_TRUE(msg.link_up);
  EXPECT_EQ(msg.control_mode, ranger_msgs::SystemState::CONTROL_MODE_REMOTE);
  EXPECT_EQ(msg.vehicle_status, ranger_msgs::SystemState::VEHICLE_STATUS_EMERGENCY_STOP);
  EXPECT_EQ(msg.motion_mode, ranger_msgs::SystemState::MOTION_MODE_SPIN);
  EXPECT_TRUE(msg.motion_mode_switching);
  EXPECT_NEAR(msg.battery_voltage, 51.2, 1e-4);
  EXPECT_EQ(msg.error_word, st.error_bits);
  ASSERT_EQ(msg.active_errors.size(), 2u);
  EXPECT_EQ(msg.motion_inhibited_reason, "remote");
  EXPECT_NE(msg.motion_inhibited_detail.find("remote control"), std::string::npos);
  EXPECT_EQ(msg.control_mode_name,
            std::string(protocol::to_string(protocol::ControlMode::kRemote)));
}

TEST(SystemState, UnknownBeforeTheFirstFrame) {
  const ranger::DriverSnapshot nothing_yet;
  const auto msg = to_system_state(nothing_yet, ros::Time(1.0));
  EXPECT_FALSE(msg.link_up);
  EXPECT_FALSE(msg.motion_known);
  EXPECT_EQ(msg.control_mode_name, "unknown");
  EXPECT_EQ(msg.motion_mode_name, "unknown");
}

TEST(SystemState, ReArmNamesTheLatchedCausesAndWhatToDo) {
  ranger::DriverSnapshot snap;
  auto& c = snap.controller;
  c.link = ranger::LinkState::kConnected;
  c.refusal = ranger::MotionRefusal::kRearmRequired;
  c.latched_causes = 0u | ranger::StopCause::kEstop;
  const auto msg = to_system_state(snap, ros::Time(1.0));
  EXPECT_TRUE(msg.rearm_required);
  EXPECT_EQ(msg.motion_inhibited_reason, "rearm_required");
  EXPECT_EQ(msg.latched_causes, std::vector<std::string>{"emergency_stop"});
  EXPECT_TRUE(msg.active_causes.empty());
  EXPECT_NE(msg.motion_inhibited_detail.find("after emergency_stop"), std::string::npos)
      << msg.motion_inhibited_detail;
  EXPECT_NE(msg.motion_inhibited_detail.find("resume"), std::string::npos);

  c.latched_causes = c.latched_causes | ranger::StopCause::kRemote;
  c.active_causes = 0u | ranger::StopCause::kEstop;
  EXPECT_EQ(to_system_state(snap, ros::Time(1.0)).latched_causes,
            (std::vector<std::string>{"remote", "emergency_stop"}));
  EXPECT_EQ(to_system_state(snap, ros::Time(1.0)).active_causes,
            std::vector<std::string>{"emergency_stop"});
}

TEST(SystemState, ReclaimBlockedSteerFirstAndBelowMinimumAreSaid) {
  ranger::DriverSnapshot snap;
  ranger::ControllerState& c = snap.controller;
  c.link = ranger::LinkState::kConnected;
  c.refusal = ranger::MotionRefusal::kStandby;
  c.reclaim_blocked = true;
  EXPECT_EQ(describe_refusal(snap),
            "remote control had the chassis: call resume to take CAN control");
  c.reclaim_blocked = false;
  c.refusal = ranger::MotionRefusal::kBelowMinimum;
  EXPECT_NE(describe_refusal(snap).find("below_minimum"), std::string::npos);
  c.refusal = ranger::MotionRefusal::kNone;
  EXPECT_EQ(describe_refusal(snap), "");
  c.steer_first_factor = 0.25;
  EXPECT_NE(describe_refusal(snap).find("steering first"), std::string::npos);
  EXPECT_NE(describe_refusal(snap).find("25 %"), std::string::npos) << describe_refusal(snap);
  EXPECT_FLOAT_EQ(to_system_state(snap, ros::Time(1.0)).steer_first_factor, 0.25f);
}

TEST(SystemState, IdentifyingAndImplausibleAreSaidWithTheirReasons) {
  ranger::DriverSnapshot snap;
  auto& c = snap.controller;
  // Listening: nothing sent, the controller deaf on purpose: the library says "identifying".
  c.refusal = ranger::MotionRefusal::kIdentifying;
  c.quiet = true;
  c.identifying = ranger::IdentificationPhase::kListening;
  snap.protocol = ranger::ProtocolChoice::kAuto;
  auto id = std::make_shared<ranger::IdentificationStatus>();
  id->message = "identifying the chassis: listening (0.4 s of 1.2 s)";
  snap.identification = id;
  auto state = to_system_state(snap, ros::Time(1.0));
  EXPECT_EQ(state.motion_inhibited_reason, "identifying");
  EXPECT_NE(state.motion_inhibited_detail.find("listening (0.4 s of 1.2 s)"), std::string::npos)
      << state.motion_inhibited_detail;
  EXPECT_EQ(state.protocol, "auto");
  EXPECT_EQ(state.identification, "listening");
  EXPECT_EQ(state.protocol_profile, "manual");
  // The probe: the controller's own refusal, the identification's words.
  c.quiet = false;
  c.link = ranger::LinkState::kConnected;
  c.refusal = ranger::MotionRefusal::kIdentifying;
  c.identifying = ranger::IdentificationPhase::kSteerProbe;
  id->message = "identifying the chassis: steering probe";
  state = to_system_state(snap, ros::Time(1.0));
  EXPECT_EQ(state.motion_inhibited_reason, "identifying");
  EXPECT_EQ(state.motion_inhibited_detail, "identifying the chassis: steering probe");
  // A plausibility stop names the setting and the value to try.
  c.identifying.reset();
  c.refusal = ranger::MotionRefusal::kImplausible;
  c.implausible_reason = "spin_sign: try cw (turns the other way)";
  snap.protocol = ranger::ProtocolChoice::kForced;
  snap.identification.reset();
  snap.profile.spin_sign = -1;
  state = to_system_state(snap, ros::Time(1.0));
  EXPECT_EQ(state.motion_inhibited_reason, "implausible_feedback");
  EXPECT_NE(state.motion_inhibited_detail.find("spin_sign: try cw"), std::string::npos)
      << state.motion_inhibited_detail;
  EXPECT_EQ(state.protocol, "forced");
  EXPECT_EQ(state.identification, "");
  EXPECT_EQ(state.protocol_profile, "manual with spin_sign=cw");
}

// Every refusal has its words (the switch in describe_refusal is exhaustive: -Wswitch).
TEST(SystemState, EveryRefusalIsDescribed) {
  ranger::DriverSnapshot snap;
  ranger::ControllerState& c = snap.controller;
  c.link = ranger::LinkState::kConnected;
  for (int r = static_cast<int>(ranger::MotionRefusal::kLinkLost);
       r <= static_cast<int>(ranger::MotionRefusal::kParked); ++r) {
    c.refusal = static_cast<ranger::MotionRefusal>(r);
    EXPECT_FALSE(describe_refusal(snap).empty()) << ranger::to_string(c.refusal);
    EXPECT_EQ(refusal_name(c), std::string(ranger::to_string(c.refusal)));
  }
}

TEST(SystemState, ParkAndTheFirmwareVersion) {
  ranger::DriverSnapshot s;
  s.controller.park_requested = true;
  s.controller.chassis_mode = ranger::protocol::MotionMode::kPark;
  s.controller.refusal = ranger::MotionRefusal::kParked;
  s.firmware = {ranger::FirmwareVersion::State::kAnswered, "fw 5.7.3"};
  const auto m = to_system_state(s, ros::Time(1.0));
  EXPECT_TRUE(m.park_requested);
  EXPECT_TRUE(m.parked);
  EXPECT_EQ(m.motion_inhibited_reason, "parked");
  EXPECT_NE(m.motion_inhibited_detail.find("call park with data = false"), std::string::npos);
  EXPECT_EQ(m.firmware_version, "fw 5.7.3");
  EXPECT_EQ(m.firmware_version_state, "answered");
}

TEST(SystemState, AChassisFoundInParkSaysHowToLeaveIt) {
  ranger::DriverSnapshot snap;
  ranger::ControllerState& c = snap.controller;
  c.link = ranger::LinkState::kConnected;
  c.refusal = ranger::MotionRefusal::kModeUnknown;
  c.chassis_mode = ranger::protocol::MotionMode::kPark;
  EXPECT_NE(describe_refusal(snap).find("call park with data = false"), std::string::npos);
}

// ---- the vendor's additions
// ----------------------------------------------------------------------

TEST(Vendor, RemoteStateNamesTheSwitchesAndKeepsTheSticks) {
  ranger::RemoteState r;
  r.swa = ranger::protocol::RemoteSwitch::kDown;
  r.swb = ranger::protocol::RemoteSwitch::kMiddle;
  r.left_vertical = 0.5;
  r.knob = -1.0;
  const auto m = to_remote_state(r, ros::Time(2.0));
  EXPECT_EQ(m.swa, "down");
  EXPECT_EQ(m.swb, "middle");
  EXPECT_EQ(m.swc, "undefined");
  EXPECT_FLOAT_EQ(m.left_vertical, 0.5f);
  EXPECT_FLOAT_EQ(m.knob, -1.0f);
  EXPECT_EQ(m.header.stamp, ros::Time(2.0));
}

TEST(Vendor, LightsRequestsAreCheckedField) {
  ranger_msgs::SetLights::Request req;
  req.front_mode = ranger_msgs::SetLights::Request::CUSTOM;
  req.front_brightness = 30;
  req.rear_mode = ranger_msgs::SetLights::Request::ON;
  req.rear_brightness = 99;  // not custom: ignored
  const auto ok = to_lights_request(req);
  ASSERT_TRUE(ok.ok());
  EXPECT_EQ(ok->front, ranger::protocol::LightMode::kCustom);
  EXPECT_EQ(ok->front_brightness, 30);
  EXPECT_EQ(ok->rear_brightness, 0);
  req.rear_mode = 4;
  const auto bad = to_lights_request(req);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message.find("rear_mode 4"), std::string::npos);
  req.rear_mode = 0;
  req.front_brightness = 101;
  EXPECT_FALSE(to_lights_request(req).ok());
  ranger_msgs::SetLights::Response res;
  fill_lights_response(ranger::LightsState{true, ranger::protocol::LightMode::kBreathing, 0,
                                           ranger::protocol::LightMode::kCustom, 40},
                       res);
  EXPECT_TRUE(res.can_control);
  EXPECT_EQ(res.front_mode, ranger_msgs::SetLights::Request::BREATHING);
  EXPECT_EQ(res.rear_brightness, 40);
}

// ---- cmd_vel_out -------------------------------------------------------------------------------

TEST(CmdVelOut, OnlyMotionCommandsCarryATwistAndTheShutdownStopIsZero) {
  ranger::SentEvent motion;
  motion.sent.message = ranger::MotionCommand{};
  motion.sent.achieved = {0.3, 0.0, 0.1};
  ASSERT_TRUE(achieved_twist(motion));
  EXPECT_DOUBLE_EQ(achieved_twist(motion)->vx, 0.3);
  ranger::SentEvent stop;
  stop.sent.message = ranger::MotionCommand{};
  stop.sent.shutdown = true;
  ASSERT_TRUE(achieved_twist(stop));
  EXPECT_DOUBLE_EQ(achieved_twist(stop)->vx, 0.0);
  ranger::SentEvent other;
  other.sent.message = ranger::ControlModeCommand{protocol::ControlMode::kCan};
  EXPECT_FALSE(achieved_twist(other));
}

// ---- odometry ---------------------------------------------------------------------------------

TEST(Odometry, PoseTwistFramesAndCovariance) {
  NodeParameters p;
  p.odom_frame = "r1/odom";
  p.base_frame = "r1/base_link";
  p.pose_covariance_diagonal = {0.1, 0.2, 1e6, 1e6, 1e6, 0.3};
  p.twist_covariance_diagonal = {0.01, 0.02, 1e6, 1e6, 1e6, 0.03};
  ranger::OdometryState o;
  o.pose = {1.0, -2.0, 0.75};
  o.twist = {0.5, 0.1, -0.2};
  o.pose_variance = {0.5, 0.6, 0.7};
  o.stamp = std::chrono::seconds(1700000000) + 250ms;  // the frames' time (bus clock)

  const auto msg = to_odometry(o, p);
  // Stamped with the frames that produced it, not with the time of publication.
  EXPECT_EQ(msg.header.stamp.sec, 1700000000u);
  EXPECT_EQ(msg.header.stamp.nsec, 250000000u);
  EXPECT_EQ(msg.header.frame_id, "r1/odom");
  EXPECT_EQ(msg.child_frame_id, "r1/base_link");
  EXPECT_DOUBLE_EQ(msg.pose.pose.position.x, 1.0);
  EXPECT_DOUBLE_EQ(msg.pose.pose.position.y, -2.0);
  EXPECT_NEAR(tf2::getYaw(msg.pose.pose.orientation), 0.75, 1e-12);
  EXPECT_DOUBLE_EQ(msg.twist.twist.linear.x, 0.5);
  EXPECT_DOUBLE_EQ(msg.twist.twist.linear.y, 0.1);
  EXPECT_DOUBLE_EQ(msg.twist.twist.angular.z, -0.2);
  // Row-major 6x6: the diagonal is at 0, 7, 14, 21, 28, 35.
  EXPECT_DOUBLE_EQ(msg.pose.covariance[0], 0.1 + 0.5);
  EXPECT_DOUBLE_EQ(msg.pose.covariance[7], 0.2 + 0.6);
  EXPECT_DOUBLE_EQ(msg.pose.covariance[14], 1e6);
  EXPECT_DOUBLE_EQ(msg.pose.covariance[35], 0.3 + 0.7);
  EXPECT_DOUBLE_EQ(msg.twist.covariance[0], 0.01);
  EXPECT_DOUBLE_EQ(msg.twist.covariance[35], 0.03);
  for (int r = 0; r < 6; ++r) {
    for (int c = 0; c < 6; ++c) {
      if (r != c) EXPECT_EQ(msg.pose.covariance[static_cast<std::size_t>(r * 6 + c)], 0.0);
    }
  }
  const auto tf = to_transform(msg);
  EXPECT_EQ(tf.header.frame_id, "r1/odom");
  EXPECT_EQ(tf.child_frame_id, "r1/base_link");
  EXPECT_DOUBLE_EQ(tf.transform.translation.x, 1.0);
  EXPECT_NEAR(tf2::getYaw(tf.transform.rotation), 0.75, 1e-12);
}

TEST(JointState, NamesComeFromTheSharedGeometryHeader) {
  ranger::WheelJoints j;
  j.steering_position = {0.1, 0.2, 0.3, 0.4};
  j.wheel_position = {1, 2, 3, 4};
  j.wheel_velocity = {5, 6, 7, 8};
  const auto msg = to_joint_state(j, ros::Time(1.0));
  ASSERT_EQ(msg.name.size(), 8u);
  ASSERT_EQ(msg.position.size(), 8u);
  ASSERT_EQ(msg.velocity.size(), 8u);
  for (int i = 0; i < ranger::kWheelCount; ++i) {
    const auto w = static_cast<std::size_t>(i);
    EXPECT_EQ(msg.name[w], ranger::kSteeringJointNames[w]);
    EXPECT_EQ(msg.name[w + 4], ranger::kWheelJointNames[w]);
    EXPECT_DOUBLE_EQ(msg.position[w], j.steering_position[w]);
    EXPECT_DOUBLE_EQ(msg.position[w + 4], j.wheel_position[w]);
    EXPECT_DOUBLE_EQ(msg.velocity[w + 4], j.wheel_velocity[w]);
  }
}

TEST(JointState, StampedWithTheNewestWheelFrame) {
  ranger::ChassisFeedback fb;
  EXPECT_EQ(joints_stamp(fb), ranger::Timestamp{0});
  fb.steering_angles = ranger::Stamped<ranger::SteeringAnglesFeedback>{{}, 5s, 7s};
  fb.wheel_speeds = ranger::Stamped<ranger::WheelSpeedsFeedback>{{}, 5s, 8s};
  EXPECT_EQ(joints_stamp(fb), ranger::Timestamp{8s});  // the frame stamps, not arrival times
}

// ---- battery ----------------------------------------------------------------------------------

ranger::Stamped<ranger::BmsData> bms(int battery, double soc, double voltage, ranger::Timestamp t) {
  ranger::BmsData d;
  d.battery = battery;
  d.soc = soc;
  d.voltage = voltage;
  d.current = -3.0;
  d.temperature = 21.5;
  return {d, t, t};
}

TEST(Battery, PercentageIsAFractionAndSlotsReportPresence) {
  ranger::ChassisFeedback fb;
  fb.bms[0] = bms(0, 87.0, 52.1, 10s);
  fb.bms[2] = bms(2, 80.0, 52.0, 10s);
  fb.bms[3] = bms(3, 80.0, 51.0, 1s);  // stale: removed long ago
  const auto msg = to_battery_state(fb, 10s + 100ms, ros::Time(3.0));
  EXPECT_TRUE(msg.present);
  EXPECT_NEAR(msg.percentage, 0.87, 1e-6);
  EXPECT_NEAR(msg.voltage, 52.1, 1e-4);
  EXPECT_NEAR(msg.current, -3.0, 1e-6);
  EXPECT_EQ(msg.power_supply_status, sensor_msgs::BatteryState::POWER_SUPPLY_STATUS_DISCHARGING);
  // The RANGER's pack is LiFePO4 (user manual), whatever the BMS says.
  EXPECT_EQ(msg.power_supply_technology, sensor_msgs::BatteryState::POWER_SUPPLY_TECHNOLOGY_LIFE);
  EXPECT_DOUBLE_EQ(msg.header.stamp.toSec(), 10.0);  // the BMS frame's own time
  ASSERT_EQ(msg.cell_voltage.size(), 4u);
  EXPECT_TRUE(std::isnan(msg.cell_voltage[0]));  // slot 1 never reported
  EXPECT_NEAR(msg.cell_voltage[1], 52.0, 1e-4);  // slot 2
  EXPECT_TRUE(std::isnan(msg.cell_voltage[2]));  // slot 3 stale
  EXPECT_TRUE(std::isnan(msg.cell_voltage[3]));

  const auto array = to_bms_state(fb, 10s + 100ms, ros::Time(3.0));
  ASSERT_EQ(array.batteries.size(), 5u);
  EXPECT_TRUE(array.batteries[0].present);
  EXPECT_FALSE(array.batteries[1].present);
  EXPECT_TRUE(array.batteries[2].present);
  EXPECT_FALSE(array.batteries[3].present);
  EXPECT_NEAR(array.batteries[2].header.stamp.toSec(), 10.0, 1e-6);
}

TEST(Battery, PercentageStaysInZeroToOne) {
  ranger::ChassisFeedback fb;
  fb.bms[0] = bms(0, 250.0, 52.1, 1s);
  EXPECT_FLOAT_EQ(to_battery_state(fb, 1s, ros::Time(1.0)).percentage, 1.0f);
}

TEST(Battery, WithoutBmsTheStatusVoltageIsUsedAndPercentageUnknown) {
  ranger::ChassisFeedback fb;
  ranger::SystemStatus status;
  status.battery_voltage = 49.5;
  fb.system_status = ranger::Stamped<ranger::SystemStatus>{status, 1s, 1s};
  const auto msg = to_battery_state(fb, 1s, ros::Time(1.0));
  EXPECT_NEAR(msg.voltage, 49.5, 1e-4);
  EXPECT_TRUE(std::isnan(msg.percentage));
}

// ---- ultrasonic -------------------------------------------------------------------------------

TEST(Ultrasonic, RangeFollowsRep117) {
  NodeParameters p;
  p.ultrasonic.max_range = 4.0;
  const auto ok = to_range(3, 1234, p, ros::Time(1.0));
  EXPECT_EQ(ok.header.frame_id, "ultrasonic_3_link");
  EXPECT_EQ(ok.radiation_type, sensor_msgs::Range::ULTRASOUND);
  EXPECT_NEAR(ok.range, 1.234, 1e-6);
  EXPECT_TRUE(std::isnan(to_range(1, -1, p, ros::Time(1.0)).range));  // offline
  EXPECT_TRUE(std::isinf(to_range(1, 5000, p, ros::Time(1.0)).range));
}

TEST(Ultrasonic, FramesArePrefixedLikeEveryOtherFrame) {
  NodeParameters p;
  p.frame_prefix = "robot1/";
  EXPECT_EQ(to_range(1, 500, p, ros::Time(1.0)).header.frame_id, "robot1/ultrasonic_1_link");
}

// Whatever raw value the library does not call "ok" (an error code, and "no reading" for 0 once
// the library names it so) is NaN; the node follows the library's name, not a raw comparison.
TEST(Ultrasonic, EveryValueTheLibraryDoesNotCallOkIsNaN) {
  NodeParameters p;
  for (int raw = -5; raw <= 5; ++raw) {
    const auto r = static_cast<std::int16_t>(raw);
    const bool ok = protocol::ultrasonic_status_name(r) == "ok";
    EXPECT_EQ(std::isnan(to_range(1, r, p, ros::Time(1.0)).range), !ok) << raw;
    EXPECT_EQ(std::isnan(ultrasonic_range_m(r)), !ok) << raw;
  }
}

TEST(Ultrasonic, StateListsSensorsInOrderWithStatusNames) {
  ranger::DriverSnapshot snap;
  ranger::ControllerState& st = snap.controller;
  ranger::UltrasonicFeedback back;
  back.first_sensor = 5;
  back.raw = {100, -1, -2, 300};
  ranger::UltrasonicFeedback front;
  front.first_sensor = 1;
  front.raw = {1000, 2000, 3000, 4000};
  snap.feedback.ultrasonic[1] = ranger::Stamped<ranger::UltrasonicFeedback>{back, 1s, 1s};
  snap.feedback.ultrasonic[0] = ranger::Stamped<ranger::UltrasonicFeedback>{front, 1s, 1s};
  st.ultrasonic_enabled = true;
  const auto msg = to_ultrasonic_state(snap, ros::Time(1.0));
  EXPECT_TRUE(msg.avoidance_known);
  EXPECT_TRUE(msg.avoidance_enabled);
  ASSERT_EQ(msg.sensors.size(), 8u);
  for (std::size_t i = 0; i < 8; ++i)
    EXPECT_EQ(msg.sensors[i].sensor, i + 1);
  EXPECT_EQ(msg.sensors[5].status, "offline");
  EXPECT_TRUE(std::isnan(msg.sensors[5].range));
  EXPECT_EQ(msg.sensors[0].status, "ok");
  EXPECT_NEAR(msg.sensors[0].range, 1.0, 1e-6);
}

// ---- actuators, time, twist -------------------------------------------------------------------

TEST(Actuators, EightMotorsWithTheirJoints) {
  ranger::ChassisFeedback fb;
  ranger::MotorLowSpeedFeedback low;
  low.motor = 6;
  low.driver_status = 0x40;  // bit 6: driver disabled
  fb.motor_low_speed[5] = ranger::Stamped<ranger::MotorLowSpeedFeedback>{low, 2s, 99s};
  const auto msg = to_actuator_state(fb, ros::Time(100.0));
  ASSERT_EQ(msg.actuators.size(), 8u);
  EXPECT_EQ(msg.actuators[0].joint_name, ranger::kWheelJointNames[0]);
  EXPECT_EQ(msg.actuators[5].joint_name, ranger::kSteeringJointNames[1]);
  EXPECT_TRUE(msg.actuators[5].driver_status_bits.driver_disabled);
  EXPECT_FALSE(msg.actuators[5].driver_status_bits.driver_error);
  EXPECT_NEAR(msg.actuators[5].low_speed_stamp.toSec(), 99.0, 1e-6);
  EXPECT_TRUE(msg.actuators[0].high_speed_stamp.isZero());
}

TEST(Time, BusStampsAreRosTime) {
  EXPECT_NEAR(to_ros_time(std::chrono::seconds(1700000000) + 500ms).toSec(), 1700000000.5, 1e-6);
  EXPECT_TRUE(to_ros_time(ranger::Timestamp{0}).isZero());
}

TEST(CmdVel, EverySixFieldsReachTheLibrarysCheck) {
  geometry_msgs::Twist t;
  t.linear.x = 0.3;
  t.linear.z = std::numeric_limits<double>::quiet_NaN();
  const ranger::MotionRequest r = to_motion_request(t);
  EXPECT_DOUBLE_EQ(r.twist.vx, 0.3);
  EXPECT_FALSE(r.mode.has_value());
  const ranger::Status st = ranger::check_finite(r);
  ASSERT_FALSE(st.ok());
  EXPECT_EQ(st.error().message, "linear.z is NaN");
  t.linear.z = 0.0;
  t.angular.x = 1.0;
  t.angular.y = -std::numeric_limits<double>::infinity();
  EXPECT_EQ(ranger::check_finite(to_motion_request(t)).error().message, "angular.y is infinite");
  t.angular.y = 0.5;
  EXPECT_TRUE(ranger::check_finite(to_motion_request(t)).ok());
  EXPECT_DOUBLE_EQ(to_motion_request(t).out_of_plane.wx, 1.0);
}

TEST(SystemState, AnInvalidCommandAndTheOdometrysGapAreSaid) {
  ranger::DriverSnapshot snap;
  auto& c = snap.controller;
  c.link = ranger::LinkState::kConnected;
  c.refusal = ranger::MotionRefusal::kInvalidCommand;
  c.invalid_command = "linear.z is NaN";
  snap.odometry.last_gap = std::chrono::milliseconds(2040);
  snap.odometry.last_gap_end = std::chrono::seconds(1700000000);
  snap.odometry.gaps = 3;
  const auto m = to_system_state(snap, ros::Time(1.0));
  EXPECT_EQ(m.motion_inhibited_reason, "invalid_command");
  EXPECT_NE(m.motion_inhibited_detail.find("linear.z is NaN"), std::string::npos)
      << m.motion_inhibited_detail;
  EXPECT_NEAR(m.odometry_gap, 2.04, 1e-9);
  EXPECT_EQ(m.odometry_gap_end, ros::Time(1700000000.0));
  EXPECT_EQ(m.odometry_gaps, 3u);
}

// Only resume re-arms; the words name the zero twist only where the owner opted in to it.
TEST(SystemState, TheRearmWordsFollowTheOptIn) {
  ranger::DriverSnapshot snap;
  auto& c = snap.controller;
  c.link = ranger::LinkState::kConnected;
  c.refusal = ranger::MotionRefusal::kRearmRequired;
  c.latched_causes = 0u | ranger::StopCause::kEstop;
  EXPECT_EQ(describe_refusal(snap),
            "rearm_required after emergency_stop: call resume to drive again");
  c.zero_twist_rearms = true;
  EXPECT_EQ(describe_refusal(snap),
            "rearm_required after emergency_stop: call resume (or send a zero cmd_vel: "
            "rearm_on_zero_twist) to drive again");
}

TEST(CmdVel, PlanarComponentsOnly) {
  geometry_msgs::Twist t;
  t.linear.x = 1.0;
  t.linear.y = -0.5;
  t.angular.z = 0.25;
  const auto b = to_body_twist(t);
  EXPECT_DOUBLE_EQ(b.vx, 1.0);
  EXPECT_DOUBLE_EQ(b.vy, -0.5);
  EXPECT_DOUBLE_EQ(b.wz, 0.25);
  EXPECT_FALSE(has_non_planar_components(t));
  t.angular.x = 0.1;
  EXPECT_TRUE(has_non_planar_components(t));
}

}  // namespace
}  // namespace ranger_base
