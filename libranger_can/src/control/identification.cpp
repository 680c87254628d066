#include "ranger_can/control/identification.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <utility>
#include <variant>

#include "ranger_can/control/kinematics.hpp"
#include "ranger_can/control/odometry.hpp"
#include "ranger_can/text.hpp"
#include "ranger_can/wire/interpretation.hpp"

namespace ranger {
namespace {

using namespace std::chrono_literals;
using protocol::MotionMode;

using S = ProtocolSetting;
using text::degrees;
using text::duration_text;
using text::format;

// 0x271 counts as unchanged while every wheel stays within this (read in 0.01 deg: 2.5 units).
constexpr double kSettleTolerance = deg_to_rad(0.025);
// Rolling wheels for a rigid-body sample, and the smallest angle (read in 0.01 deg) that makes
// a sample tell the 0x271 readings apart.
constexpr double kRollingSpeed = 0.05;  // m/s
constexpr double kInformativeAngle = deg_to_rad(0.3);
constexpr int kMinRigidSamples = 10;
constexpr int kMinByte7Steps = 10;
constexpr int kMaxSteerProbes = 2;
// The reference (inner vs mean) is judged only at angles where the two differ measurably.
constexpr double kMinReferenceAngle = deg_to_rad(3.0);

const std::array<AngleUnit, 2> kUnits = {AngleUnit::kCentidegree, AngleUnit::kMilliradian};
const std::array<SteeringSign, 2> kSigns = {SteeringSign::kRightPositive,
                                            SteeringSign::kLeftPositive};
const std::array<SteeringReference, 2> kReferences = {SteeringReference::kMeanFront,
                                                      SteeringReference::kInnerFront};

// The best and second-best of a set of residuals (infinity for missing ones).
struct Ranking {
  int best = -1;
  double best_residual = std::numeric_limits<double>::infinity();
  double second_residual = std::numeric_limits<double>::infinity();
  void add(int index, double residual) {
    if (residual < best_residual) {
      second_residual = best_residual;
      best_residual = residual;
      best = index;
    } else if (residual < second_residual) {
      second_residual = residual;
    }
  }
  // Whether the best is within `tolerance` and the second at least `margin` times worse (a floor
  // keeps an exact fit from asking for an infinite margin of nothing).
  bool clear(double tolerance, double margin, double floor) const {
    return best >= 0 && best_residual <= tolerance &&
           second_residual >= margin * std::max(best_residual, floor);
  }
  double confidence() const {
    if (!std::isfinite(second_residual) || second_residual <= 0.0) return 1.0;
    return std::clamp(1.0 - best_residual / second_residual, 0.0, 1.0);
  }
};

std::string values_text(const std::array<double, 4>& a) {
  std::string out;
  for (double v : a)
    out += (out.empty() ? "" : " ") + text::fixed(rad_to_deg(v), 2);
  return out + " deg";
}

// A reading of an angle field: its unit and sign.
struct Reading271 {
  AngleUnit unit;
  SteeringSign sign;
};

// The four wheel angles (REP-103, rad) of a 0x271 frame read in `unit` and `sign` under `profile`;
// nullopt when that reading puts them beyond any model's reach.
std::optional<std::array<double, 4>> read_271(const CanFrame& frame, ProtocolProfile profile,
                                              AngleUnit unit, SteeringSign sign) {
  profile.steering_unit_271 = unit;
  profile.steering_sign_271 = sign;
  Result<Message> m = decode(frame, profile);
  if (!m) return std::nullopt;
  const auto* a = std::get_if<SteeringAnglesFeedback>(&*m);
  if (a == nullptr) return std::nullopt;
  std::array<double, 4> out{};
  for (std::size_t i = 0; i < out.size(); ++i)
    out[i] = interpretation::rep103_from_manual_wheel_angle(a->angles[i]);
  return out;
}

// One explanation of the steering probe's answer: a reading of 0x111 (unit, sign, reference) and
// of 0x271, with how well the predicted wheel angles fit the measured ones.
struct SteerCombo {
  AngleUnit u111;
  SteeringSign s111;
  SteeringReference ref;
  AngleUnit u271;
  SteeringSign s271;
  double commanded;  // REP-103 angle the chassis reads
  double residual;   // rad: the worst wheel's error
};

// Every combination of the 0x111 reading and the 0x271 readings `h271`: the wheel angles the
// probe (sent as `probe_wire_angle` under `proposal`) predicts against those `angles` shows.
std::vector<SteerCombo> rank_steer_combos(const CanFrame& angles, const ProtocolProfile& proposal,
                                          const VehicleGeometry& geometry, double probe_wire_angle,
                                          const std::vector<Reading271>& h271) {
  std::vector<SteerCombo> combos;
  // The wire value the probe went out as, read under each 0x111 hypothesis.
  MotionCommand sent;
  sent.steering_angle = probe_wire_angle;
  const Result<CanFrame> wire = encode(sent, proposal);
  for (AngleUnit u111 : kUnits) {
    for (SteeringSign s111 : kSigns) {
      ProtocolProfile p = proposal;
      p.steering_unit_111 = u111;
      p.steering_sign_111 = s111;
      Result<Message> read = wire ? decode(*wire, p) : Result<Message>(wire.error());
      if (!read) continue;
      const MotionCommand as_read = std::get<MotionCommand>(*read);
      for (SteeringReference ref : kReferences) {
        p.steering_reference = ref;
        const auto predicted =
            wheel_angles_for_command(as_read, MotionMode::kAckermann, geometry, p);
        for (const Reading271& h : h271) {
          const auto measured = read_271(angles, proposal, h.unit, h.sign);
          if (!measured) continue;
          double r = 0.0;
          for (std::size_t i = 0; i < 4; ++i)
            r = std::max(r, std::fabs((*measured)[i] - predicted[i]));
          combos.push_back(
              {u111, s111, ref, h.unit, h.sign,
               interpretation::rep103_from_manual_command_steering(as_read.steering_angle), r});
        }
      }
    }
  }
  return combos;
}

enum class SteerOutcome {
  kReprobeTooSmall,   // too small to tell the readings apart; the best fit names another 0x111
                      // unit: probe again in it
  kReprobeCorrected,  // a clear fit, but far smaller than asked: probe again in the corrected
                      // 0x111 unit and sign, so that the reference is judged at a useful angle
  kNoFit,             // no combination explains the answer clearly
  kDecided,
};

struct SteerDecision {
  SteerOutcome outcome = SteerOutcome::kNoFit;
  std::optional<SteerCombo> best;  // the best fit of units and signs (nullopt: nothing fits)
  double confidence = 1.0;         // of the units and signs
  // kDecided: the residuals of the winning units and signs under each reference (mean, inner),
  // and the reference where they tell it apart.
  std::array<double, 2> reference_residual{std::numeric_limits<double>::infinity(),
                                           std::numeric_limits<double>::infinity()};
  std::optional<SteeringReference> reference;
  double reference_confidence = 1.0;
};

bool same_readings(const SteerCombo& a, const SteerCombo& b) {
  return a.u111 == b.u111 && a.s111 == b.s111 && a.u271 == b.u271 && a.s271 == b.s271;
}

// The units and signs (the reference set aside: it is a 6 % effect): one entry per (u111, s111,
// u271, s271), that of its best reference.
Ranking rank_readings(const std::vector<SteerCombo>& combos) {
  Ranking gross;
  for (std::size_t c = 0; c < combos.size(); ++c) {
    bool dominated = false;
    for (std::size_t d = 0; d < combos.size(); ++d) {
      if (d != c && same_readings(combos[d], combos[c]) &&
          (combos[d].residual < combos[c].residual ||
           (combos[d].residual == combos[c].residual && d < c))) {
        dominated = true;
      }
    }
    if (!dominated) gross.add(static_cast<int>(c), combos[c].residual);
  }
  return gross;
}

// The reference, from the two entries of the winning units and signs: decided where they tell it
// apart (a turn of at least kMinReferenceAngle).
void decide_reference(const std::vector<SteerCombo>& combos, const IdentificationConfig& config,
                      SteerDecision& out) {
  const SteerCombo& g = *out.best;
  for (const SteerCombo& k : combos) {
    if (same_readings(k, g)) {
      out.reference_residual[k.ref == SteeringReference::kInnerFront ? 1 : 0] = k.residual;
    }
  }
  const int best_ref = out.reference_residual[1] < out.reference_residual[0] ? 1 : 0;
  const double lo = out.reference_residual[static_cast<std::size_t>(best_ref)];
  const double hi = out.reference_residual[static_cast<std::size_t>(1 - best_ref)];
  if (std::fabs(g.commanded) >= kMinReferenceAngle &&
      hi >= config.margin * std::max(lo, deg_to_rad(0.05))) {
    out.reference = kReferences[static_cast<std::size_t>(best_ref)];
    out.reference_confidence = hi > 0 ? 1.0 - lo / hi : 1.0;
  }
}

// What the steering probe's answer decides, given the proposal it was sent under and the number
// of probes made so far.
SteerDecision decide_steer(const std::vector<SteerCombo>& combos, const ProtocolProfile& proposal,
                           const IdentificationConfig& config, int probes) {
  const Ranking gross = rank_readings(combos);
  SteerDecision out;
  if (gross.best >= 0) out.best = combos[static_cast<std::size_t>(gross.best)];
  const double probe_tol = config.angle_tolerance + 0.1 * 6.0 * config.probe_angle;
  const bool clear = gross.clear(probe_tol, config.margin, deg_to_rad(0.1));
  const bool may_reprobe = probes < kMaxSteerProbes;
  // Far smaller than asked in another 0x111 unit than the proposal's: probe again in that unit.
  const bool too_small = out.best && std::fabs(out.best->commanded) < kMinReferenceAngle &&
                         may_reprobe && out.best->u111 != proposal.steering_unit_111;
  if (!clear) {
    out.outcome = too_small && gross.best_residual <= probe_tol ? SteerOutcome::kReprobeTooSmall
                                                                : SteerOutcome::kNoFit;
    return out;
  }
  if (too_small) {
    out.outcome = SteerOutcome::kReprobeCorrected;
    return out;
  }
  out.outcome = SteerOutcome::kDecided;
  out.confidence = gross.confidence();
  decide_reference(combos, config, out);
  return out;
}

// 0x221's steering angle read under each unit and sign, against what it should report for the
// wheels as they stand (`measured`, REP-103 rad) under the proposal's reference.
struct Angle221Decision {
  double expected = 0.0;              // rad, REP-103
  std::optional<Reading271> reading;  // the unit and sign, when one reading fits clearly
  double confidence = 1.0;
};

Angle221Decision decide_221(const CanFrame& motion, const std::array<double, 4>& m,
                            const ProtocolProfile& proposal, const IdentificationConfig& config) {
  Angle221Decision out;
  const double mean_front = (m[kRightFront] + m[kLeftFront]) / 2.0;
  const double inner_front =
      std::fabs(m[kRightFront]) > std::fabs(m[kLeftFront]) ? m[kRightFront] : m[kLeftFront];
  out.expected =
      proposal.steering_reference == SteeringReference::kInnerFront ? inner_front : mean_front;
  Ranking r221;
  for (int h = 0; h < 4; ++h) {
    ProtocolProfile p = proposal;
    p.steering_unit_221 = kUnits[h / 2];
    p.steering_sign_221 = kSigns[h % 2];
    Result<Message> fb = decode(motion, p);
    if (!fb) continue;
    const double a =
        interpretation::rep103_from_manual_steering(std::get<MotionFeedback>(*fb).steering_angle);
    r221.add(h, std::fabs(a - out.expected));
  }
  if (std::fabs(out.expected) >= deg_to_rad(1.0) &&
      r221.clear(config.angle_tolerance + 0.1 * std::fabs(out.expected), config.margin,
                 deg_to_rad(0.1))) {
    out.reading = Reading271{kUnits[r221.best / 2], kSigns[r221.best % 2]};
    out.confidence = r221.confidence();
  }
  return out;
}

}  // namespace

Status IdentificationConfig::validate() const {
  if (listen_time.count() <= 0 || timeout.count() <= 0 || step_timeout.count() <= 0 ||
      settle_time.count() <= 0) {
    return Error{Errc::kOutOfRange,
                 "identification: listen_time, timeout, step_timeout and settle_time must be > 0"};
  }
  if (listen_time >= timeout) {
    return Error{Errc::kOutOfRange, "identification: listen_time must be shorter than timeout"};
  }
  if (min_status_frames < 1) {
    return Error{Errc::kOutOfRange, "identification: min_status_frames must be >= 1"};
  }
  if (!(probe_angle > deg_to_rad(1.0) && probe_angle <= deg_to_rad(7.0))) {
    return Error{Errc::kOutOfRange,
                 "identification: probe_angle must be in (1, 7] deg (read 5.7 times larger in "
                 "the other unit it must stay within the 40 deg Ackermann range)"};
  }
  if (!(angle_tolerance > 0.0) || !(margin > 1.0)) {
    return Error{Errc::kOutOfRange, "identification: angle_tolerance must be > 0 and margin > 1"};
  }
  return ok_status();
}

std::string unidentified_message(const std::string& reason, std::chrono::nanoseconds timeout) {
  return "the chassis could not be identified within " + duration_text(timeout) +
         " (identify_timeout): " + reason +
         ". The robot stays at rest. Set the protocol instead of `auto` (protocol: manual or "
         "protocol: agx_v2, and single settings such as steering_unit_111: millirad), or "
         "commission it once with the wheels off the ground: `ranger_can commission IFACE "
         "--wheels-lifted --output FILE`, then load FILE with the parameter commissioning_file";
}

ChassisIdentifier::ChassisIdentifier(IdentificationConfig config, VehicleGeometry geometry,
                                     std::optional<std::string> forced_revision, bool read_only)
    : config_(std::move(config)),
      geometry_(geometry),
      forced_revision_(std::move(forced_revision)),
      read_only_(read_only) {
  status_.revision = forced_revision_.value_or("manual");
  if (auto p = protocol_preset(status_.revision)) status_.profile = *p;
  status_.message = "listening";
}

void ChassisIdentifier::start(Timestamp now) {
  if (started_) return;
  started_ = true;
  status_.started = now;
  timeout_from_ = now;
  status_.finished = now;
}

void ChassisIdentifier::note(std::string line) {
  status_.evidence.push_back(std::move(line));
}

void ChassisIdentifier::set(ProtocolSetting setting, std::string_view value, std::string evidence) {
  if (Status st = set_setting(status_.profile, setting, value); !st) {
    note("internal: " + st.error().message);
    return;
  }
  const std::string_view name = to_string(setting);
  for (IdentifiedSetting& s : status_.decided) {
    if (s.name == name) {
      s.value = std::string(value);
      s.evidence = evidence;
      note(evidence);
      return;
    }
  }
  status_.decided.push_back({std::string(name), std::string(value), evidence});
  note(std::move(evidence));
}

std::optional<std::array<double, 4>> ChassisIdentifier::wheel_angles(const CanFrame& frame,
                                                                     AngleUnit unit,
                                                                     SteeringSign sign) const {
  return read_271(frame, status_.profile, unit, sign);
}

// ---- frames
// --------------------------------------------------------------------------------------

void ChassisIdentifier::on_frame(const CanFrame& frame, Timestamp now) {
  start(now);
  if (frame.is_error || status_.done()) return;
  observe_passive(frame);
  observe_probe(frame, now);
}

void ChassisIdentifier::observe_passive(const CanFrame& frame) {
  observe_origin(frame);
  switch (frame.id) {
    case protocol::kSystemStatusId:
      observe_status(frame);
      break;
    case protocol::kMotionModeFeedbackId:
      if (Result<Message> m = decode(frame, status_.profile)) {
        max_mode_raw_ = std::max<int>(max_mode_raw_, std::get<MotionModeFeedback>(*m).mode_raw);
      }
      break;
    case protocol::kBmsBaseId:  // the whole pack
      observe_bms(frame);
      break;
    case protocol::kSteeringAnglesId:
      last_angles_frame_ = frame;
      last_angles_time_ = frame.stamp;
      break;
    case protocol::kWheelSpeedsId:
      observe_rolling(frame);
      break;
    default:
      break;
  }
}

void ChassisIdentifier::observe_origin(const CanFrame& frame) {
  const std::uint32_t id = frame.id;
  if (!protocol::is_chassis_frame(frame)) return;  // the host's own commands do not count
  // Frames only the vendor's revision defines, sent by the chassis (the frame table).
  if ((protocol::find_frame(id)->revisions & protocol::kInManual) == 0) {
    const std::string what = text::hex(id) + " (" + std::string(protocol::frame_name(id)) + ")";
    if (std::find(agx_signatures_.begin(), agx_signatures_.end(), what) == agx_signatures_.end()) {
      agx_signatures_.push_back(what);
    }
  }
  // Padding: a chassis frame longer than its layout.
  if (protocol::extra_bytes(frame) > 0 &&
      std::find(padded_ids_.begin(), padded_ids_.end(), id) == padded_ids_.end()) {
    padded_ids_.push_back(id);
  }
}

void ChassisIdentifier::observe_status(const CanFrame& frame) {
  // Read with the agx16 layout: byte 7 is then `counter`, whatever the chassis means by it.
  ProtocolProfile agx = status_.profile;
  agx.error_word = ErrorWordLayout::kAgxV2_16;
  Result<Message> m = decode(frame, agx);
  if (!m) return;
  const auto& st = std::get<SystemStatus>(*m);
  if (status_frames_++ == 0) first_status_ = status_.started;
  status_voltage_ = st.battery_voltage;
  if (st.control_mode_raw == static_cast<std::uint8_t>(protocol::ControlMode::kUart)) {
    uart_seen_ = true;
  }
  const std::uint8_t b7 = st.counter.value_or(0);
  if (last_byte7_) {
    ++byte7_steps_;
    if (b7 != *last_byte7_) ++byte7_changes_;
    if (b7 == static_cast<std::uint8_t>(*last_byte7_ + 1)) ++byte7_increments_;
  }
  last_byte7_ = b7;
}

void ChassisIdentifier::observe_bms(const CanFrame& frame) {
  ProtocolProfile p = status_.profile;
  p.bms_voltage_scale = 0.01;
  Result<Message> m = decode(frame, p);
  if (!m || !status_voltage_) return;
  const double v001 = std::get<BmsData>(*m).voltage;
  const double v01 = v001 * 10.0;
  const double ref = *status_voltage_;
  const double tol = std::max(2.0, 0.05 * ref);
  ++bms_frames_;
  if (std::fabs(v001 - ref) <= tol) ++bms_agree_001_;
  if (std::fabs(v01 - ref) <= tol) ++bms_agree_01_;
}

void ChassisIdentifier::observe_rolling(const CanFrame& frame) {
  if (!last_angles_frame_ || frame.stamp - last_angles_time_ > 60ms ||
      frame.stamp < last_angles_time_) {
    return;
  }
  Result<Message> m = decode(frame, status_.profile);
  if (!m) return;
  const auto& speeds = std::get<WheelSpeedsFeedback>(*m).speeds;
  double fastest = 0.0;
  for (double s : speeds)
    fastest = std::max(fastest, std::fabs(s));
  if (fastest < kRollingSpeed) return;
  // Informative only when the wheels are steered (straight wheels fit every reading).
  const auto plain =
      wheel_angles(*last_angles_frame_, AngleUnit::kCentidegree, SteeringSign::kRightPositive);
  if (plain) {
    double widest = 0.0;
    for (double a : *plain)
      widest = std::max(widest, std::fabs(a));
    if (widest < kInformativeAngle) return;
  }
  double norm = 0.0;
  for (double s : speeds)
    norm += s * s;
  ++rigid_samples_;
  for (int h = 0; h < 4; ++h) {
    const auto angles = wheel_angles(*last_angles_frame_, kUnits[h / 2], kSigns[h % 2]);
    if (!angles) {
      ++rigid_impossible_[h];
      continue;
    }
    std::array<WheelMeasurement, kWheelCount> wheels{};
    for (int i = 0; i < kWheelCount; ++i)
      wheels[i] = {(*angles)[i], speeds[i]};
    const BodyTwist t = fit_body_twist(wheels, geometry_);
    double r = 0.0;
    for (int i = 0; i < kWheelCount; ++i) {
      const WheelPosition p = geometry_.wheel_position(i);
      const double ex = t.vx - t.wz * p.y - speeds[i] * std::cos((*angles)[i]);
      const double ey = t.vy + t.wz * p.x - speeds[i] * std::sin((*angles)[i]);
      r += ex * ex + ey * ey;
    }
    rigid_residual_[h] += r / norm;
  }
}

void ChassisIdentifier::observe_probe(const CanFrame& frame, Timestamp now) {
  if (frame.id == protocol::kSystemStatusId) {
    Result<Message> m = decode(frame, status_.profile);
    if (m) control_mode_raw_ = std::get<SystemStatus>(*m).control_mode_raw;
  } else if (frame.id == protocol::kMotionModeFeedbackId) {
    Result<Message> m = decode(frame, status_.profile);
    if (!m) return;
    const auto& mm = std::get<MotionModeFeedback>(*m);
    mode_ = mm.mode_known ? std::optional<MotionMode>(mm.mode) : std::nullopt;
    switching_ = mm.switching;
  } else if (frame.id == protocol::kSteeringAnglesId) {
    const auto before =
        angles_ ? wheel_angles(*angles_, AngleUnit::kCentidegree, SteeringSign::kRightPositive)
                : std::nullopt;
    const auto after = wheel_angles(frame, AngleUnit::kCentidegree, SteeringSign::kRightPositive);
    bool changed = !angles_;
    if (!changed) {
      if (before && after) {
        for (std::size_t i = 0; i < 4; ++i)
          changed = changed || std::fabs((*before)[i] - (*after)[i]) > kSettleTolerance;
      } else {
        changed = !std::equal(frame.data.begin(), frame.data.begin() + frame.dlc,
                              angles_->data.begin()) ||
                  frame.dlc != angles_->dlc;
      }
    }
    if (changed) angles_changed_ = now;
    angles_ = frame;
  } else if (frame.id == protocol::kMotionFeedbackId) {
    motion_ = frame;
  }
}

// ---- phases
// --------------------------------------------------------------------------------------

void ChassisIdentifier::tick(Timestamp now) {
  start(now);
  if (status_.done()) return;
  status_.finished = now;
  // Under the remote control the operator drives: waiting for CAN command mode is no failure,
  // and the time for the probe counts from when the remote hands back.
  if (status_.phase == IdentificationPhase::kAwaitingControl &&
      (under_remote() || !probe_hold_.empty())) {
    timeout_from_ = now;
  }
  if (now - timeout_from_ >= config_.timeout) {
    fail(timeout_reason(), now);
    return;
  }
  switch (status_.phase) {
    case IdentificationPhase::kListening:
      tick_listening(now);
      break;
    case IdentificationPhase::kAwaitingControl:
      tick_awaiting_control(now);
      break;
    default:
      tick_step(now);
      break;
  }
}

std::string ChassisIdentifier::timeout_reason() const {
  switch (status_.phase) {
    case IdentificationPhase::kListening:
      return status_frames_ == 0 ? "no system status (0x211) heard: is the chassis on and the bus "
                                   "at 500 kbit/s?"
                                 : "too few system status frames (0x211) heard";
    case IdentificationPhase::kAwaitingControl:
      if (!control_mode_raw_) return "no system status (0x211) heard";
      if (*control_mode_raw_ != static_cast<std::uint8_t>(protocol::ControlMode::kCan)) {
        return "CAN command mode was not granted (0x211 control mode " +
               std::to_string(*control_mode_raw_) + "): is the remote control in charge?";
      }
      return "no known motion mode (0x291) reported";
    default:
      return "the steering probe did not finish (" + std::string(to_string(status_.phase)) + ")";
  }
}

void ChassisIdentifier::tick_listening(Timestamp now) {
  if (status_frames_ < static_cast<std::uint64_t>(config_.min_status_frames) ||
      now - status_.started < config_.listen_time) {
    status_.message = "identifying the chassis: listening (" +
                      duration_text(now - status_.started) + " of " +
                      duration_text(config_.listen_time) + ")";
    return;
  }
  decide_passive(now);
  if (read_only_) {
    decide(now);
  } else {
    status_.phase = IdentificationPhase::kAwaitingControl;
    status_.message = "identifying the chassis: waiting for CAN command mode";
  }
}

void ChassisIdentifier::tick_awaiting_control(Timestamp now) {
  const bool ready = control_mode_raw_ == static_cast<std::uint8_t>(protocol::ControlMode::kCan) &&
                     mode_ && !switching_;
  if (ready && !probe_hold_.empty()) {
    status_.message = "identifying the chassis: the steering probe waits: " + probe_hold_;
  } else if (ready) {
    begin_step(config_.spin_check && !verdict_271_ ? IdentificationPhase::kSpinCheck
                                                   : IdentificationPhase::kSteerProbe,
               now);
  } else if (under_remote()) {
    observe_remote_driving(now);
  } else {
    status_.message = "identifying the chassis: waiting for CAN command mode";
  }
}

// The probe's steps: the spin check, the steering probe, the return to straight.
void ChassisIdentifier::tick_step(Timestamp now) {
  const bool timed_out = now - step_started_ >= config_.step_timeout;
  switch (status_.phase) {
    case IdentificationPhase::kSpinCheck:
      if (settled(now)) {
        evaluate_spin(now);
      } else if (timed_out) {
        note("spin check: no settled answer within " + duration_text(config_.step_timeout) +
             " (mode " +
             (mode_ ? std::string(protocol::to_string(*mode_)) : std::string("unknown")) +
             "); the steering probe decides the 0x271 reading alone");
        begin_step(IdentificationPhase::kSteerProbe, now);
      }
      break;
    case IdentificationPhase::kSteerProbe:
      if (settled(now)) {
        evaluate_steer(now);
      } else if (timed_out) {
        fail("the steering probe got no settled answer (0x271) within " +
                 duration_text(config_.step_timeout),
             now);
      }
      break;
    case IdentificationPhase::kReturning:
      if (settled(now) || timed_out) decide(now);
      break;
    default:
      break;
  }
}

void ChassisIdentifier::begin_step(IdentificationPhase phase, Timestamp now) {
  status_.phase = phase;
  step_started_ = now;
  angles_changed_ = now;
  switch (phase) {
    case IdentificationPhase::kSpinCheck:
      status_.message = "identifying the chassis: spin position at standstill";
      break;
    case IdentificationPhase::kSteerProbe: {
      ++steer_probes_;
      // The probe: probe_angle to the left (REP-103) under the proposal, as the codec will send
      // it (rounded to the wire's unit).
      MotionCommand c;
      c.steering_angle = interpretation::manual_from_rep103_command_steering(config_.probe_angle);
      Result<CanFrame> f = encode(c, status_.profile);
      Result<Message> back = f ? decode(*f, status_.profile) : Result<Message>(f.error());
      probe_wire_angle_ = back ? std::get<MotionCommand>(*back).steering_angle : c.steering_angle;
      status_.message = "identifying the chassis: steering probe " + degrees(config_.probe_angle) +
                        " at standstill";
      break;
    }
    case IdentificationPhase::kReturning:
      status_.message = "identifying the chassis: wheels back to straight";
      break;
    default:
      break;
  }
}

bool ChassisIdentifier::settled(Timestamp now) const {
  MotionMode wanted = MotionMode::kAckermann;
  if (status_.phase == IdentificationPhase::kSpinCheck) wanted = MotionMode::kSpin;
  if (mode_ != wanted || switching_ || !angles_) return false;
  // At least a settle time after the step began (the command needs a moment to arrive), and the
  // wheels unchanged for one.
  return now - step_started_ >= 2 * config_.settle_time &&
         now - angles_changed_ >= config_.settle_time;
}

void ChassisIdentifier::evaluate_spin(Timestamp now) {
  judge_spin_position("spin position at standstill", /*quiet_if_unclear=*/false);
  begin_step(IdentificationPhase::kSteerProbe, now);
}

bool ChassisIdentifier::judge_spin_position(const std::string& context, bool quiet_if_unclear) {
  const auto expected =
      wheel_angles_for_command(MotionCommand{}, MotionMode::kSpin, geometry_, status_.profile);
  Ranking rank;
  std::string seen;
  for (int h = 0; h < 4; ++h) {
    const auto angles = wheel_angles(*angles_, kUnits[h / 2], kSigns[h % 2]);
    if (!angles) continue;
    double r = 0.0;
    for (std::size_t i = 0; i < 4; ++i)
      r = std::max(r, std::fabs((*angles)[i] - expected[i]));
    rank.add(h, r);
  }
  const auto plain = wheel_angles(*angles_, AngleUnit::kCentidegree, SteeringSign::kRightPositive);
  const double tol = config_.angle_tolerance + 0.1 * std::fabs(expected[0]);
  if (rank.clear(tol, config_.margin, deg_to_rad(0.2))) {
    const Hypothesis271 v{kUnits[rank.best / 2], kSigns[rank.best % 2]};
    verdict_271_ = v;
    min_margin_ = std::min(min_margin_, rank.confidence());
    const std::string read = context + ": 0x271 read " +
                             (plain ? values_text(*plain) + " in 0.01 deg" : "beyond 100 deg") +
                             ", expected +-" + degrees(std::fabs(expected[0])) +
                             " (atan(wheelbase/track), RF +, RR -, LR +, LF - in REP-103)";
    set(S::kSteeringUnit271, to_string(v.unit),
        read + ": the unit is " + std::string(to_string(v.unit)));
    set(S::kSteeringSign271, to_string(v.sign),
        "spin position sign pattern: " + std::string(to_string(v.sign)));
    return true;
  }
  if (!quiet_if_unclear) {
    note("spin check inconclusive: 0x271 " + (plain ? values_text(*plain) : std::string("?")) +
         " fits no reading of the spin position " + degrees(std::fabs(expected[0])) +
         " (best residual " + degrees(rank.best_residual) + ")");
  }
  return false;
}

bool ChassisIdentifier::under_remote() const {
  return control_mode_raw_ == static_cast<std::uint8_t>(protocol::ControlMode::kRemote);
}

void ChassisIdentifier::observe_remote_driving(Timestamp now) {
  // The remote's own driving tells the 0x271 reading: steered wheels rolling (the rigid-body
  // fit), or the wheels held at the spin position while the remote spins.
  if (!verdict_271_) judge_rigid_body(/*quiet_if_unclear=*/true);
  if (!verdict_271_ && mode_ == MotionMode::kSpin && !switching_ && angles_ &&
      now - angles_changed_ >= config_.settle_time) {
    judge_spin_position("spin position while the remote control spins", true);
  }
  std::string text = "identifying the chassis under the remote control: ";
  if (verdict_271_) {
    text += "the wheels' reading is decided (steering_unit_271 " +
            std::string(to_string(verdict_271_->unit)) + ", steering_sign_271 " +
            std::string(to_string(verdict_271_->sign)) + ": odometry and joint states follow)";
  } else {
    text +=
        "the wheels' reading (steering_unit_271, steering_sign_271) is not known yet: odometry "
        "and joint states wait for the remote to drive with the wheels steered, or to spin";
  }
  text +=
      "; still lacking for commands: steering_unit_111, steering_sign_111, steering_reference, "
      "steering_unit_221, steering_sign_221 (probed at standstill once CAN command mode is "
      "granted)";
  status_.message = text;
}

void ChassisIdentifier::evaluate_steer(Timestamp now) {
  std::vector<Reading271> h271;
  if (verdict_271_) {
    h271.push_back({verdict_271_->unit, verdict_271_->sign});
  } else {
    for (int h = 0; h < 4; ++h)
      h271.push_back({kUnits[h / 2], kSigns[h % 2]});
  }
  const std::vector<SteerCombo> combos =
      rank_steer_combos(*angles_, status_.profile, geometry_, probe_wire_angle_, h271);
  const SteerDecision d = decide_steer(combos, status_.profile, config_, steer_probes_);
  const auto plain = wheel_angles(*angles_, AngleUnit::kCentidegree, SteeringSign::kRightPositive);
  const std::string seen = plain ? values_text(*plain) + " (read in 0.01 deg)" : "beyond 100 deg";
  switch (d.outcome) {
    case SteerOutcome::kReprobeTooSmall:
      note("steering probe 1: 0x271 came back " + (plain ? values_text(*plain) : std::string("?")) +
           ", too small to judge: probing again in " + std::string(to_string(d.best->u111)));
      status_.profile.steering_unit_111 = d.best->u111;
      begin_step(IdentificationPhase::kSteerProbe, now);
      return;
    case SteerOutcome::kReprobeCorrected:
      note("steering probe 1: 0x271 came back " + seen + ", " +
           degrees(std::fabs(d.best->commanded)) + " where " + degrees(config_.probe_angle) +
           " was asked: 0x111 reads " + std::string(to_string(d.best->u111)) +
           "; probing again in that unit");
      status_.profile.steering_unit_111 = d.best->u111;
      status_.profile.steering_sign_111 = d.best->s111;
      begin_step(IdentificationPhase::kSteerProbe, now);
      return;
    case SteerOutcome::kNoFit:
      fail("the steering probe's answer fits no reading of the protocol: 0x111 steering " +
               degrees(config_.probe_angle) + " to the left (as " +
               std::string(to_string(status_.profile.steering_unit_111)) + ", " +
               std::string(to_string(status_.profile.steering_sign_111)) + "), 0x271 came back " +
               seen + (d.best ? ", best fit off by " + degrees(d.best->residual) : ""),
           now);
      return;
    case SteerOutcome::kDecided:
      break;
  }
  const SteerCombo g = *d.best;
  const double actual = std::fabs(g.commanded);
  min_margin_ = std::min(min_margin_, d.confidence);
  if (!verdict_271_) {
    set(S::kSteeringUnit271, to_string(g.u271),
        "steering probe: 0x271 came back " + seen + ": the four wheels fit 0x271 in " +
            std::string(to_string(g.u271)));
    set(S::kSteeringSign271, to_string(g.s271),
        "steering probe: the wheels' pattern fits 0x271 " + std::string(to_string(g.s271)));
    verdict_271_ = Hypothesis271{g.u271, g.s271};
  }
  const std::string asked = "steering probe: " + degrees(config_.probe_angle) +
                            " to the left asked at standstill, the wheels stand at " + seen;
  set(S::kSteeringUnit111, to_string(g.u111),
      asked + ": 0x111 reads " + std::string(to_string(g.u111)) + " (" + degrees(actual) +
          " steered)");
  set(S::kSteeringSign111, to_string(g.s111),
      std::string("steering probe: the wheels turned ") + (g.commanded > 0 ? "left" : "right") +
          ": 0x111 is " + std::string(to_string(g.s111)));
  const double r_mean = d.reference_residual[0], r_inner = d.reference_residual[1];
  if (d.reference) {
    const bool inner = *d.reference == SteeringReference::kInnerFront;
    min_margin_ = std::min(min_margin_, d.reference_confidence);
    set(S::kSteeringReference, to_string(*d.reference),
        std::string("steering probe: ") +
            (inner ? "the inner front wheel" : "the front wheels' mean") +
            " stands at the commanded " + degrees(actual) + " (off by " +
            degrees(inner ? r_inner : r_mean) + "; the " + (inner ? "mean" : "inner wheel") +
            " is off by " + degrees(inner ? r_mean : r_inner) + ")");
  } else {
    note("steering probe: the reference (inner or mean front wheel) is not decidable at " +
         degrees(actual) + " (residuals " + degrees(r_mean) + " mean, " + degrees(r_inner) +
         " inner): kept " + std::string(to_string(status_.profile.steering_reference)));
  }
  // 0x221: its angle against what the chassis should report for the wheels as they stand.
  if (motion_) {
    const auto measured = wheel_angles(*angles_, g.u271, g.s271);
    const Angle221Decision a = decide_221(*motion_, *measured, status_.profile, config_);
    if (a.reading) {
      min_margin_ = std::min(min_margin_, a.confidence);
      set(S::kSteeringUnit221, to_string(a.reading->unit),
          "steering probe: 0x221 reports " + degrees(a.expected) + " in " +
              std::string(to_string(a.reading->unit)));
      set(S::kSteeringSign221, to_string(a.reading->sign),
          "steering probe: 0x221's angle is " + std::string(to_string(a.reading->sign)));
    } else {
      note("steering probe: 0x221's angle fits no reading clearly: kept its preset");
    }
  } else {
    note("steering probe: no 0x221 heard: its steering unit and sign kept from the preset");
  }
  begin_step(IdentificationPhase::kReturning, now);
}

void ChassisIdentifier::decide_passive(Timestamp now) {
  const std::string listened = duration_text(now - status_.started);
  if (!forced_revision_) {
    if (!agx_signatures_.empty() || uart_seen_) {
      status_.revision = "agx_v2";
      std::string what;
      for (const auto& s : agx_signatures_)
        what += (what.empty() ? "" : ", ") + s;
      if (uart_seen_) what += std::string(what.empty() ? "" : ", ") + "0x211 control mode 2 (UART)";
      note("heard " + what + ": only the vendor's revision sends it: preset agx_v2");
    } else {
      status_.revision = "manual";
      note(
          "no frame only the vendor's revision sends (0x231, 0x241, 0x311, 0x4A1 answers, "
          "control mode UART) in " +
          listened + ": preset manual");
    }
  } else {
    note("preset " + status_.revision + " given (not identified)");
  }
  if (auto p = protocol_preset(status_.revision)) status_.profile = *p;
  // Frame lengths.
  if (!padded_ids_.empty()) {
    std::string ids;
    for (std::uint32_t id : padded_ids_)
      ids += (ids.empty() ? "" : ", ") + text::hex(id);
    set(S::kTxDlc, "8",
        "the chassis pads its frames (" + ids +
            " longer than their layout): commands padded to 8 bytes");
  } else {
    note("no chassis frame longer than its layout: tx_dlc kept at the preset's " +
         std::to_string(status_.profile.tx_dlc));
  }
  // 0x211 byte 7.
  if (byte7_steps_ >= kMinByte7Steps && byte7_increments_ * 10 >= byte7_steps_ * 9) {
    set(S::kErrorWord, "agx16",
        "0x211 byte 7 rose by one in " + std::to_string(byte7_increments_) + " of " +
            std::to_string(byte7_steps_) + " frames: a counter, so bytes 4-5 are the error word");
  } else if (byte7_steps_ >= kMinByte7Steps && byte7_changes_ == 0) {
    set(S::kErrorWord, to_string(status_.profile.error_word),
        "0x211 byte 7 constant over " + std::to_string(byte7_steps_ + 1) +
            " frames: no counter; the preset's layout stands");
  } else {
    note("0x211 byte 7 neither counts nor stays constant (" + std::to_string(byte7_changes_) +
         " changes in " + std::to_string(byte7_steps_) + " frames): error_word kept");
  }
  // Motion-mode numbering.
  if (max_mode_raw_ > 2 && status_.profile.mode_numbering == ModeNumbering::kManual) {
    set(S::kModeNumbering, "agx_v2",
        "0x291 reported mode " + std::to_string(max_mode_raw_) +
            ": beyond the manual's 0-2, so the vendor's numbering");
  }
  // BMS voltage scale.
  if (bms_frames_ > 0 && bms_agree_01_ != bms_agree_001_) {
    const bool tenth = bms_agree_01_ > bms_agree_001_;
    set(S::kBmsVoltageScale, tenth ? "0.1" : "0.01",
        "0x361 voltage agrees with 0x211's " + format("%.1f", status_voltage_.value_or(0.0)) +
            " V in " + (tenth ? "0.1 V" : "0.01 V") + " (" +
            std::to_string(std::max(bms_agree_01_, bms_agree_001_)) + " of " +
            std::to_string(bms_frames_) + " frames)");
  } else if (bms_frames_ == 0) {
    note("no BMS frame (0x361) with a battery voltage to compare: bms_voltage_scale kept");
  }
  judge_rigid_body(/*quiet_if_unclear=*/false);
}

bool ChassisIdentifier::judge_rigid_body(bool quiet_if_unclear) {
  // Rigid-body fits while the wheels rolled.
  if (rigid_samples_ >= kMinRigidSamples) {
    Ranking rank;
    for (int h = 0; h < 4; ++h) {
      if (rigid_impossible_[h] > 0) continue;
      rank.add(h, std::sqrt(rigid_residual_[h] / rigid_samples_));
    }
    if (rank.clear(0.1, config_.margin, 0.005)) {
      verdict_271_ = Hypothesis271{kUnits[rank.best / 2], kSigns[rank.best % 2]};
      min_margin_ = std::min(min_margin_, rank.confidence());
      const std::string why = "the rolling wheels (" + std::to_string(rigid_samples_) +
                              " samples) form one rigid-body motion only under 0x271 " +
                              std::string(to_string(verdict_271_->unit)) + ", " +
                              std::string(to_string(verdict_271_->sign)) + " (relative residual " +
                              format("%.3f", rank.best_residual) + ", next " +
                              format("%.3f", rank.second_residual) + ")";
      set(S::kSteeringUnit271, to_string(verdict_271_->unit), why);
      set(S::kSteeringSign271, to_string(verdict_271_->sign), why);
      return true;
    }
    if (!quiet_if_unclear) {
      note("rolling wheels seen (" + std::to_string(rigid_samples_) +
           " samples) but no 0x271 reading fits them clearly");
    }
  }
  return false;
}

void ChassisIdentifier::fail(std::string why, Timestamp now) {
  status_.phase = IdentificationPhase::kFailed;
  status_.finished = now;
  note("failed: " + why);
  status_.message = unidentified_message(why, config_.timeout);
  status_.confidence = 0.0;
}

void ChassisIdentifier::decide(Timestamp now) {
  status_.phase = IdentificationPhase::kDecided;
  status_.finished = now;
  status_.profile.revision = status_.revision;
  status_.undecided.clear();
  for (const ProfileSetting& s : profile_settings()) {
    const bool known = std::any_of(status_.decided.begin(), status_.decided.end(),
                                   [&](const IdentifiedSetting& d) { return d.name == s.name; });
    if (!known) status_.undecided.emplace_back(s.name);
  }
  status_.confidence = min_margin_;
  status_.message =
      "identified in " + duration_text(now - status_.started) + ": " + describe(status_.profile);
}

void ChassisIdentifier::finish(Timestamp now) {
  start(now);
  if (status_.done()) return;
  status_.finished = now;
  if (status_frames_ == 0) {
    fail("no system status (0x211) in the input", now);
    return;
  }
  decide_passive(now);
  decide(now);
}

bool ChassisIdentifier::adopt(std::string_view name, std::string_view value, std::string evidence) {
  auto it = std::find(status_.undecided.begin(), status_.undecided.end(), name);
  const auto setting = kProtocolSettingNames.parse(name);
  if (!status_.decided_ok() || it == status_.undecided.end() || !setting) return false;
  ProtocolProfile p = status_.profile;
  if (!set_setting(p, *setting, value)) return false;
  status_.undecided.erase(it);
  set(*setting, value, "learned while driving: " + evidence);
  status_.message = "identified: " + describe(status_.profile);
  return true;
}

IdentificationRequest ChassisIdentifier::request() const {
  IdentificationRequest r;
  if (status_.phase == IdentificationPhase::kListening || read_only_) return r;
  r.quiet = false;
  r.profile = status_.profile;
  switch (status_.phase) {
    case IdentificationPhase::kSpinCheck:
      r.mode = MotionMode::kSpin;
      r.probe = MotionCommand{};
      break;
    case IdentificationPhase::kSteerProbe: {
      r.mode = MotionMode::kAckermann;
      MotionCommand c;
      c.steering_angle = probe_wire_angle_;
      r.probe = c;
      break;
    }
    case IdentificationPhase::kReturning:
      r.mode = MotionMode::kAckermann;
      r.probe = MotionCommand{};
      break;
    default:
      break;
  }
  return r;
}

IdentificationStatus identify_log(const std::vector<CanFrame>& frames,
                                  const VehicleGeometry& geometry,
                                  const IdentificationConfig& config,
                                  std::optional<std::string> forced_revision) {
  ChassisIdentifier id(config, geometry, std::move(forced_revision), /*read_only=*/true);
  Timestamp last{0};
  for (const CanFrame& f : frames) {
    id.on_frame(f, f.stamp);
    last = std::max(last, f.stamp);
  }
  id.finish(last);
  return id.status();
}

}  // namespace ranger
