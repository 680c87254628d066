// `ranger_can commission IFACE --wheels-lifted [--output FILE]`: a guided first start for a
// chassis on blocks. Identifies it (as `identify`), takes CAN control, then makes small, slow,
// bounded moves, each read back from the feedback: steering a few degrees each way at zero speed,
// a slow spin, a slow roll forward with the wheels steered. Decides every setting it can, says
// which it cannot, prints the table and writes the commissioning file the node loads with
// `commissioning_file` (control/commissioning.hpp). At the end, on a failure and on Ctrl-C it
// sends the stop and hands CAN control back (0x421 standby).
#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <ostream>
#include <string>
#include <vector>

#include "cli_commands.hpp"
#include "cli_options.hpp"
#include "cli_profile.hpp"
#include "cli_session.hpp"
#include "cli_signals.hpp"
#include "ranger_can/control/commissioning.hpp"
#include "ranger_can/control/kinematics.hpp"
#include "ranger_can/control/odometry.hpp"
#include "ranger_can/text.hpp"
#include "ranger_can/wire/interpretation.hpp"

namespace ranger::cli {

namespace {

using namespace std::chrono_literals;
using protocol::MotionMode;

using S = ProtocolSetting;
using text::fixed;

constexpr double kSteerProbe = deg_to_rad(5.0);  // each way, at zero speed
constexpr double kSpinRate = 0.3;                // rad/s: 0.16 m/s at the wheels of a RANGER
constexpr double kRollSpeed = 0.2;               // m/s
constexpr double kRollCurvature = 0.8;           // 1/m: about 20 deg at the front wheels
constexpr auto kMoveTimeout = std::chrono::seconds(5);

// Degrees with two decimals, without the unit.
std::string deg2(double rad) {
  return fixed(rad_to_deg(rad), 2);
}

std::string spin_reading(const ProtocolProfile& p) {
  return std::string(to_string(p.spin_field)) + "/" + (p.spin_sign > 0 ? "ccw" : "cw");
}

struct Row {
  ProtocolSetting setting;
  std::string value;
  bool decided = false;
  std::string commanded;  // what was asked ("-" for what was only listened to)
  std::string came_back;  // what the chassis answered
  std::string evidence;   // for the file's comment
};

// What the slow roll measured, averaged over its samples.
struct RollSample {
  int n = 0;               // samples with 0x221 and 0x281
  double reported = 0.0;   // 0x221's speed
  double mean = 0.0;       // the wheels' mean speed
  double body = 0.0;       // the body centre's (odometry)
  double wz = 0.0;         // the body's yaw rate
  int current_n = 0;       // samples with 0x361
  double current = 0.0;    // its current, as on the wire
  int driver_reports = 0;  // motor drivers heard (0x261-0x268)
  int disabled = 0;        // of which read as disabled
};

struct Commission {
  DriverSession& s;
  Io io;
  ProtocolProfile profile;
  DriverConfig config;
  std::vector<Row> rows;
  std::string failure;  // a move without a response (or a contradiction): nothing is written

  std::string value(S setting) const { return *get_setting(profile, setting); }

  void set_row(Row r) {
    for (Row& x : rows) {
      if (x.setting == r.setting) {
        x = std::move(r);
        return;
      }
    }
    rows.push_back(std::move(r));
  }
  bool has_row(S setting) const {
    return std::any_of(rows.begin(), rows.end(),
                       [&](const Row& r) { return r.setting == setting; });
  }

  bool fail(const std::string& why) {
    failure = why;
    return false;
  }

  // Waits for CAN mode, `mode` (not switching) and, with `settle`, 0x271 unchanged 300 ms.
  bool wait_standing(MotionMode mode, const std::string& move) {
    std::optional<std::array<double, 4>> last;
    Timestamp steady_since = s.now();
    const Timestamp began = s.now();
    const bool ok = s.run_until(
        [&](const DriverSnapshot& snap) {
          const auto& c = snap.controller;
          const auto& a = snap.feedback.steering_angles;
          if (c.control_mode != protocol::ControlMode::kCan || c.motion_mode != mode ||
              c.chassis_switching || !a) {
            last.reset();
            return false;
          }
          bool changed = !last;
          for (std::size_t i = 0; last && i < 4; ++i)
            changed = changed || std::fabs(a->value.angles[i] - (*last)[i]) > deg_to_rad(0.05);
          if (changed) steady_since = s.now();
          last = a->value.angles;
          return s.now() - steady_since >= 300ms && s.now() - began >= 600ms;
        },
        kMoveTimeout);
    if (!ok && !s.interrupted()) fail("the move '" + move + "' got no response within 5 s");
    return ok;
  }

