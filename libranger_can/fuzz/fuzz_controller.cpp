// Fuzzes the chassis controller with arbitrary sequences of chassis feedback (valid, corrupt,
// foreign and error frames), caller commands (NaN, inf, 1e9, forced modes, floods), explicit
// requests, failing sends and an advancing clock.
//
// The harness keeps its own record of what the chassis last said (0x211, 0x291, the BMS pack
// SOC, wheel speeds) and of the caller's last command, and checks every frame the controller
// sends against it (each a FUZZ_CHECK):
//  * every frame is one the codec accepts, and no field of state() is NaN/inf;
//  * a 0x111 with non-zero motion goes out only while the last 0x211 (at most link_timeout old)
//    said CAN command mode, no e-stop and no critical error bit; the last 0x291 named the mode
//    the command was solved for and was not switching; the pack SOC (if reported) is not low;
//    the caller's last command is finite and younger than cmd_timeout; and not after shutdown();
//  * a 0x111 stays within the configured kinematic limits;
//  * 0x421 is sent by itself only while the chassis said standby (remote control is never
//    fought) and only ever asks for standby or CAN mode;
//  * 0x141 goes out only at confirmed standstill (fresh 0x281, else fresh 0x221).
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <string>
#include <vector>

#include "fuzz_input.hpp"
#include "ranger_can/control/controller.hpp"
#include "ranger_can/transport/bus.hpp"
#include "ranger_can/wire/codec.hpp"
#include "ranger_can/wire/protocol.hpp"

namespace {

namespace protocol = ranger::protocol;
using ranger::CanFrame;
using ranger::Timestamp;
using ranger::fuzz::consume_double;
using std::chrono::milliseconds;

// A bus that records what is sent and can be told to refuse sends (a full transmit queue).
class RecordingBus final : public ranger::Bus {
 public:
  ranger::Status send(const CanFrame& frame) override {
    if (refuse_) return ranger::Error{ranger::Errc::kWouldBlock, "transmit queue full (fuzz)"};
    sent.push_back(frame);
    return ranger::ok_status();
  }
  ranger::Result<CanFrame> receive(std::chrono::nanoseconds) override {
    return ranger::Error{ranger::Errc::kTimeout, "nothing (fuzz)"};
  }
  int fd() const override { return -1; }
  ranger::BusStatus status() const override { return {}; }
  void set_filter(const std::vector<std::uint32_t>&) override {}
  std::string name() const override { return "fuzz"; }

  void refuse(bool on) { refuse_ = on; }
  std::vector<CanFrame> sent;

