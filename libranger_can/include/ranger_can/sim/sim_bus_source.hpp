// The virtual chassis as a bus source: `sim` (or `sim:VARIANT`) wherever a bus is named — the ROS
// node's port_name, every `ranger_can` command, the example program. The chassis runs on an
// in-process LoopbackNetwork, either on a thread of its own against a real clock
// (VirtualChassisRunner), or in lock-step with the caller's simulated clock (step()).
#pragma once

#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

#include "ranger_can/clock.hpp"
#include "ranger_can/control/model.hpp"
#include "ranger_can/result.hpp"
#include "ranger_can/sim/virtual_chassis.hpp"
#include "ranger_can/sim/virtual_chassis_runner.hpp"
#include "ranger_can/transport/bus_source.hpp"
#include "ranger_can/transport/loopback_bus.hpp"

namespace ranger::sim {

// A virtual chassis variant: a chassis that differs from the manual in one documented way (or, for
// `agx_v2` and `mini_v1`, the way a whole revision or model does), for testing a driver against
// every reading of the protocol. Each variant is the config's profile changed by settings, plus
// what the chassis sends beyond the codec; the driver drives it right with `driver` (the
// options of `ranger_can`; the same settings as parameters for the node).
struct VariantInfo {
  std::string name;         // "spin_cw"
  std::string description;  // one line
  // What makes a driver match it, as `ranger_can` options ("--model M", "--protocol R",
  // "--set NAME=VALUE", space-separated; empty for the defaults).
  std::string driver;
};
// Every variant, "manual" (the plain `sim`) first.
const std::vector<VariantInfo>& variants();
// The names `sim:VARIANT` accepts.
const std::vector<std::string>& variant_names();
// "  manual               the user manual's chassis ..." lines, one per variant (for --help).
std::string variants_help();
// `config` changed the way VARIANT's chassis differs: applied last, over whatever model and
// profile `config` already has ("manual" changes nothing). kInvalidArgument naming the valid
// variants for an unknown one.
Result<VirtualChassisConfig> apply_variant(std::string_view variant, VirtualChassisConfig config);
// `config` as the chassis of `model`: its geometry, limits (the chassis's own ranges) and profile.
VirtualChassisConfig chassis_for_model(const ModelPreset& model, VirtualChassisConfig config = {});

struct SimSourceOptions {
  VirtualChassisConfig chassis;       // before the variant is applied
  std::uint32_t boot_error_bits = 0;  // 0x211 error bits the chassis boots with
  bool lock_step = false;  // true: no thread; the owner calls step() with its simulated clock
};

class SimBusSource final : public BusSource {
 public:
  // `spec` is "sim" or "sim:VARIANT" (checked by open_bus_source). Boots the chassis at
  // clock.now(); `clock` must outlive the source.
  SimBusSource(std::string spec, VirtualChassisConfig config, const SimSourceOptions& options,
               const Clock& clock);
  ~SimBusSource() override;

  // A new endpoint on the chassis's network. With the chassis on a thread of its own, every
  // receive on it first catches the chassis up to the clock (VirtualChassisRunner::catch_up), as
  // a reader of a real bus finds what a chassis sent while the reader's host was busy.
  Result<std::unique_ptr<Bus>> open() override;
  std::string name() const override { return spec_; }

  // Runs `f(VirtualChassis&)` with the chassis held (fault injection, ground truth).
  template <typename F>
  auto with_chassis(F&& f) {
    if (runner_) return runner_->with_chassis(std::forward<F>(f));
    std::lock_guard<std::mutex> lock(mutex_);
    return f(*chassis_);
  }
  ChassisSnapshot snapshot() {
    return with_chassis([](VirtualChassis& c) { return c.snapshot(); });
  }
  // Why the chassis thread ended early (empty otherwise).
  std::string failure() const { return runner_ ? runner_->failure() : std::string(); }

  // Lock-step only: hands the chassis every frame waiting for it and steps it to `now`.
  void step(Timestamp now);
  // Lock-step only: when step() next has something to do.
  Timestamp next_deadline();

  LoopbackNetwork& network() { return *network_; }

 private:
  std::string spec_;
  std::unique_ptr<LoopbackNetwork> network_;
  std::unique_ptr<Bus> chassis_bus_;
  std::shared_ptr<VirtualChassisRunner> runner_;  // threaded (the endpoints hold it weakly)
  std::mutex mutex_;                              // lock-step
  std::unique_ptr<VirtualChassis> chassis_;       // lock-step
};

// A bus source for any spec: sim and sim:VARIANT here (the chassis from `options`), everything
// else from ranger::open_bus_source. An unknown variant is refused with the valid names.
Result<std::shared_ptr<BusSource>> open_bus_source(std::string_view spec, const Clock& clock,
                                                   const SimSourceOptions& options = {});

}  // namespace ranger::sim
