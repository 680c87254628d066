#include "ranger_can/sim/sim_bus_source.hpp"

#include <utility>

namespace ranger::sim {
namespace {

constexpr std::string_view kSim = "sim";

std::string join(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names)
    out += (out.empty() ? "" : ", ") + n;
  return out;
}

}  // namespace

const std::vector<std::string>& variant_names() {
  static const std::vector<std::string> names = {"manual"};
  return names;
}

Result<VirtualChassisConfig> apply_variant(std::string_view variant, VirtualChassisConfig config) {
  if (variant == "manual") return config;
  return Error{Errc::kInvalidArgument, "unknown virtual chassis variant '" + std::string(variant) +
                                           "' (valid: " + join(variant_names()) + ")"};
}

SimBusSource::SimBusSource(std::string spec, VirtualChassisConfig config,
                           const SimSourceOptions& options, const Clock& clock)
    : spec_(std::move(spec)) {
  LoopbackOptions net;
  net.interface = spec_;
  net.clock = &clock;
  network_ = std::make_unique<LoopbackNetwork>(net);
  chassis_bus_ = network_->connect();
  if (options.lock_step) {
    chassis_ = std::make_unique<VirtualChassis>(*chassis_bus_, config, clock.now());
  } else {
    runner_ = std::make_unique<VirtualChassisRunner>(*chassis_bus_, config, clock);
  }
  if (options.boot_error_bits != 0) {
    with_chassis([&](VirtualChassis& c) {
      c.set_error_bits(options.boot_error_bits);
      return 0;
    });
  }
}

SimBusSource::~SimBusSource() {
  if (runner_) runner_->stop();
}

Result<std::unique_ptr<Bus>> SimBusSource::open() {
  return std::unique_ptr<Bus>(network_->connect());
}

void SimBusSource::step(Timestamp now) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (chassis_) chassis_->poll(now);
}

Timestamp SimBusSource::next_deadline() {
  std::lock_guard<std::mutex> lock(mutex_);
  return chassis_ ? chassis_->next_deadline() : Timestamp::max();
}

Result<std::shared_ptr<BusSource>> open_bus_source(std::string_view spec, const Clock& clock,
                                                   const SimSourceOptions& options) {
  auto kind = bus_kind(spec);
  if (!kind) return kind.error();
  if (*kind != BusKind::kSim) {
    auto source = ranger::open_bus_source(spec, clock);
    if (!source) return source.error();
    return std::shared_ptr<BusSource>(std::move(*source));
  }
  const std::string_view variant =
      spec.size() > kSim.size() ? spec.substr(kSim.size() + 1) : std::string_view("manual");
  auto config = apply_variant(variant, options.chassis);
  if (!config) return config.error();
  return std::shared_ptr<BusSource>(
      std::make_shared<SimBusSource>(std::string(spec), *config, options, clock));
}

}  // namespace ranger::sim
