#include "ranger_can/sim/sim_bus_source.hpp"
#include "ranger_can/text.hpp"

#include <algorithm>
#include <utility>

namespace ranger::sim {
namespace {

constexpr std::string_view kSim = "sim";

using text::join;

// An endpoint on the threaded chassis's network that brings the chassis up to the clock before
// each read (see SimBusSource::open); everything else is the endpoint's own.
class CatchUpBus final : public Bus {
 public:
  CatchUpBus(std::unique_ptr<Bus> bus, std::weak_ptr<VirtualChassisRunner> runner)
      : bus_(std::move(bus)), runner_(std::move(runner)) {}

  Status send(const CanFrame& frame) override { return bus_->send(frame); }
  Result<CanFrame> receive(std::chrono::nanoseconds timeout) override {
    catch_up();
    return bus_->receive(timeout);
  }
  std::size_t receive_queued(std::vector<Result<CanFrame>>& out, std::size_t max) override {
    catch_up();
    return bus_->receive_queued(out, max);
  }
  int fd() const override { return bus_->fd(); }
  BusStatus status() const override { return bus_->status(); }
  void set_filter(const std::vector<std::uint32_t>& ids) override { bus_->set_filter(ids); }
  std::string name() const override { return bus_->name(); }

 private:
  void catch_up() {
    if (auto runner = runner_.lock()) runner->catch_up();
  }

  std::unique_ptr<Bus> bus_;
  std::weak_ptr<VirtualChassisRunner> runner_;
};

// How far back a late step of the threaded chassis replays its frames: longer than any pause a
// loaded host gives a thread, shorter than what an endpoint's queue holds (LoopbackOptions).
constexpr std::chrono::nanoseconds kThreadedReplayWindow = std::chrono::seconds(1);

}  // namespace

const std::vector<VariantInfo>& variants() {
  static const std::vector<VariantInfo> kVariants = {
      {"manual", "the user manual's chassis (the plain `sim`)", ""},
      {"agx_v2", "the vendor's revision (agx_v2), also sending 0x231, 0x241 and 0x4A1 answers",
       "--protocol agx_v2"},
      {"padded", "the manual's layout, every frame it sends padded to 8 bytes", "--set tx_dlc=8"},
      {"spin_cw", "spin values (0x111 bytes 4-5, 0x221 in spin mode) clockwise positive",
       "--set spin_sign=cw"},
      {"steer_left_positive", "0x111, 0x221 and 0x271 steering angles positive to the left",
       "--set steering_sign_111=left_positive --set steering_sign_221=left_positive "
       "--set steering_sign_271=left_positive"},
      {"speed221_body", "0x221 reports the body centre's speed in Ackermann mode",
       "--set feedback_speed=body_centre"},
      {"inner_angle", "0x111 steers and 0x221 reports the inner front wheel's angle",
       "--set steering_reference=inner_front"},
      {"mini_v1", "the RANGER MINI V1: geometry, limits and protocol of model ranger_mini_v1",
       "--model ranger_mini_v1"},
      {"mini_v3", "the RANGER MINI 3.0: model ranger_mini_v3, drive modes, the field's switch",
       "--model ranger_mini_v3"},
      {"mini_v3_manual",
       "the RANGER MINI 3.0's BMS as its transcribed manual has it: 0.1 V, 500 ms",
       "--model ranger_mini_v3 --set bms_voltage_scale=0.1"},
      {"field_switch",
       "the RANGER switching modes as a real MINI 3.0: new mode at once, 3.26 rad/s", ""},
      {"mode_left", "a mode switch as the manual reads it: the mode left, switching=1 throughout",
       ""},
      {"undecidable", "neither revision: the manual's IDs and lengths, agx_v2 values, no 0x271",
       "--protocol agx_v2 --set tx_dlc=0 --set mode_numbering=manual"},
  };
  return kVariants;
}

const std::vector<std::string>& variant_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> out;
    for (const VariantInfo& v : variants())
      out.push_back(v.name);
    return out;
  }();
  return names;
}

std::string variants_help() {
  std::string out;
  for (const VariantInfo& v : variants()) {
    std::string name = "  " + v.name;
    name.resize(std::max<std::size_t>(name.size() + 2, 23), ' ');
    out += name + v.description + "\n";
  }
  return out;
}

namespace {

// The models a real chassis has been observed of, and what the field showed (docs/FIELD_FACTS.md):
// its switch, the lag of its steering's profile (t = d / rate + lag, the rate the model's
// steering_rate; 0: a pure rate), its frame rates and its pack's state of health.
struct FieldObservation {
  std::string_view model;
  SwitchModelConfig (*switch_model)();
  double steering_lag;          // s
  FrameRates (*frame_rates)();  // frame_schedule.hpp's column
  double battery_soh;           // %, 0x361 byte 1
};
constexpr FieldObservation kFieldObservations[] = {
    {"ranger_mini_v3", field_switch_model, kFieldSlewLag, field_frame_rates, 100.0},
};

}  // namespace

