#include "ranger_can/transport/bus.hpp"

namespace ranger {

std::string_view to_string(BusState s) {
  switch (s) {
    case BusState::kActive:
      return "active";
    case BusState::kErrorWarning:
      return "error-warning";
    case BusState::kErrorPassive:
      return "error-passive";
    case BusState::kBusOff:
      return "bus-off";
    case BusState::kDown:
      return "down";
  }
  return "unknown";
}

}  // namespace ranger