 private:
  bool refuse_ = false;
};

// What the chassis last told the controller, as the harness saw it.
struct ChassisSaid {
  std::optional<Timestamp> status_time;  // last decodable 0x211
  std::uint8_t control_mode = 0, vehicle_status = 0;
  std::uint32_t error_bits = 0;
  bool have_mode = false;  // last decodable 0x291
  std::uint8_t motion_mode = 0, switching = 0;
  std::optional<double> pack_soc;
  std::optional<Timestamp> wheels_time, motion_time;
  double max_wheel_speed = 0.0, motion_speed = 0.0;
};

struct CallerSaid {
  bool any = false;
  bool finite = false;
  Timestamp time{0};
};

std::uint8_t pick(FuzzedDataProvider& in, std::initializer_list<std::uint8_t> usual) {
  if (in.ConsumeIntegralInRange<int>(0, 7) == 0) return in.ConsumeIntegral<std::uint8_t>();
  const auto i = in.ConsumeIntegralInRange<std::size_t>(0, usual.size() - 1);
  return *(usual.begin() + i);
}

void put_i16(CanFrame& f, int at, int v) {
  const auto u = static_cast<std::uint16_t>(static_cast<std::int16_t>(v));
  f.data[at] = static_cast<std::uint8_t>(u >> 8);
  f.data[at + 1] = static_cast<std::uint8_t>(u);
}

// A wheel or body speed in mm/s: mostly at or near standstill, sometimes anything.
int speed_mmps(FuzzedDataProvider& in) {
  switch (in.ConsumeIntegralInRange<int>(0, 3)) {
    case 0:
      return 0;
    case 1:
      return in.ConsumeIntegralInRange<int>(-30, 30);
    default:
      return in.ConsumeIntegral<std::int16_t>();
  }
}

// A frame from the chassis (or from something else on the bus). Structured so that the
// interesting states (CAN mode, no faults, mode confirmed) are reached often.
CanFrame make_frame(FuzzedDataProvider& in) {
  CanFrame f;
  switch (in.ConsumeIntegralInRange<int>(0, 9)) {
    case 0:
    case 1:
    case 2: {  // 0x211: control mode, vehicle status, battery, error bits
      f.id = protocol::kSystemStatusId;
      f.dlc = 8;
      f.data[0] = pick(in, {0x00, 0x00, 0x00, 0x01, 0x02});
      f.data[1] = pick(in, {0x01, 0x01, 0x01, 0x00, 0x03});
      f.data[2] = 0x01;
      f.data[3] = 0xE0;
      std::uint32_t bits = 0;
      switch (in.ConsumeIntegralInRange<int>(0, 5)) {
        case 0:
          bits = 1u << in.ConsumeIntegralInRange<int>(0, 31);
          break;
        case 1:
          bits = in.ConsumeIntegral<std::uint32_t>();
          break;
        default:
          break;
      }
      for (int i = 0; i < 4; ++i)
        f.data[4 + i] = static_cast<std::uint8_t>(bits >> (24 - 8 * i));
      break;
    }
    case 3:
    case 4: {  // 0x291: motion mode and switching
      f.id = protocol::kMotionModeFeedbackId;
      f.dlc = 2;
      f.data[0] = pick(in, {0x00, 0x01, 0x02});
      f.data[1] = pick(in, {0x00, 0x00, 0x01});
      break;
    }
    case 5: {  // 0x281 wheel speeds
      f.id = protocol::kWheelSpeedsId;
      f.dlc = 8;
      for (int i = 0; i < 4; ++i)
        put_i16(f, 2 * i, speed_mmps(in));
      break;
    }
    case 6: {  // 0x221 motion feedback
      f.id = protocol::kMotionFeedbackId;
      f.dlc = 8;
      put_i16(f, 0, speed_mmps(in));
      put_i16(f, 6, in.ConsumeIntegral<std::int16_t>());
      break;
    }
    case 7: {  // BMS pack data: SOC around the cut-off
      f.id = protocol::kBmsBaseId;
      f.dlc = 8;
      f.data[0] = pick(in, {90, 50, 10, 9, 0});
      f.data[1] = 100;
      break;
    }
    case 8: {  // any RANGER ID (0x45A, motors, ultrasonic, our own commands echoed), any bytes
      static const std::vector<std::uint32_t> kIds = protocol::all_ids();
      f.id = kIds[in.ConsumeIntegralInRange<std::size_t>(0, kIds.size() - 1)];
      const int dlc = protocol::layout_dlc(f.id);
      f.dlc = static_cast<std::uint8_t>(dlc >= 0 ? dlc : 8);
      for (std::size_t i = 0; i < f.dlc; ++i)
        f.data[i] = in.ConsumeIntegral<std::uint8_t>();
      break;
    }
    default: {  // garbage: foreign IDs, wrong DLCs, error frames
      f.id = in.ConsumeIntegral<std::uint32_t>() & 0x1FFFFFFFu;
      f.dlc = in.ConsumeIntegralInRange<std::uint8_t>(0, 8);
      f.is_error = in.ConsumeBool();
      for (std::size_t i = 0; i < f.dlc; ++i)
        f.data[i] = in.ConsumeIntegral<std::uint8_t>();
      break;
    }
  }
  f.stamp = Timestamp{in.ConsumeIntegral<std::int64_t>()};  // the bus clock is not ours
  return f;
}

// Updates the harness's record with a frame the controller was given at `now`.
void record(const CanFrame& f, Timestamp now, ChassisSaid& said) {
  const auto message = ranger::decode(f);
  if (!message.ok()) return;
  if (const auto* s = std::get_if<ranger::SystemStatus>(&*message)) {
    said.status_time = now;
    said.control_mode = s->control_mode_raw;
    said.vehicle_status = s->vehicle_status_raw;
    said.error_bits = s->error_bits;
  } else if (const auto* m = std::get_if<ranger::MotionModeFeedback>(&*message)) {
    said.have_mode = true;
    said.motion_mode = m->mode_raw;
    said.switching = f.data[1];
  } else if (const auto* b = std::get_if<ranger::BmsData>(&*message)) {
    if (b->battery == 0) said.pack_soc = b->soc;
  } else if (const auto* w = std::get_if<ranger::WheelSpeedsFeedback>(&*message)) {
    said.wheels_time = now;
    said.max_wheel_speed = 0.0;
    for (double v : w->speeds)
      said.max_wheel_speed = std::max(said.max_wheel_speed, std::abs(v));
  } else if (const auto* mf = std::get_if<ranger::MotionFeedback>(&*message)) {
    said.motion_time = now;
    said.motion_speed = std::abs(mf->speed);
  }
}

bool finite(const ranger::BodyTwist& t) {
  return std::isfinite(t.vx) && std::isfinite(t.vy) && std::isfinite(t.wz);
}

// RANGER_FUZZ_TRACE=1 prints every step of a replayed input (for reading a reproducer).
const bool kTrace = std::getenv("RANGER_FUZZ_TRACE") != nullptr;

class Harness {
 public:
  explicit Harness(const ranger::ControllerConfig& config) : config_(config), ctl_(bus_, config) {}

