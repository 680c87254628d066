// How the sub-commands that talk to a chassis (sim, monitor, send) open IFACE.
//
// A name registered here as an in-process LoopbackNetwork is opened on that network; any other
// name is a SocketCAN interface (can0, vcan0). Tests register a network and then run the very
// same sub-commands in-process, with no kernel CAN support needed.
#pragma once

#include <memory>
#include <string>

#include "ranger_can/transport/bus.hpp"
#include "ranger_can/transport/loopback_bus.hpp"
#include "ranger_can/result.hpp"

namespace ranger::cli {

// Makes `network` openable under its interface() name (replacing an earlier one of that name).
void register_loopback_interface(std::shared_ptr<LoopbackNetwork> network);
void unregister_loopback_interface(const std::string& name);

// Opens `iface`: a registered loopback network, else SocketCAN. Errors name the interface.
Result<std::unique_ptr<Bus>> open_interface(const std::string& iface);

}  // namespace ranger::cli
