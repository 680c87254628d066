#include "ranger_can/sim/chassis_lights.hpp"

namespace ranger::sim {

namespace {

bool same(const LightState& a, const LightState& b) {
  return a.enable == b.enable && a.front_mode == b.front_mode && a.front_custom == b.front_custom &&
         a.rear_mode == b.rear_mode && a.rear_custom == b.rear_custom;
}

std::string light_text(protocol::LightMode mode, std::uint8_t custom) {
  std::string out(protocol::to_string(mode));
  if (mode == protocol::LightMode::kCustom) out += " " + std::to_string(custom);
  return out;
}

}  // namespace

std::string describe_lights(const LightState& state) {
  return "front " + light_text(state.front_mode, state.front_custom) + ", rear " +
         light_text(state.rear_mode, state.rear_custom) + (state.enable ? " (CAN)" : "");
}

void ChassisLights::command(const LightCommand& command) {
  const LightState before = report();
  can_ = command;
  changed_ = changed_ || !same(before, report());
}

void ChassisLights::set_remote(bool in_control, protocol::RemoteSwitch swa) {
  const LightState before = report();
  remote_in_control_ = in_control;
  swa_ = swa;
  changed_ = changed_ || !same(before, report());
}

LightState ChassisLights::report() const {
  LightState s;
  if (remote_in_control_) {
    const auto mode = swa_ == protocol::RemoteSwitch::kDown ? protocol::LightMode::kOff
                                                            : protocol::LightMode::kOn;
    s.front_mode = s.rear_mode = mode;
    return s;
  }
  if (!can_.enable) {
    s.front_mode = s.rear_mode = protocol::LightMode::kOn;
    return s;
  }
  s.enable = true;
  s.front_mode = can_.front_mode;
  s.front_custom = can_.front_custom;
  s.rear_mode = can_.rear_mode;
  s.rear_custom = can_.rear_custom;
  return s;
}

bool ChassisLights::take_changed() {
  const bool c = changed_;
  changed_ = false;
  return c;
}

}  // namespace ranger::sim