VirtualChassisConfig chassis_for_model(const ModelPreset& model, VirtualChassisConfig config) {
  config.switch_model = mode_left_switch_model();
  config.limits.steering_rate = model.limits.steering_rate;
  config.limits.steering_acceleration = 0.0;
  config.frame_rates = manual_frame_rates();
  for (const FieldObservation& f : kFieldObservations) {
    if (f.model != model.name) continue;
    config.switch_model = f.switch_model();
    config.limits.steering_acceleration = model.limits.steering_rate / f.steering_lag;
    config.frame_rates = f.frame_rates();
    config.drivetrain.battery_soh = f.battery_soh;
  }
  config.geometry = model.geometry;
  config.limits.max_linear_speed = model.limits.max_linear_speed;
  config.limits.max_speed_at_large_steering = model.limits.max_speed_at_large_steering;
  config.limits.max_spin_speed = model.limits.max_spin_wheel_speed;
  config.limits.max_ackermann_angle = model.limits.max_ackermann_steering;
  config.limits.max_oblique_angle = model.limits.max_oblique_steering;
  config.profile = model.profile;
  return config;
}

namespace {

// The preset of a revision or a model the variant table names (both exist: the tests say so).
ProtocolProfile preset(std::string_view revision) {
  auto p = protocol_preset(revision);
  return p ? *p : manual_profile();
}

}  // namespace

Result<VirtualChassisConfig> apply_variant(std::string_view variant, VirtualChassisConfig config) {
  ProtocolProfile& p = config.profile;
  if (variant == "manual") return config;
  if (variant == "agx_v2") {
    p = preset("agx_v2");
    config.vendor_frames = true;
  } else if (variant == "padded") {
    p.tx_dlc = 8;
  } else if (variant == "spin_cw") {
    p.spin_sign = -1;
  } else if (variant == "steer_left_positive") {
    p.steering_sign_111 = p.steering_sign_221 = p.steering_sign_271 = SteeringSign::kLeftPositive;
  } else if (variant == "speed221_body") {
    p.feedback_speed = FeedbackSpeed::kBodyCentre;
  } else if (variant == "inner_angle") {
    p.steering_reference = SteeringReference::kInnerFront;
  } else if (variant == "mini_v1") {
    auto model = model_preset("ranger_mini_v1");
    if (!model) return model.error();
    config = chassis_for_model(*model, config);
    config.vendor_frames = true;  // the vendor's protocol family
  } else if (variant == "mini_v3") {
    auto model = model_preset("ranger_mini_v3");
    if (!model) return model.error();
    config = chassis_for_model(*model, config);
    config.vendor_frames = true;    // 0x231, 0x241 (its manual), 0x4A1 (the vendor's SDK)
    config.odometer_frames = true;  // 0x311, 0x312 in mm
  } else if (variant == "mini_v3_manual") {
    auto v3 = apply_variant("mini_v3", config);
    if (!v3) return v3.error();
    config = *v3;
    p.bms_voltage_scale = 0.1;
    config.frame_rates = manual_frame_rates();
    return config;
  } else if (variant == "field_switch") {
    config.switch_model = field_switch_model();
  } else if (variant == "mode_left") {
    config.switch_model = mode_left_switch_model();
  } else if (variant == "undecidable") {
    // Built so that no passive evidence settles the revision, and the steering unit cannot be
    // read at rest: the vendor's units, signs, spin field, error word (byte 7 a counter), BMS
    // scale and driver bit, on the manual's identifiers (no 0x231/0x241, no 0x4A1 answer) with
    // the manual's lengths and mode numbers; no 0x271 (no wheel angle whose value geometry
    // fixes), and 0x221 reports angle 0 in spin mode (its spin position would tell the unit).
    p = preset("agx_v2");
    p.tx_dlc = 0;
    p.mode_numbering = ModeNumbering::kManual;
    config.vendor_frames = false;
    config.steering_angles_frame = false;
    config.spin_angle_reported = false;
  } else {
    return Error{Errc::kInvalidArgument, "unknown virtual chassis variant '" +
                                             std::string(variant) +
                                             "' (valid: " + join(variant_names()) + ")"};
  }
  return config;
}

SimBusSource::SimBusSource(std::string spec, VirtualChassisConfig config,
                           const SimSourceOptions& options, const Clock& clock)
    : spec_(std::move(spec)) {
  LoopbackOptions net;
  net.interface = spec_;
  net.clock = &clock;
  net.sender_stamps = !options.lock_step;
  network_ = std::make_unique<LoopbackNetwork>(net);
  chassis_bus_ = network_->connect();
  if (options.lock_step) {
    chassis_ = std::make_unique<VirtualChassis>(*chassis_bus_, config, clock.now());
  } else {
    if (config.replay_window.count() == 0) config.replay_window = kThreadedReplayWindow;
    runner_ = std::make_shared<VirtualChassisRunner>(*chassis_bus_, config, clock);
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
  std::unique_ptr<Bus> bus = network_->connect();
  if (!runner_) return bus;
  return std::unique_ptr<Bus>(std::make_unique<CatchUpBus>(std::move(bus), runner_));
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