  std::array<double, 4> wheel_angles() const {
    std::array<double, 4> out{};
    const auto& a = s.snapshot()->feedback.steering_angles;
    for (std::size_t i = 0; a && i < 4; ++i)
      out[i] = interpretation::rep103_from_manual_wheel_angle(a->value.angles[i]);
    return out;
  }

  // 1. Steering a few degrees each way at zero speed.
  bool steer() {
    std::string back;
    for (double angle : {kSteerProbe, -kSteerProbe}) {
      const std::string move = "steer " + deg2(std::fabs(angle)) + " deg " +
                               (angle > 0 ? "left" : "right") + " at zero speed";
      s.driver().standstill_probe(StandstillProbe{MotionMode::kAckermann, angle});
      s.run_for(100ms);
      if (!wait_standing(MotionMode::kAckermann, move)) return false;
      MotionCommand c;
      c.steering_angle = interpretation::manual_from_rep103_command_steering(angle);
      const auto wanted =
          wheel_angles_for_command(c, MotionMode::kAckermann, config.controller.geometry, profile);
      const auto got = wheel_angles();
      double worst = 0.0, widest = 0.0;
      for (std::size_t i = 0; i < 4; ++i) {
        worst = std::max(worst, std::fabs(got[i] - wanted[i]));
        widest = std::max(widest, std::fabs(got[i]));
      }
      if (widest < deg_to_rad(0.5)) return fail("the move '" + move + "' got no response (0x271)");
      if (worst > deg_to_rad(1.0)) {
        return fail("the move '" + move + "' came back " + deg2(got[kRightFront]) + "/" +
                    deg2(got[kLeftFront]) + " deg at the front wheels, " +
                    deg2(wanted[kRightFront]) + "/" + deg2(wanted[kLeftFront]) +
                    " deg expected: the identified steering settings do not hold");
      }
      back += (back.empty() ? "" : "; ") + deg2(got[kRightFront]) + "/" + deg2(got[kLeftFront]) +
              " deg (RF/LF)";
    }
    s.driver().standstill_probe(std::nullopt);
    for (S setting : {S::kSteeringUnit111, S::kSteeringSign111, S::kSteeringUnit271,
                      S::kSteeringSign271, S::kSteeringReference}) {
      Row r{setting,
            value(setting),
            true,
            "steer +-5 deg at zero speed",
            back,
            "steering +-5 deg at zero speed came back as commanded (front wheels " + back + ")"};
      for (const Row& x : rows) {
        if (x.setting == setting && !x.evidence.empty()) {
          r.evidence = x.evidence + "; " + r.evidence;
        }
      }
      set_row(r);
    }
    return true;
  }

  // A slow spin under the current settings: the wheels' mean fitted yaw rate.
  std::optional<double> spin_trial() {
    s.command(MotionRequest{BodyTwist{0.0, 0.0, kSpinRate}, MotionMode::kSpin});
    const bool spinning = s.run_until(
        [](const DriverSnapshot& snap) {
          return snap.controller.motion_mode == MotionMode::kSpin &&
                 !snap.controller.chassis_switching &&
                 snap.controller.refusal == MotionRefusal::kNone;
        },
        kMoveTimeout);
    if (!spinning) {
      s.command(MotionRequest{});
      return std::nullopt;
    }
    s.run_for(1s);  // accelerate
    double sum = 0.0;
    int n = 0;
    const Timestamp end = s.now() + 1500ms;
    s.run_until(
        [&](const DriverSnapshot& snap) {
          sum += snap.odometry.twist.wz;
          ++n;
          return s.now() >= end;
        },
        2s);
    s.command(MotionRequest{});
    s.run_for(1s);
    return n > 0 ? sum / n : 0.0;
  }

  void restart_with(const ProtocolProfile& p) {
    DriverConfig c = config;
    c.protocol = ProtocolChoice::kForced;
    c.controller.profile = p;
    s.restart(c);
    profile = p;
  }