  // Checks every frame sent since the last call; `automatic` = sent by the state machine (tick,
  // on_frame), not by an explicit request.
  void check_sent(bool automatic) {
    for (const CanFrame& f : bus_.sent) {
      if (kTrace) trace("  sent", f);
      check_frame(f, automatic);
    }
    bus_.sent.clear();
    check_state();
  }

  void run(FuzzedDataProvider& in) {
    while (in.remaining_bytes() > 0) {
      switch (in.ConsumeIntegralInRange<int>(0, 11)) {
        case 0:
        case 1:
        case 2: {  // feedback
          const CanFrame f = make_frame(in);
          if (kTrace) trace("frame", f);
          record(f, now_, said_);
          ctl_.on_frame(f, now_);
          check_sent(true);
          break;
        }
        case 3:
        case 4: {  // the clock moves on, the loop ticks
          static constexpr std::int64_t kSteps[] = {0,   1,   5,   10,  19,  20,   21,   50,  99,
                                                    100, 101, 499, 500, 501, 1000, 1500, 5000};
          const std::int64_t ms = in.ConsumeBool()
                                      ? kSteps[in.ConsumeIntegralInRange<std::size_t>(
                                            0, sizeof(kSteps) / sizeof(kSteps[0]) - 1)]
                                      : in.ConsumeIntegralInRange<std::int64_t>(0, 3600000);
          now_ += milliseconds(ms);
          tick();
          break;
        }
        case 5:
          tick();
          break;
        case 6:
        case 7: {  // a command from the caller
          ranger::MotionRequest request;
          request.twist = {consume_double(in), consume_double(in), consume_double(in)};
          if (in.ConsumeBool()) {
            request.mode = static_cast<protocol::MotionMode>(pick(in, {0, 1, 2}));
          }
          command(request);
          break;
        }
        case 8: {  // a flood: the same command at 10 kHz for a while, ticking as a loop would
          ranger::MotionRequest request;
          request.twist = {consume_double(in), consume_double(in), consume_double(in)};
          const int n = in.ConsumeIntegralInRange<int>(1, 2000);
          for (int i = 0; i < n; ++i) {
            now_ += std::chrono::microseconds(100);
            command(request);
            if (i % 10 == 0) tick();
          }
          break;
        }
        case 9: {  // explicit requests
          switch (in.ConsumeIntegralInRange<int>(0, 3)) {
            case 0: {
              std::optional<protocol::MotionMode> mode;
              if (in.ConsumeBool()) mode = static_cast<protocol::MotionMode>(pick(in, {0, 1, 2}));
              ctl_.request_motion_mode(mode, now_);
              break;
            }
            case 1: {
              const auto mode = static_cast<protocol::ControlMode>(pick(in, {0, 1, 3}));
              const auto st = ctl_.request_control_mode(mode, now_);
              if (mode == protocol::ControlMode::kRemote) FUZZ_CHECK(!st.ok());
              break;
            }
            case 2: {
              const auto code = in.ConsumeIntegral<std::uint8_t>();
              const auto st = ctl_.clear_errors(code, now_);
              if (code > protocol::kMaxErrorClearCode) FUZZ_CHECK(!st.ok());
              break;
            }
            default:
              (void)ctl_.set_ultrasonic(in.ConsumeBool(), now_);
              break;
          }
          check_sent(false);
          break;
        }
        case 10:
          bus_.refuse(in.ConsumeBool());
          break;
        default:
          if (in.ConsumeIntegralInRange<int>(0, 7) == 0) {
            ctl_.shutdown(now_);
            shut_down_ = true;
            check_sent(false);
          }
          break;
      }
    }
  }

