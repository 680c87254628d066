// `ranger_can send IFACE COMMAND ...`: one frame to a chassis, for bench tests. Every command
// goes through the codec (byte-exact encoding, saturation) and every angle through
// interpretation.hpp, exactly like the driver.
#include <cctype>
#include <cmath>
#include <optional>
#include <ostream>
#include <string>

#include "cli_args.hpp"
#include "cli_bus.hpp"
#include "cli_commands.hpp"
#include "cli_frame_format.hpp"
#include "ranger_can/wire/candump_log.hpp"
#include "ranger_can/clock.hpp"
#include "ranger_can/wire/codec.hpp"
#include "ranger_can/wire/interpretation.hpp"

namespace ranger::cli {

namespace {

constexpr const char* kUsage =
    "usage: ranger_can send IFACE COMMAND [ARGS] [--dry-run]\n"
    "\n"
    "Sends one command frame to the chassis on IFACE and prints it in candump -L format.\n"
    "\n"
    "commands:\n"
    "  mode ackermann|oblique|spin      0x141 motion mode\n"
    "  control can|standby              0x421 control mode (CAN command mode / standby)\n"
    "  clear-errors [CODE]              0x441 clear errors: CODE 0-16 or 0x00-0x10 (default 0 =\n"
    "                                   all non-critical faults; 1-8 motor driver n "
    "communication,\n"
    "                                   9 battery under-voltage, 10 remote signal loss, 11-14\n"
    "                                   steering calibration of motor 5-8, 15 over-current, 16\n"
    "                                   over-temperature)\n"
    "  ultrasonic on|off                0x451 ultrasonic obstacle avoidance\n"
    "  motion V STEER_DEG SPIN          0x111 once: V linear speed m/s (forward +, |V| <= 2.6),\n"
    "                                   STEER_DEG steering in degrees, REP-103 sign: positive =\n"
    "                                   LEFT (|STEER_DEG| <= 90; sent with the manual's sign),\n"
    "                                   SPIN wheel speed m/s, counter-clockwise + (|SPIN| <= 1).\n"
    "                                   The chassis stops again 500 ms later unless repeated.\n"
    "\n"
    "options:\n"
    "  -n, --dry-run   print the frame, do not open IFACE\n"
    "  -h, --help      this text\n";

Error bad(const std::string& what) {
  return Error{Errc::kInvalidArgument, what};
}

Result<Message> parse_command(const std::vector<std::string>& w) {
  if (w.empty()) return bad("missing COMMAND (mode, control, clear-errors, ultrasonic, motion)");
  const std::string& c = w[0];
  auto expect_args = [&](std::size_t min, std::size_t max, const char* form) -> Status {
    if (w.size() - 1 < min || w.size() - 1 > max)
      return bad("usage: send IFACE " + std::string(form));
    return ok_status();
  };
  if (c == "mode") {
    if (auto s = expect_args(1, 1, "mode ackermann|oblique|spin"); !s) return s.error();
    if (w[1] == "ackermann") return Message{MotionModeCommand{protocol::MotionMode::kAckermann}};
    if (w[1] == "oblique") return Message{MotionModeCommand{protocol::MotionMode::kOblique}};
    if (w[1] == "spin") return Message{MotionModeCommand{protocol::MotionMode::kSpin}};
    return bad("mode: unknown motion mode '" + w[1] + "' (ackermann, oblique or spin)");
  }
  if (c == "control") {
    if (auto s = expect_args(1, 1, "control can|standby"); !s) return s.error();
    if (w[1] == "can") return Message{ControlModeCommand{protocol::ControlMode::kCan}};
    if (w[1] == "standby") return Message{ControlModeCommand{protocol::ControlMode::kStandby}};
    return bad("control: unknown control mode '" + w[1] + "' (can or standby)");
  }
  if (c == "clear-errors") {
    if (auto s = expect_args(0, 1, "clear-errors [CODE]"); !s) return s.error();
    std::int64_t code = 0;
    if (w.size() == 2) {
      auto v = parse_integer("clear-errors CODE", w[1], 0, protocol::kMaxErrorClearCode);
      if (!v) return v.error();
      code = *v;
    }
    return Message{ErrorClearCommand{static_cast<std::uint8_t>(code)}};
  }
  if (c == "ultrasonic") {
    if (auto s = expect_args(1, 1, "ultrasonic on|off"); !s) return s.error();
    if (w[1] == "on") return Message{UltrasonicSettingCommand{true}};
    if (w[1] == "off") return Message{UltrasonicSettingCommand{false}};
    return bad("ultrasonic: expected 'on' or 'off', got '" + w[1] + "'");
  }
  if (c == "motion") {
    if (auto s = expect_args(3, 3, "motion V STEER_DEG SPIN"); !s) return s.error();
    auto v = parse_double_in("motion V", w[1], -interpretation::kMaxLinearSpeedMps,
                             interpretation::kMaxLinearSpeedMps);
    if (!v) return v.error();
    constexpr double kRadPerDeg = M_PI / 180.0;  // the user's unit, not the wire's
    auto steer = parse_double_in("motion STEER_DEG", w[2], -kMaxObliqueSteeringRad / kRadPerDeg,
                                 kMaxObliqueSteeringRad / kRadPerDeg);
    if (!steer) return steer.error();
    auto spin = parse_double_in("motion SPIN", w[3], -kMaxSpinSpeedMps, kMaxSpinSpeedMps);
    if (!spin) return spin.error();
    MotionCommand m;
    m.linear_speed = *v;
    m.steering_angle = interpretation::manual_from_rep103_command_steering(*steer * kRadPerDeg);
    m.spin_speed = *spin;
    return Message{m};
  }
  return bad("unknown command '" + c + "' (mode, control, clear-errors, ultrasonic, motion)");
}

}  // namespace

int run_send(const Args& args, Io io) {
  bool dry_run = false;
  std::vector<std::string> words;
  for (const auto& a : args) {
    if (a == "-h" || a == "--help") {
      io.out << kUsage;
      return 0;
    }
    if (a == "-n" || a == "--dry-run") {
      dry_run = true;
    } else if (a.size() > 1 && a[0] == '-' &&
               !(std::isdigit(static_cast<unsigned char>(a[1])) || a[1] == '.')) {
      io.err << "ranger_can send: unknown option '" << a << "'\n";
      return 2;
    } else {
      words.push_back(a);
    }
  }
  auto usage_fail = [&](const std::string& msg) {
    io.err << "ranger_can send: " << msg << "\n"
           << "usage: ranger_can send IFACE COMMAND [ARGS]   ('ranger_can send --help' for more)\n";
    return 2;
  };
  if (words.empty()) return usage_fail("missing IFACE (e.g. can0)");
  const std::string iface = words[0];
  auto message = parse_command(std::vector<std::string>(words.begin() + 1, words.end()));
  if (!message) return usage_fail(message.error().message);
  auto frame = encode(*message);
  if (!frame) {
    io.err << "ranger_can send: " << frame.error().message << "\n";
    return 1;
  }
  frame->stamp = SystemClock().now();  // for the printed candump line
  std::string text;
  append_message_text(text, *message);
  if (dry_run) {
    io.out << format_candump_line(*frame, iface) << "   " << text << "  (dry run, not sent)\n";
    return 0;
  }
  auto bus = open_interface(iface);
  if (!bus) {
    io.err << "ranger_can send: " << bus.error().message << "\n";
    return 1;
  }
  if (auto s = (*bus)->send(*frame); !s) {
    io.err << "ranger_can send: sending on " << iface << " failed: " << s.error().message << "\n";
    return 1;
  }
  io.out << format_candump_line(*frame, iface) << "   " << text << "\n";
  return 0;
}

}  // namespace ranger::cli