  // 2. A slow spin: the spin field and sign.
  bool spin() {
    const std::string move = "spin slowly (" + fixed(kSpinRate, 2) + " rad/s counter-clockwise)";
    std::string tried;
    for (int attempt = 0; attempt < 3; ++attempt) {
      const std::optional<double> wz = spin_trial();
      if (s.interrupted()) return false;
      if (!wz) return fail("the move '" + move + "' got no response (no spin mode, or refused)");
      const std::string back = "the wheels turn the body at " + fixed(*wz, 3) + " rad/s";
      tried +=
          (tried.empty() ? "" : "; ") + spin_reading(profile) + ": " + fixed(*wz, 3) + " rad/s";
      if (*wz > 0.5 * kSpinRate) {
        set_row({S::kSpinField, value(S::kSpinField), true, move, back,
                 "a slow spin turned the way and rate commanded (" + tried + ")"});
        set_row({S::kSpinSign, value(S::kSpinSign), true, move, back,
                 "a slow spin turned counter-clockwise as commanded (" + tried + ")"});
        return true;
      }
      ProtocolProfile next = profile;
      if (*wz < -0.5 * kSpinRate) {
        next.spin_sign = -profile.spin_sign;  // the other way round
      } else if (std::fabs(*wz) < 0.1 * kSpinRate) {
        next.spin_field = profile.spin_field == SpinField::kWheelSpeed ? SpinField::kYawRate
                                                                       : SpinField::kWheelSpeed;
      } else {
        return fail("the move '" + move + "' came back " + back +
                    ": neither the rate nor its "
                    "opposite nor nothing");
      }
      io.out << "  " << move << ": " << back << " under " << spin_reading(profile) << "; trying "
             << spin_reading(next) << "\n";
      restart_with(next);
    }
    return fail("the move '" + move + "' got no response under any spin field and sign (" + tried +
                ")");
  }

  // The roll's samples over 1.5 s: speeds, yaw rate, the pack's current, the drivers' status.
  RollSample measure_roll() {
    RollSample r;
    std::array<bool, protocol::kMotorCount> seen{}, off{};
    const Timestamp end = s.now() + 1500ms;
    s.run_until(
        [&](const DriverSnapshot& snap) {
          const auto& fb = snap.feedback;
          if (fb.motion && fb.wheel_speeds) {
            r.reported += fb.motion->value.speed;
            double m = 0.0;
            for (double v : fb.wheel_speeds->value.speeds)
              m += std::fabs(v) / 4.0;
            r.mean += m;
            r.body += snap.odometry.twist.vx;
            r.wz += snap.odometry.twist.wz;
            ++r.n;
          }
          if (fb.bms[0]) {
            r.current += fb.bms[0]->value.current;
            ++r.current_n;
          }
          for (std::size_t m = 0; m < fb.motor_low_speed.size(); ++m) {
            const auto& d = fb.motor_low_speed[m];
            if (!d) continue;
            seen[m] = true;
            if (d->value.driver_status & protocol::driver_status::kDriverDisabled) off[m] = true;
          }
          return s.now() >= end;
        },
        2s);
    if (r.n > 0) {
      r.reported /= r.n;
      r.mean /= r.n;
      r.body /= r.n;
      r.wz /= r.n;
    }
    if (r.current_n > 0) r.current /= r.current_n;
    for (std::size_t m = 0; m < seen.size(); ++m) {
      r.driver_reports += seen[m] ? 1 : 0;
      r.disabled += off[m] ? 1 : 0;
    }
    return r;
  }

  // 3. A slow roll forward with the wheels steered: 0x221's speed, the BMS current, the drivers.
  bool roll() {
    const std::string move = "roll forward " + fixed(kRollSpeed, 2) + " m/s, steered left";
    s.command(MotionRequest{BodyTwist{kRollSpeed, 0.0, kRollSpeed * kRollCurvature},
                            MotionMode::kAckermann});
    const bool rolling = s.run_until(
        [](const DriverSnapshot& snap) {
          const auto& w = snap.feedback.wheel_speeds;
          if (!w || snap.controller.motion_mode != MotionMode::kAckermann) return false;
          double fastest = 0.0;
          for (double v : w->value.speeds)
            fastest = std::max(fastest, std::fabs(v));
          return fastest > 0.05;
        },
        kMoveTimeout);
    if (!rolling) {
      s.command(MotionRequest{});
      s.run_for(500ms);
      if (s.interrupted()) return false;
      return fail("the move '" + move + "' got no response: no wheel turned (0x281)");
    }
    s.run_for(1s);
    const RollSample r = measure_roll();
    s.command(MotionRequest{});
    s.run_for(1500ms);
    if (r.n == 0) return fail("the move '" + move + "' got no response (0x221/0x281)");
    if (r.wz <= 0.0) {
      return fail("the move '" + move + "' turned the body " + fixed(r.wz, 3) +
                  " rad/s (right): the identified steering sign does not hold");
    }
    judge_feedback_speed(r, move);
    judge_current_sign(r, move);
    judge_driver_bit6(r, move);
    set_row({S::kSteeringSign111, value(S::kSteeringSign111), true, move,
             "the body turns left at " + fixed(r.wz, 3) + " rad/s",
             "steered left at zero speed and rolling: the body turns left"});
    return true;
  }