 private:
  void trace(const char* what, const CanFrame& f) const {
    std::fprintf(stderr, "%10.3f %s %s%03X [%d]", static_cast<double>(now_.count()) / 1e6, what,
                 f.is_error ? "err " : "", f.id, f.dlc);
    for (std::size_t i = 0; i < f.dlc && i < CanFrame::kMaxDlc; ++i) {
      std::fprintf(stderr, " %02X", f.data[i]);
    }
    std::fprintf(stderr, "\n");
  }

  void tick() {
    if (kTrace) std::fprintf(stderr, "%10.3f tick\n", static_cast<double>(now_.count()) / 1e6);
    ctl_.tick(now_);
    check_sent(true);
    if (!shut_down_) {  // (after shutdown nothing is due)
      FUZZ_CHECK(ctl_.next_tick_due() >= now_);
      FUZZ_CHECK(ctl_.next_tick_due() <= now_ + config_.keep_alive_period);
    }
  }

  void command(const ranger::MotionRequest& request) {
    if (kTrace) {
      std::fprintf(stderr, "%10.3f command %g %g %g mode %d\n",
                   static_cast<double>(now_.count()) / 1e6, request.twist.vx, request.twist.vy,
                   request.twist.wz, request.mode ? static_cast<int>(*request.mode) : -1);
    }
    const auto st = ctl_.set_command(request, now_);
    const bool ok_input = finite(request.twist);
    if (shut_down_) {
      FUZZ_CHECK(!st.ok());
    } else if (!ok_input) {
      FUZZ_CHECK(!st.ok() && st.error().code == ranger::Errc::kNotFinite);
    }
    if (!shut_down_) caller_ = CallerSaid{true, ok_input, now_};
    check_sent(false);
  }

  void check_frame(const CanFrame& f, bool automatic) {
    const auto message = ranger::decode(f);
    FUZZ_CHECK(message.ok());
    switch (f.id) {
      case protocol::kMotionCommandId:
        check_motion(std::get<ranger::MotionCommand>(*message));
        break;
      case protocol::kControlModeCommandId: {
        FUZZ_CHECK(f.data[0] == 0x00 || f.data[0] == 0x01);
        FUZZ_CHECK(!shut_down_ || !automatic);
        if (automatic) {
          FUZZ_CHECK(said_.status_time && said_.control_mode == 0x00);  // only from standby
          FUZZ_CHECK(f.data[0] == 0x01);
        }
        break;
      }
      case protocol::kMotionModeCommandId: {
        FUZZ_CHECK(automatic && !shut_down_);
        FUZZ_CHECK(f.data[0] <= 2);
        // Only at confirmed standstill (the controller's documented rule, same freshness).
        const auto fresh = [&](const std::optional<Timestamp>& t) {
          return t && now_ - *t <= config_.link_timeout;
        };
        if (fresh(said_.wheels_time)) {
          FUZZ_CHECK(said_.max_wheel_speed <= config_.standstill_speed + 1e-9);
        } else {
          FUZZ_CHECK(fresh(said_.motion_time));
          FUZZ_CHECK(said_.motion_speed <= config_.standstill_speed + 1e-9);
        }
        break;
      }
      default:
        break;
    }
  }

