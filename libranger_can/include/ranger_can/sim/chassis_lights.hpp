// The lights of the virtual chassis: what it reports in 0x231 (agx_v2).
//
// Reading of the manual (section 2.3) and the vendor's revision:
//  * At power-on the front and rear lights are on ("lights on indicate power is on"), not under
//    CAN control (0x231 byte 0 = 0).
//  * In CAN command mode a 0x121 with byte 0 = 1 sets both modes and their custom brightness
//    (0x231 byte 0 = 1); a 0x121 with byte 0 = 0 hands the lights back to the chassis (on).
//  * While the remote control has the chassis, its SWA switch decides: down = both off, up or
//    middle = both on ("SWA is the light control switch, whose moving to the bottom is to turn
//    off the light; SWB needs to be moved to the middle or bottom first"). What CAN set comes back
//    when the remote hands control back.
#pragma once

#include <cstdint>
#include <string>

#include "ranger_can/wire/codec.hpp"
#include "ranger_can/wire/protocol.hpp"

namespace ranger::sim {

class ChassisLights {
 public:
  // A 0x121 the chassis obeys (CAN command mode).
  void command(const LightCommand& command);
  // The remote control: whether it has the chassis (control mode remote) and its SWA position.
  void set_remote(bool in_control, protocol::RemoteSwitch swa);
  // What 0x231 reports now (counter 0: the sender numbers its frames).
  LightState report() const;
  // True when the lights are not what they were before the last command()/set_remote() call
  // (for the chassis's event log); the flag clears when read.
  bool take_changed();

 private:
  LightCommand can_{};  // what the last 0x121 set
  bool remote_in_control_ = false;
  protocol::RemoteSwitch swa_ = protocol::RemoteSwitch::kUp;
  bool changed_ = false;
};

// "front on, rear custom 40 (CAN)" / "front off, rear off".
std::string describe_lights(const LightState& state);

}  // namespace ranger::sim
