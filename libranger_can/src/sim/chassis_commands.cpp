#include "ranger_can/sim/chassis_commands.hpp"

#include <cctype>
#include <cmath>
#include <vector>

#include "ranger_can/parse.hpp"
#include "ranger_can/text.hpp"
#include "ranger_can/wire/protocol.hpp"

namespace ranger::sim {

const char* const kChassisCommandHelp =
    "commands (one per line):\n"
    "  remote on|can|off|lost   the remote control takes over | hands back to CAN command mode |\n"
    "                           is switched off (standby) | loses its signal (standby + error)\n"
    "  remote swd top|bottom    motion switch: top = dual Ackermann, and spin while only the\n"
    "                           right stick is pushed; bottom = oblique (user manual 2.3)\n"
    "  remote sticks LEFT RIGHT stick positions, each -1..1 (|v| < 0.05 reads as centred):\n"
    "                           LEFT + forward = + max linear speed at 1; RIGHT + pushed right =\n"
    "                           steer right by the max Ackermann (top) or oblique (bottom)\n"
    "                           angle at 1, or with LEFT centred spin clockwise at the max spin\n"
    "                           wheel speed; the chassis drives them while the remote has control\n"
    "  remote swa top|bottom    lights under the remote: bottom = both off, top = both on\n"
    "  remote swc top|middle|bottom  middle = ultrasonic obstacle avoidance on, else off\n"
    "  estop on|off             press / release the emergency stop\n"
    "  error BIT|NAME [on|off]  raise (default) or drop a 0x211 error bit: 0-31 or its name,\n"
    "                           e.g. 'error 9' = host_communication_lost, 'error 15 off'\n"
    "  clear [CODE]             what 0x441 CODE does (0-16 or 0x00-0x10, default 0)\n"
    "  battery PCT              set the state of charge (below 10: power cut, refuses motion)\n"
    "  silent SEC|on|off        send nothing for SEC seconds / until 'silent off'\n"
    "  garbage N                send N frames a driver must reject (unknown IDs, bad DLC)\n"
    "  stuck on|off             motion-mode switches never complete / complete again\n"
    "  ultrasonic N|all MM      distance of sensor N (1-8) or all sensors, mm (-1..-4: codes)\n"
    "  ultrasonic on|off        obstacle avoidance, as the remote's SWC switch sets it\n"
    "  pose X Y YAW             move the ground truth (m, m, rad)\n"
    "  version TEXT             the firmware version the chassis answers 0x4A1 with (agx_v2)\n"
    "  status                   print the chassis state\n";

namespace {

using Words = std::vector<std::string>;
using protocol::RemoteSwitch;

// The remote's switch positions as the chassis language names them (SWC alone has a middle).
constexpr auto kLeverNames = text::enum_names<RemoteSwitch>({
    {RemoteSwitch::kUp, "top"},
    {RemoteSwitch::kMiddle, "middle"},
    {RemoteSwitch::kDown, "bottom"},
});

Error usage(const std::string& what) {
  return Error{Errc::kInvalidArgument, what};
}

Status need(const Words& w, std::size_t n, const std::string& form) {
  if (w.size() != n) return usage("usage: " + form);
  return ok_status();
}

Result<bool> parse_on_off(const std::string& command, const std::string& word) {
  if (word == "on") return true;
  if (word == "off") return false;
  return usage(command + ": expected 'on' or 'off', got '" + word + "'");
}

// Wraps a chassis call that prints nothing.
ChassisAction act(std::function<void(VirtualChassis&)> f) {
  return ChassisAction([f = std::move(f)](VirtualChassis& c) {
    f(c);
    return std::string();
  });
}

// `command on|off`, calling `set` with the flag.
Result<ChassisAction> on_off_action(const Words& w, void (VirtualChassis::*set)(bool)) {
  if (auto s = need(w, 2, w[0] + " on|off"); !s) return s.error();
  auto on = parse_on_off(w[0], w[1]);
  if (!on) return on.error();
  return act([set, on = *on](VirtualChassis& c) { (c.*set)(on); });
}

// ---- one parser per command ----

Result<ChassisAction> parse_sticks(const Words& w) {
  if (auto s = need(w, 4, "remote sticks LEFT RIGHT (each -1..1)"); !s) return s.error();
  auto left = parse_double_in("remote sticks LEFT", w[2], -1.0, 1.0);
  if (!left) return left.error();
  auto right = parse_double_in("remote sticks RIGHT", w[3], -1.0, 1.0);
  if (!right) return right.error();
  return act([l = *left, r = *right](VirtualChassis& c) { c.set_remote_sticks(l, r); });
}

Result<ChassisAction> parse_lever(const Words& w) {
  const bool three = w[1] == "swc";
  const std::string form = "remote " + w[1] + (three ? " top|middle|bottom" : " top|bottom");
  if (auto s = need(w, 3, form); !s) return s.error();
  const auto position = kLeverNames.parse(w[2]);
  if (!position || (*position == RemoteSwitch::kMiddle && !three)) {
    return usage(form + ": unknown position '" + w[2] + "'");
  }
  void (VirtualChassis::*set)(RemoteSwitch) = w[1] == "swa"   ? &VirtualChassis::set_remote_swa
                                              : w[1] == "swc" ? &VirtualChassis::set_remote_swc
                                                              : &VirtualChassis::set_remote_swd;
  return act([set, p = *position](VirtualChassis& c) { (c.*set)(p); });
}

Result<ChassisAction> parse_remote(const Words& w, std::string_view) {
  if (w.size() >= 2 && w[1] == "sticks") return parse_sticks(w);
  if (w.size() >= 2 && (w[1] == "swa" || w[1] == "swc" || w[1] == "swd")) return parse_lever(w);
  if (auto s = need(w, 2, "remote on|can|off|lost|swa|swc|swd|sticks ..."); !s) return s.error();
  if (w[1] == "on") return act([](VirtualChassis& c) { c.remote_takeover(); });
  if (w[1] == "can") return act([](VirtualChassis& c) { c.remote_hand_back(false); });
  if (w[1] == "off") return act([](VirtualChassis& c) { c.remote_hand_back(true); });
  if (w[1] == "lost") return act([](VirtualChassis& c) { c.remote_signal_lost(); });
  return usage("remote: expected on|can|off|lost|swa|swc|swd|sticks, got '" + w[1] + "'");
}

Result<ChassisAction> parse_estop(const Words& w, std::string_view) {
  return on_off_action(w, &VirtualChassis::set_emergency_stop);
}

Result<ChassisAction> parse_error(const Words& w, std::string_view) {
  if (w.size() != 2 && w.size() != 3) return usage("usage: error BIT|NAME [on|off]");
  if (auto bit = check_error_bit(w[1]); !bit) return bit.error();
  bool on = true;
  if (w.size() == 3) {
    auto v = parse_on_off(w[0], w[2]);
    if (!v) return v.error();
    on = *v;
  }
  // The bit of the name in the chassis's own layout.
  return ChassisAction([name = w[1], on](VirtualChassis& c) -> std::string {
    const auto bit = parse_error_bit(name, c.profile().error_word);
    if (!bit) return bit.error().message;
    c.set_error_bit(*bit, on);
    return "";
  });
}

Result<ChassisAction> parse_clear(const Words& w, std::string_view) {
  if (w.size() > 2) return usage("usage: clear [CODE]");
  std::int64_t code = 0;
  if (w.size() == 2) {
    auto c = parse_integer("clear CODE", w[1], 0, protocol::kMaxErrorClearCode);
    if (!c) return c.error();
    code = *c;
  }
  return act([code](VirtualChassis& c) { c.clear_errors(static_cast<std::uint8_t>(code)); });
}

Result<ChassisAction> parse_battery(const Words& w, std::string_view) {
  if (auto s = need(w, 2, "battery PCT"); !s) return s.error();
  auto pct = parse_double_in("battery PCT", w[1], 0.0, 100.0);
  if (!pct) return pct.error();
  return act([pct = *pct](VirtualChassis& c) { c.set_battery_soc(pct); });
}

Result<ChassisAction> parse_silent(const Words& w, std::string_view) {
  if (auto s = need(w, 2, "silent SEC|on|off"); !s) return s.error();
  if (w[1] == "on" || w[1] == "off") {
    return act([on = w[1] == "on"](VirtualChassis& c) { c.set_silent(on); });
  }
  auto sec = parse_double_in("silent SEC", w[1], 0.0, 86400.0);
  if (!sec) return sec.error();
  return act([d = from_seconds(*sec)](VirtualChassis& c) { c.silence_for(d); });
}

Result<ChassisAction> parse_garbage(const Words& w, std::string_view) {
  if (auto s = need(w, 2, "garbage N"); !s) return s.error();
  auto n = parse_integer("garbage N", w[1], 1, 100000);
  if (!n) return n.error();
  return act([n = static_cast<int>(*n)](VirtualChassis& c) { c.inject_garbage(n); });
}

Result<ChassisAction> parse_stuck(const Words& w, std::string_view) {
  return on_off_action(w, &VirtualChassis::set_mode_switch_stuck);
}

Result<ChassisAction> parse_ultrasonic(const Words& w, std::string_view) {
  if (w.size() == 2) {
    auto on = parse_on_off(w[0], w[1]);
    if (!on) return on.error();
    return act([on = *on](VirtualChassis& c) { c.set_ultrasonic_enabled(on); });
  }
  if (w.size() != 3) return usage("usage: ultrasonic N|all MM  or  ultrasonic on|off");
  auto mm = parse_integer("ultrasonic MM", w[2], -4, 32767);
  if (!mm) return mm.error();
  const auto raw = static_cast<std::int16_t>(*mm);
  if (w[1] == "all") {
    return act([raw](VirtualChassis& c) {
      for (int n = 1; n <= protocol::kUltrasonicCount; ++n)
        c.set_ultrasonic(n, raw);
    });
  }
  auto n = parse_integer("ultrasonic N", w[1], 1, protocol::kUltrasonicCount);
  if (!n) return n.error();
  return act([n = static_cast<int>(*n), raw](VirtualChassis& c) { c.set_ultrasonic(n, raw); });
}

Result<ChassisAction> parse_version(const Words&, std::string_view line) {
  // The rest of the line, as typed (inner spaces kept).
  const std::string text(text::trim(line.substr(line.find("version") + 7)));
  if (text.empty()) return usage("usage: version TEXT");
  if (text.size() > 64) return usage("version: at most 64 characters");
  for (char ch : text) {
    if (static_cast<unsigned char>(ch) < 0x20 || static_cast<unsigned char>(ch) > 0x7E) {
      return usage("version: printable ASCII only");
    }
  }
  return act([text](VirtualChassis& c) { c.set_version(text); });
}

Result<ChassisAction> parse_pose(const Words& w, std::string_view) {
  if (auto s = need(w, 4, "pose X Y YAW"); !s) return s.error();
  auto x = parse_double("pose X", w[1]);
  if (!x) return x.error();
  auto y = parse_double("pose Y", w[2]);
  if (!y) return y.error();
  auto yaw = parse_double("pose YAW", w[3]);
  if (!yaw) return yaw.error();
  return act([p = Pose2D{*x, *y, wrap_angle(*yaw)}](VirtualChassis& c) { c.set_pose(p); });
}

Result<ChassisAction> parse_status(const Words& w, std::string_view) {
  if (auto s = need(w, 1, "status"); !s) return s.error();
  return ChassisAction(
      [](VirtualChassis& c) { return describe_chassis(c.snapshot(), c.profile().error_word); });
}

// The commands, in the order help and messages list them.
struct Command {
  std::string_view word;
  Result<ChassisAction> (*parse)(const Words& w, std::string_view line);
};
const Command kCommands[] = {
    {"remote", parse_remote},   {"estop", parse_estop},     {"error", parse_error},
    {"clear", parse_clear},     {"battery", parse_battery}, {"silent", parse_silent},
    {"garbage", parse_garbage}, {"stuck", parse_stuck},     {"ultrasonic", parse_ultrasonic},
    {"pose", parse_pose},       {"version", parse_version}, {"status", parse_status},
};

}  // namespace

Result<int> parse_error_bit(const std::string& text, ErrorWordLayout layout) {
  const int width = protocol::error_word_bits(layout);
  if (!text.empty() && (std::isdigit(static_cast<unsigned char>(text[0])) != 0)) {
    auto n = parse_integer("error bit", text, 0, width - 1);
    if (!n) return n.error();
    return static_cast<int>(*n);
  }
  if (const protocol::FaultInfo* f = protocol::find_fault(text)) {
    if (f->bit(layout) != protocol::kNoBit) return f->bit(layout);
  }
  std::vector<std::string> names;
  for (const auto& b : protocol::system_error_bits(layout))
    names.emplace_back(b.name);
  return Error{Errc::kInvalidArgument, "unknown error bit '" + text + "' (give 0-" +
                                           std::to_string(width - 1) +
                                           " or one of: " + text::join(names, ", ") + ")"};
}

Result<int> check_error_bit(const std::string& text) {
  auto manual = parse_error_bit(text, ErrorWordLayout::kManual32);
  if (manual) return manual;
  auto agx16 = parse_error_bit(text, ErrorWordLayout::kAgxV2_16);
  return agx16 ? agx16 : manual;
}

std::string describe_chassis(const sim::ChassisSnapshot& s, ErrorWordLayout layout) {
  using text::fixed;
  std::string out;
  out += "control " + std::string(protocol::to_string(s.control_mode));
  out += ", motion " + std::string(protocol::to_string(s.motion_mode));
  if (s.switching)
    out += " (switching to " + std::string(protocol::to_string(s.switch_target)) + ")";
  out += ", vehicle " + std::string(protocol::to_string(s.vehicle_status));
  out += ", speed " + fixed(s.speed, 3) + ", steering " + fixed(rad_to_deg(s.steering), 1) + " deg";
  out += ", twist (" + fixed(s.twist.vx, 3) + ", " + fixed(s.twist.vy, 3) + ", " +
         fixed(s.twist.wz, 3) + ")";
  out += ", pose (" + fixed(s.pose.x, 3) + ", " + fixed(s.pose.y, 3) + ", " +
         fixed(rad_to_deg(s.pose.yaw), 1) + " deg)";
  out += ", battery " + fixed(s.battery.soc, 1) + "% " + fixed(s.battery.voltage, 1) + " V";
  out += ", errors ";
  const auto names = protocol::error_bit_names(s.error_bits, layout);
  out += names.empty() ? "none" : text::join(names, ",");
  out += s.motion_allowed ? ", motion allowed" : ", motion refused: " + s.motion_refused_reason;
  auto position = [](RemoteSwitch p) {
    return std::string(kLeverNames.contains(p) ? kLeverNames.name(p) : "middle");
  };
  out += ", remote SWA " + position(s.remote.swa) + " SWC " + position(s.remote.swc) + " SWD " +
         position(s.remote.swd) + " sticks (" + fixed(s.remote.left, 2) + ", " +
         fixed(s.remote.right, 2) + ")";
  out += ", lights " + describe_lights(s.lights);
  if (s.silent) out += ", SILENT";
  return out;
}

Result<ChassisAction> parse_chassis_command(std::string_view line) {
  const auto w = text::split_words(line);
  if (w.empty() || w[0][0] == '#') {
    return ChassisAction([](VirtualChassis&) { return std::string(); });
  }
  for (const Command& c : kCommands) {
    if (w[0] == c.word) return c.parse(w, line);
  }
  return usage("unknown command '" + w[0] + "' (valid: " + text::join(chassis_command_names()) +
               ")");
}

Result<std::string> apply_chassis_command(std::string_view line, VirtualChassis& chassis) {
  auto action = parse_chassis_command(line);
  if (!action) return action.error();
  return (*action)(chassis);
}

const std::vector<std::string>& chassis_command_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> out;
    for (const Command& c : kCommands)
      out.emplace_back(c.word);
    return out;
  }();
  return names;
}

}  // namespace ranger::sim