  void check_motion(const ranger::MotionCommand& cmd) {
    const auto& limits = config_.limits;
    constexpr double kWireEps = 0.0011;  // one wire count (mm/s, 0.01 deg) plus rounding
    FUZZ_CHECK(std::abs(cmd.linear_speed) <= limits.max_linear_speed + kWireEps);
    FUZZ_CHECK(std::abs(cmd.spin_speed) <= limits.max_spin_wheel_speed + kWireEps);
    FUZZ_CHECK(std::abs(cmd.steering_angle) <= limits.max_oblique_steering + 1e-3);
    if (cmd.linear_speed == 0.0 && cmd.spin_speed == 0.0 && cmd.steering_angle == 0.0) return;
    // Any non-zero field (steering alone turns the wheels) needs every condition for motion.
    FUZZ_CHECK(!shut_down_);
    FUZZ_CHECK(said_.status_time.has_value());
    FUZZ_CHECK(now_ - *said_.status_time <= config_.link_timeout);
    FUZZ_CHECK(said_.control_mode == 0x01);    // CAN command mode
    FUZZ_CHECK(said_.vehicle_status != 0x01);  // not e-stopped
    FUZZ_CHECK(!protocol::is_critical_error(said_.error_bits));
    FUZZ_CHECK(said_.have_mode && said_.switching == 0x00);  // mode known, not switching
    const auto& solution = ctl_.state().last_solution;
    FUZZ_CHECK(solution.has_value());
    FUZZ_CHECK(static_cast<std::uint8_t>(solution->mode) == said_.motion_mode);
    if (said_.motion_mode == static_cast<std::uint8_t>(protocol::MotionMode::kAckermann)) {
      FUZZ_CHECK(std::abs(cmd.steering_angle) <= limits.max_ackermann_steering + 1e-3);
    }
    FUZZ_CHECK(!said_.pack_soc || *said_.pack_soc >= config_.low_battery_soc);
    FUZZ_CHECK(caller_.any);
    FUZZ_CHECK(now_ - caller_.time < config_.cmd_timeout);
    if (!caller_.finite) {
      // A NaN/inf command means stop: at once, or along the configured deceleration ramp. The
      // command may carry no more speed than the (shrinking, see check_state) limited twist.
      const ranger::BodyTwist& t = ctl_.state().limited;
      const auto& g = config_.geometry;
      FUZZ_CHECK(std::abs(cmd.linear_speed) <= std::hypot(t.vx, t.vy) + kWireEps);
      FUZZ_CHECK(std::abs(cmd.spin_speed) <=
                 std::abs(t.wz) * std::hypot(g.wheelbase / 2, g.track / 2) + kWireEps);
    }
  }

  void check_state() {
    const ranger::ControllerState& s = ctl_.state();
    FUZZ_CHECK(finite(s.limited));
    FUZZ_CHECK(finite(s.requested.twist));
    if (s.last_motion_command) {
      FUZZ_CHECK(std::isfinite(s.last_motion_command->linear_speed) &&
                 std::isfinite(s.last_motion_command->spin_speed) &&
                 std::isfinite(s.last_motion_command->steering_angle));
    }
    if (s.last_solution) {
      FUZZ_CHECK(finite(s.last_solution->achieved));
    }
    FUZZ_CHECK(s.shut_down == shut_down_);
    if (caller_.any && !caller_.finite) {  // stopping after a NaN: never speeding up
      FUZZ_CHECK(std::abs(s.limited.vx) <= std::abs(limited_.vx) + 1e-12);
      FUZZ_CHECK(std::abs(s.limited.vy) <= std::abs(limited_.vy) + 1e-12);
      FUZZ_CHECK(std::abs(s.limited.wz) <= std::abs(limited_.wz) + 1e-12);
    }
    limited_ = s.limited;
  }

  ranger::ControllerConfig config_;
  RecordingBus bus_;
  ranger::ChassisController ctl_;
  Timestamp now_{std::chrono::seconds(1000)};
  ChassisSaid said_;
  CallerSaid caller_;
  ranger::BodyTwist limited_;  // state().limited at the previous check
  bool shut_down_ = false;
};

ranger::ControllerConfig make_config(FuzzedDataProvider& in) {
  ranger::ControllerConfig config;
  const auto variant = in.ConsumeIntegralInRange<int>(0, 3);
  if (variant == 1) {  // the ROS node's usual acceleration limits
    for (ranger::SpeedLimits* l : {&config.limit_vx, &config.limit_vy, &config.limit_wz}) {
      l->has_velocity_limits = l->has_acceleration_limits = true;
      l->min_velocity = -1.0;
      l->max_velocity = 1.0;
      l->min_acceleration = -2.0;
      l->max_acceleration = 1.0;
    }
  } else if (variant == 2) {
    config.auto_command_mode = false;
  }
  return config;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzedDataProvider in(data, size);
  const ranger::ControllerConfig config = make_config(in);
  FUZZ_CHECK(config.validate().ok());
  Harness harness(config);
  harness.run(in);
  return 0;
}