  void judge_feedback_speed(const RollSample& r, const std::string& move) {
    const std::string speeds = "0x221 " + fixed(r.reported, 3) + " m/s, wheels' mean " +
                               fixed(r.mean, 3) + " m/s, body centre " + fixed(r.body, 3) + " m/s";
    if (std::fabs(r.mean - r.body) < 0.005) {
      set_row({S::kFeedbackSpeed, value(S::kFeedbackSpeed), false, move, speeds,
               "the turn was too gentle to tell the readings apart (" + speeds + ")"});
      return;
    }
    const bool is_mean = std::fabs(r.reported - r.mean) < std::fabs(r.reported - r.body);
    set_row({S::kFeedbackSpeed, is_mean ? "mean_wheel" : "body_centre", true, move, speeds,
             std::string("rolling while turning, 0x221 reports the ") +
                 (is_mean ? "mean of the four wheel speeds" : "body centre's speed") + " (" +
                 speeds + ")"});
  }

  void judge_current_sign(const RollSample& r, const std::string& move) {
    if (r.current_n > 0 && std::fabs(r.current) >= 0.3) {
      set_row(
          {S::kBmsCurrentSign, r.current > 0 ? "discharge_positive" : "charge_positive", true, move,
           "0x361 current " + fixed(r.current, 2) + " A",
           "the pack discharges while the wheels turn, 0x361 reads " + fixed(r.current, 2) + " A"});
    } else {
      set_row({S::kBmsCurrentSign, value(S::kBmsCurrentSign), false, move,
               r.current_n ? "0x361 current " + fixed(r.current, 2) + " A" : "no 0x361",
               "no current large enough to tell (kept the preset's)"});
    }
  }

  void judge_driver_bit6(const RollSample& r, const std::string& move) {
    const bool all_disabled = r.disabled == r.driver_reports;
    if (r.driver_reports == 0 || (!all_disabled && r.disabled != 0)) return;
    const std::string v =
        all_disabled
            ? std::string(to_string(profile.driver_status_bit6 == DriverStatusBit6::kDisabled
                                        ? DriverStatusBit6::kEnabled
                                        : DriverStatusBit6::kDisabled))
            : value(S::kDriverStatusBit6);
    set_row({S::kDriverStatusBit6, v, true, move,
             std::to_string(r.disabled) + " of " + std::to_string(r.driver_reports) +
                 " drivers read as disabled under the identified reading",
             "the drivers work while the wheels turn: bit 6 set means " + v});
  }

  // What the moves confirm without a question of their own, and what they cannot tell: `kept`'s
  // value (the model's, else the identified revision's preset's), `source` saying which.
  void settle_the_rest(const ProtocolProfile& kept, const std::string& source) {
    set_row({S::kTxDlc, std::to_string(profile.tx_dlc), true, "every command", "obeyed",
             "the chassis obeyed commands of DLC " +
                 std::string(profile.tx_dlc == 8 ? "8 (padded)" : "of each layout")});
    set_row({S::kModeNumbering, *get_setting(kept, S::kModeNumbering), true, "0x141 ackermann/spin",
             "0x291 confirmed",
             "the spin and Ackermann switches were answered as numbered (modes above 2 not "
             "tried: " +
                 source + ")"});
    for (const ProfileSetting& p : profile_settings()) {
      if (has_row(p.id)) continue;
      std::string why = "not decidable by these moves: " + source;
      if (p.id == S::kVehicleStatus1IsEstop) {
        why = "needs the e-stop pressed (watch 0x211 byte 0 with `ranger_can decode`): kept";
      }
      set_row({p.id, *get_setting(kept, p.id), false, "-", "-", why});
    }
    // The decided values are the profile from here on.
    for (const Row& r : rows)
      (void)set_setting(profile, r.setting, r.value);
  }

