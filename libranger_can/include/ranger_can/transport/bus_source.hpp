// Where a driver's bus comes from: one spec string names it, the way users type it.
//
//   can0, vcan0, ...    a SocketCAN interface (socketcan_bus.hpp), kernel ID filters set
//   replay:FILE         a candump log (either candump format) played at its own pace, read-only:
//                       what the driver sends is discarded, so a field log runs through the whole
//                       driver (and the ROS node) exactly as the live bus did
//   sim, sim:VARIANT    the in-process virtual chassis: provided by the simulator library
//                       (sim/sim_bus_source.hpp, sim::open_bus_source), so that a production
//                       binary can leave the simulator out
//
// A BusSource can be asked again after a failed open (an adapter plugged in later); the bus it
// returns then reopens itself after link loss (bus.hpp's contract).
#pragma once

#include <memory>
#include <string>
#include <string_view>

#include "ranger_can/clock.hpp"
#include "ranger_can/result.hpp"
#include "ranger_can/transport/bus.hpp"

namespace ranger {

class BusSource {
 public:
  virtual ~BusSource() = default;
  // A bus, or an error naming the interface, what was tried and what to do about it.
  virtual Result<std::unique_ptr<Bus>> open() = 0;
  virtual std::string name() const = 0;  // the spec: "can0", "replay:drive.log", "sim"
  // True when nothing sent reaches a chassis (a replayed log): the driver sends nothing.
  virtual bool read_only() const { return false; }
};

// The kind a spec names, without opening anything.
enum class BusKind { kSocketCan, kReplay, kSim };
// kInvalidArgument for an empty spec, "replay:" without a file, or an interface name longer than
// the kernel allows; the message lists the forms.
Result<BusKind> bus_kind(std::string_view spec);

// A SocketCAN interface or a replayed log. `clock` (must outlive the source and its buses) paces
// the replay and stamps its frames (SystemClock: stamps comparable with live SocketCAN ones).
// `sim` specs are refused here with a message pointing at sim::open_bus_source.
Result<std::unique_ptr<BusSource>> open_bus_source(std::string_view spec, const Clock& clock);

// The in-process bus a replayed log is played on, for tests and tools that want it directly:
// every frame of `path` (in file order; lines without a timestamp follow the previous one by
// 1 ms) becomes receivable once clock.now() - start >= its offset from the first frame, stamped
// start + offset. send() succeeds and discards the frame (counted as tx). Errors: the file cannot
// be read, or it holds no frame.
Result<std::unique_ptr<Bus>> open_replay_bus(const std::string& path, const Clock& clock);

}  // namespace ranger
