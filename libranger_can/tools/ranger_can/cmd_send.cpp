// `ranger_can send IFACE COMMAND [ARGS...]`: one frame to a chassis, for bench tests. Every
// command goes through the codec (byte-exact encoding, saturation) and every angle through
// interpretation.hpp, exactly like the driver. The commands are a table (kCommands): the help,
// the summary and the parser all read it.
#include <cmath>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "cli_bus.hpp"
#include "cli_commands.hpp"
#include "cli_frame_format.hpp"
#include "cli_options.hpp"
#include "cli_profile.hpp"
#include "ranger_can/clock.hpp"
#include "ranger_can/parse.hpp"
#include "ranger_can/text.hpp"
#include "ranger_can/wire/candump_log.hpp"
#include "ranger_can/wire/codec.hpp"
#include "ranger_can/wire/interpretation.hpp"
#include "ranger_can/wire/protocol.hpp"

namespace ranger::cli {

namespace {

using Words = std::vector<std::string>;  // the command's arguments (after its name)

Error bad(const std::string& what) {
  return Error{Errc::kInvalidArgument, what};
}

// The modes `send mode` takes: every motion mode but park, which has a command of its own.
std::vector<std::string> mode_names() {
  std::vector<std::string> names;
  for (const auto& [mode, name] : protocol::kMotionModeNames)
    if (mode != protocol::MotionMode::kPark) names.emplace_back(name);
  return names;
}

Result<Message> parse_mode(const Words& w) {
  const auto mode = protocol::kMotionModeNames.parse(w[0]);
  if (mode && *mode != protocol::MotionMode::kPark) return Message{MotionModeCommand{*mode}};
  return bad("mode: unknown motion mode '" + w[0] + "' (" + text::join(mode_names()) + ")");
}

Result<Message> parse_park(const Words& w) {
  // Park off: back to dual Ackermann, the mode every chassis starts in.
  if (w[0] == "on") return Message{MotionModeCommand{protocol::MotionMode::kPark}};
  if (w[0] == "off") return Message{MotionModeCommand{protocol::MotionMode::kAckermann}};
  return bad("park: expected 'on' or 'off', got '" + w[0] + "'");
}

// One light: off | on | breathing | custom:PCT (brightness 0..100).
Status parse_light(const std::string& what, const std::string& word, protocol::LightMode& mode,
                   std::uint8_t& brightness) {
  brightness = 0;
  const auto named = protocol::kLightModeNames.parse(word);  // custom takes its brightness
  if (named && *named != protocol::LightMode::kCustom) {
    mode = *named;
  } else if (word.rfind("custom:", 0) == 0) {
    auto pct = parse_integer("lights " + what + " custom:PCT", word.substr(7), 0, 100);
    if (!pct) return pct.error();
    mode = protocol::LightMode::kCustom;
    brightness = static_cast<std::uint8_t>(*pct);
  } else {
    return bad("lights " + what + ": expected off, on, breathing or custom:PCT, got '" + word +
               "'");
  }
  return ok_status();
}

Result<Message> parse_lights(const Words& w) {
  LightCommand c;
  c.enable = true;
  if (w.size() == 1 && w[0] == "release") {
    c.enable = false;  // the chassis's own lights again
    return Message{c};
  }
  if (w.size() != 2) return bad("usage: send IFACE lights FRONT REAR | release");
  if (Status st = parse_light("FRONT", w[0], c.front_mode, c.front_custom); !st) return st.error();
  if (Status st = parse_light("REAR", w[1], c.rear_mode, c.rear_custom); !st) return st.error();
  return Message{c};
}

Result<Message> parse_version(const Words&) {
  return Message{VersionRequest{}};
}

Result<Message> parse_control(const Words& w) {
  const auto mode = protocol::kControlModeNames.parse(w[0]);
  if (mode == protocol::ControlMode::kCan || mode == protocol::ControlMode::kStandby) {
    return Message{ControlModeCommand{*mode}};
  }
  return bad("control: unknown control mode '" + w[0] + "' (can or standby)");
}

Result<Message> parse_clear_errors(const Words& w) {
  std::int64_t code = 0;
  if (!w.empty()) {
    auto v = parse_integer("clear-errors CODE", w[0], 0, protocol::kMaxErrorClearCode);
    if (!v) return v.error();
    code = *v;
  }
  return Message{ErrorClearCommand{static_cast<std::uint8_t>(code)}};
}

Result<Message> parse_ultrasonic(const Words& w) {
  if (w[0] == "on") return Message{UltrasonicSettingCommand{true}};
  if (w[0] == "off") return Message{UltrasonicSettingCommand{false}};
  return bad("ultrasonic: expected 'on' or 'off', got '" + w[0] + "'");
}

Result<Message> parse_motion(const Words& w) {
  auto v = parse_double_in("motion V", w[0], -interpretation::kMaxLinearSpeedMps,
                           interpretation::kMaxLinearSpeedMps);
  if (!v) return v.error();
  // Degrees: the user's unit, not the wire's.
  auto steer = parse_double_in("motion STEER_DEG", w[1], -rad_to_deg(kMaxObliqueSteeringRad),
                               rad_to_deg(kMaxObliqueSteeringRad));
  if (!steer) return steer.error();
  auto spin = parse_double_in("motion SPIN", w[2], -kMaxSpinSpeedMps, kMaxSpinSpeedMps);
  if (!spin) return spin.error();
  MotionCommand m;
  m.linear_speed = *v;
  m.steering_angle = interpretation::manual_from_rep103_command_steering(deg_to_rad(*steer));
  m.spin_speed = *spin;
  return Message{m};
}

struct SendCommand {
  std::string name;
  std::string args;  // as the help shows them
  std::size_t min_args, max_args;
  std::string help;
  Result<Message> (*parse)(const Words&);
};

const std::vector<SendCommand>& send_commands() {
  static const std::vector<SendCommand> commands = {
      {"mode", text::join(mode_names(), "|"), 1, 1,
       "0x141 motion mode (side_slip: MINI V1 and agx_v2 numbering only)", parse_mode},
      {"park", "on|off", 1, 1,
       "0x141 park (on) or dual Ackermann (off); agx_v2 numbering only (the manual and the MINI "
       "V1 have no park)",
       parse_park},
      {"lights", "FRONT REAR|release", 1, 2,
       "0x121 lights (agx_v2): FRONT and REAR each off, on, breathing or custom:PCT (brightness "
       "0-100); release hands the lights back to the chassis",
       parse_lights},
      {"version", "", 0, 0, "0x4A1 firmware version request (agx_v2; the answer is not waited for)",
       parse_version},
      {"control", "can|standby", 1, 1, "0x421 control mode (CAN command mode / standby)",
       parse_control},
      {"clear-errors", "[CODE]", 0, 1,
       "0x441 clear errors: CODE 0-16 or 0x00-0x10 (default 0 = all non-critical faults; 1-8 "
       "motor driver n communication, 9 battery under-voltage, 10 remote signal loss, 11-14 "
       "steering calibration of motor 5-8, 15 over-current, 16 over-temperature)",
       parse_clear_errors},
      {"ultrasonic", "on|off", 1, 1, "0x451 ultrasonic obstacle avoidance", parse_ultrasonic},
      {"motion", "V STEER_DEG SPIN", 3, 3,
       "0x111 once: V linear speed m/s (forward +, |V| <= " +
           number_text(interpretation::kMaxLinearSpeedMps) +
           "), STEER_DEG steering in degrees, REP-103 sign: positive = LEFT (|STEER_DEG| <= " +
           number_text(rad_to_deg(kMaxObliqueSteeringRad)) +
           "; sent with the manual's sign), SPIN wheel speed m/s, counter-clockwise + (|SPIN| <= " +
           number_text(kMaxSpinSpeedMps) +
           "). The chassis stops again 500 ms later unless repeated.",
       parse_motion},
  };
  return commands;
}

std::string command_names() {
  std::string names;
  for (const auto& c : send_commands())
    names += (names.empty() ? "" : ", ") + c.name;
  return names;
}

Result<Message> parse_command(const std::string& name, const Words& args) {
  for (const auto& c : send_commands()) {
    if (c.name != name) continue;
    if (args.size() < c.min_args || args.size() > c.max_args) {
      return bad("usage: send IFACE " + c.name + " " + c.args);
    }
    return c.parse(args);
  }
  return bad("unknown command '" + name + "' (" + command_names() + ")");
}

// The 0x111 of `send motion` in the vehicle's protocol: the spin (a wheel speed, counter-clockwise
// positive) goes out in the profile's spin field with its sign, a yaw rate through the geometry.
void apply_spin_field(Message& message, const Vehicle& vehicle) {
  auto* m = std::get_if<MotionCommand>(&message);
  if (m == nullptr) return;
  const double ccw = m->spin_speed;
  m->spin_speed = 0.0;
  if (vehicle.profile.spin_field == SpinField::kYawRate) {
    m->yaw_rate = interpretation::spin_wire_from_ccw(
        interpretation::spin_yaw_rate_from_wheel_speed(ccw, vehicle.geometry.wheelbase,
                                                       vehicle.geometry.track),
        vehicle.profile);
  } else {
    m->spin_speed = interpretation::spin_wire_from_ccw(ccw, vehicle.profile);
  }
}

int send_main(const ParsedArgs& args, Io io) {
  const std::string iface = *args.get("IFACE");
  const Result<Vehicle> vehicle = vehicle_from_args(args);
  if (!vehicle) return usage_error(send_command(), io, vehicle.error().message);
  auto message = parse_command(*args.get("COMMAND"), args.all("ARGS"));
  if (!message) return usage_error(send_command(), io, message.error().message);
  apply_spin_field(*message, *vehicle);
  if (const auto* m = std::get_if<MotionModeCommand>(&*message);
      m && !protocol::motion_mode_to_wire(m->mode, vehicle->profile.mode_numbering)) {
    io.err << "ranger_can send: " << protocol::to_string(m->mode) << ": unsupported by protocol "
           << vehicle->profile.revision << " (its motion-mode numbering has no "
           << protocol::to_string(m->mode) << " mode)\n";
    return 1;
  }
  auto frame = encode(*message, vehicle->profile);
  if (!frame) {
    io.err << "ranger_can send: " << frame.error().message << "\n";
    return 1;
  }
  frame->stamp = SystemClock().now();  // for the printed candump line
  std::string text;
  append_message_text(text, *message);
  if (args.has("--dry-run")) {
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

std::string commands_help() {
  std::vector<HelpRow> rows;
  for (const auto& c : send_commands())
    rows.push_back({"  " + c.name + " " + c.args, c.help});
  return format_rows("commands", rows);
}

}  // namespace

const CommandSpec& send_command() {
  static const CommandSpec spec{
      "send",
      "send one command: " + command_names(),
      "Sends one command frame to the chassis on IFACE and prints it in candump -L format,\n"
      "encoded under the protocol profile of --model, --protocol and --set (units, signs, the\n"
      "spin field, the mode numbering, the frame length).",
      {required_arg("IFACE", "the CAN interface of the chassis", "can0"),
       required_arg("COMMAND", "one of the commands below: " + command_names(), "control"),
       rest_args("ARGS", "the command's arguments (negative numbers need no '--')")},
      {flag("--dry-run", "print the frame, do not open IFACE").alias('n'), model_option(),
       protocol_option(false), set_option()},
      commands_help(),
      send_main,
  };
  return spec;
}

int run_send(const Args& args, Io io) {
  return run_command(send_command(), args, io);
}

}  // namespace ranger::cli