  // The table, in the settings' order; its rows for the file.
  std::vector<CommissionedSetting> print_table() const {
    io.out << "\n"
           << text::format("%-26s %-19s %-8s %s\n", "setting", "value", "",
                           "commanded -> came back");
    std::vector<CommissionedSetting> file_rows;
    for (const ProfileSetting& p : profile_settings()) {
      for (const Row& r : rows) {
        if (r.setting != p.id) continue;
        io.out << text::format("%-26s %-19s %-8s ", p.name.data(), r.value.c_str(),
                               r.decided ? "decided" : "kept")
               << r.commanded << " -> " << r.came_back << "\n";
        file_rows.push_back({std::string(p.name), r.value, r.decided, r.evidence});
      }
    }
    return file_rows;
  }
};

std::string plan_text() {
  return "ranger_can commission: a guided first start, for a chassis on blocks (every wheel off\n"
         "the ground). It will:\n"
         "  1. listen to the chassis without sending anything, then take CAN command mode and\n"
         "     identify its protocol settings (a switch to spin mode and a 6 deg steering probe,\n"
         "     both at zero speed);\n"
         "  2. steer 5 deg left and right at zero speed, reading the wheel angles back (0x271);\n"
         "  3. spin slowly (0.3 rad/s, 1.5 s) reading the wheels back: the spin field and sign;\n"
         "  4. roll forward slowly (0.2 m/s, steered, 2.5 s): 0x221's speed reading, the BMS\n"
         "     current sign, the drivers' status bit;\n"
         "  5. stop, hand CAN control back (0x421 standby), print the table and write --output.\n"
         "The wheels will turn. Put the chassis on blocks and run again with --wheels-lifted.\n";
}

// The driver's configuration for commissioning: --model's geometry, the identification on.
Result<DriverConfig> commission_config(const ParsedArgs& args, const Vehicle& vehicle) {
  DriverConfig config;
  apply_vehicle(vehicle, config);
  config.protocol = ProtocolChoice::kAuto;
  config.identify_revision = protocol_revision(args);
  config.plausibility.enabled = false;  // the moves judge for themselves
  config.controller.release_control_on_shutdown = true;
  if (Status st = config.validate(); !st) return st.error();
  return config;
}

// What the moves cannot tell comes from --model's profile on the identified revision (with
// --set), else from the identified revision's preset; the text says which.
std::pair<ProtocolProfile, std::string> kept_values(const ParsedArgs& args, const Vehicle& vehicle,
                                                    const ProtocolProfile& profile) {
  if (vehicle.model) {
    if (auto m = model_profile(*vehicle.model, profile.revision);
        m && apply_set_options(*m, args)) {
      return {*m, "the " + vehicle.model->display_name + "'s value"};
    }
  }
  return {profile, "the " + profile.revision + " preset's value"};
}

Status write_commissioning_file(const std::string& path, const Commission& c,
                                const std::vector<CommissionedSetting>& rows,
                                const std::string& iface, const Vehicle& vehicle) {
  const std::string text =
      format_commissioning_file(c.profile, rows,
                                {"ranger_can commission " + iface + " --wheels-lifted" +
                                     (vehicle.model ? " --model " + vehicle.model->name : ""),
                                 "load it with the node's parameter commissioning_file (or "
                                 "ranger::load_commissioning_file)",
                                 "identified as " + describe(c.profile)});
  std::ofstream f(path);
  if (!(f << text)) return Error{Errc::kIoError, "cannot write '" + path + "'"};
  return ok_status();
}

int commission_main(const ParsedArgs& args, Io io) {
  const std::string iface = *args.get("IFACE");
  if (!args.has("--wheels-lifted")) {
    io.out << plan_text();
    io.err << "ranger_can commission: not without --wheels-lifted (nothing was sent)\n";
    return 2;
  }
  const Result<Vehicle> vehicle = vehicle_from_args(args);  // --model: a MINI's geometry
  if (!vehicle) return usage_error(commission_command(), io, vehicle.error().message);
  const Result<DriverConfig> config = commission_config(args, *vehicle);
  if (!config) return usage_error(commission_command(), io, config.error().message);
  StopSignals signals;
  auto opened = DriverSession::open(iface, *config);
  if (!opened) {
    io.err << "ranger_can commission: " << opened.error().message << "\n";
    return 1;
  }
  DriverSession& s = **opened;
  Commission c{s, io, {}, *config, {}, {}};
  auto finish = [&](int rc, const std::string& why) {
    s.command(MotionRequest{});
    s.run_for(200ms);
    s.stop();  // the stop, then 0x421 standby
    if (!why.empty()) io.err << "ranger_can commission: " << why << "\n";
    if (rc != 0)
      io.err << "ranger_can commission: stopped, CAN control handed back; no file written\n";
    return rc;
  };

  io.out << "identifying " << iface << " ...\n";
  const bool identified = s.run_until(
      [](const DriverSnapshot& snap) { return snap.identification && snap.identification->done(); },
      config->identification.timeout + 2s);
  if (s.interrupted()) return finish(1, "interrupted");
  const auto snap = s.snapshot();
  if (!identified || !snap->identification || !snap->identification->decided_ok()) {
    return finish(
        1, snap->identification ? snap->identification->message : "the identification did not end");
  }
  const IdentificationStatus id = *snap->identification;
  // The settings in use: the identification's, with what it only kept taken from --model's.
  c.profile = snap->profile;
  if (Status st = apply_set_options(c.profile, args); !st) {
    return finish(2, st.error().message);
  }
  if (c.profile != snap->profile) c.restart_with(c.profile);
  io.out << "identified in " << fixed(seconds(id.elapsed()), 2) << " s"
         << (s.simulated() ? " (simulated)" : "") << ": " << describe(c.profile) << "\n";
  for (const IdentifiedSetting& d : id.decided) {
    c.set_row({*kProtocolSettingNames.parse(d.name), d.value, true,
               d.name.rfind("steering", 0) == 0 ? "probe at standstill" : "-", "see evidence",
               d.evidence});
  }

  io.out << "moving (wheels lifted) ...\n";
  if (!c.steer() || !c.spin() || !c.roll()) {
    return finish(1, s.interrupted() ? std::string("interrupted") : c.failure);
  }
  const auto [kept, source] = kept_values(args, *vehicle, c.profile);
  c.settle_the_rest(kept, source);
  const int rc = finish(0, "");

  const std::vector<CommissionedSetting> file_rows = c.print_table();
  if (const auto out = args.get("--output")) {
    if (Status st = write_commissioning_file(*out, c, file_rows, iface, *vehicle); !st) {
      io.err << "ranger_can commission: " << st.error().message << "\n";
      return 1;
    }
    io.out << "\nwrote " << *out << "\n";
  }
  return rc;
}

}  // namespace

const CommandSpec& commission_command() {
  static const CommandSpec spec{
      "commission",
      "guided first start on blocks: decide every protocol setting, write a file",
      "A guided first start for a chassis on blocks: identifies it (as `identify`), takes CAN\n"
      "control, then makes small, slow, bounded moves, each read back from the feedback (steer 5\n"
      "deg each way at zero speed, spin slowly, roll forward slowly with the wheels steered);\n"
      "decides every protocol setting it can and says which it cannot; prints a table (setting,\n"
      "value, decided or kept, commanded -> came back) and writes --output, a flat YAML file of\n"
      "`setting: value` lines with the evidence as comments, which the node loads with the\n"
      "parameter commissioning_file. It sends the stop and hands CAN control back (0x421\n"
      "standby) at the end, on a failure and on Ctrl-C.\n"
      "\n"
      "Without --wheels-lifted it explains what it would do and stops (nothing is sent).",
      {required_arg("IFACE", "the bus: a SocketCAN interface, sim or sim:VARIANT", "can0")},
      {flag("--wheels-lifted", "the chassis is on blocks, every wheel off the ground: move"),
       option("--output", "FILE", "write the commissioning file there", non_empty()),
       model_option(), protocol_option(), set_option()},
      "Exit status: 0 every move answered (the file written); 1 a move got no response or\n"
      "contradicted the identification (it says which; no file), the chassis was not\n"
      "identified, the bus could not be opened, or interrupted; 2 without --wheels-lifted or on a\n"
      "usage error.",
      commission_main,
  };
  return spec;
}

int run_commission(const Args& args, Io io) {
  return run_command(commission_command(), args, io);
}

}  // namespace ranger::cli
