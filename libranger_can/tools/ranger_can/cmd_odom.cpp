// `ranger_can odom [FILE]`: replays a candump log through the driver's odometry (the very
// ranger::Odometry class the ROS node runs) and prints the pose as JSON lines. Frames are decoded
// under the protocol profile of --protocol/--set (cli_profile), so the odometry sees every
// revision in the one convention of codec.hpp.
#include <istream>
#include <iterator>
#include <limits>
#include <optional>
#include <ostream>
#include <sstream>
#include <string>

#include "cli_commands.hpp"
#include "cli_input.hpp"
#include "cli_options.hpp"
#include "cli_profile.hpp"
#include "ranger_can/control/odometry.hpp"
#include "ranger_can/json.hpp"
#include "ranger_can/parse.hpp"
#include "ranger_can/wire/candump_log.hpp"

namespace ranger::cli {

namespace {

struct Options {
  OdometryConfig config;
  ProtocolProfile profile;
  std::optional<std::string> path;  // absent: standard input
  long every = 1;
  bool quiet = false;
};

void append_pose(std::string& out, const OdometryState& s, bool with_twist) {
  JsonWriter w(out);
  w.begin_object();
  w.key("t").seconds(s.stamp);
  w.key("x").number(s.pose.x);
  w.key("y").number(s.pose.y);
  w.key("yaw").number(s.pose.yaw);
  if (with_twist) {
    w.key("vx").number(s.twist.vx);
    w.key("vy").number(s.twist.vy);
    w.key("wz").number(s.twist.wz);
    w.key("source").string(to_string(s.active_source));
  }
  w.end_object();
  out += '\n';
}

int replay(std::istream& in, const Options& opt, Io io) {
  Odometry odom(opt.config);
  std::string out;
  std::size_t timestamped = 0;
  std::uint64_t steps = 0;
  const CandumpReadSummary summary = read_candump(in, "odom", io.err, [&](const LogEntry& e) {
    if (e.has_timestamp) ++timestamped;
    if (e.frame.is_error) return;
    const Result<Message> message = decode(e.frame, opt.profile);
    if (!message || !odom.on_message(*message, e.frame.stamp)) return;
    ++steps;
    if (!opt.quiet && steps % static_cast<std::uint64_t>(opt.every) == 0) {
      out.clear();
      append_pose(out, odom.state(), true);
      io.out << out;
    }
  });
  const bool read_ok = report_candump_end(summary, "odom", io.err);
  if (read_ok && steps > 0) {  // the final pose only when there is one
    out.clear();
    append_pose(out, odom.state(), false);
    io.out << out;
  }
  io.out.flush();
  if (!read_ok) return 1;
  if (steps == 0) {
    io.err << "ranger_can odom: no pose: ";
    if (summary.frames == 0) {
      io.err << describe_no_frames(summary) << "\n";
    } else if (timestamped == 0) {
      io.err << "the log has no timestamps; record it with 'candump -L' (or -ta)\n";
    } else {
      io.err << "none of the " << summary.frames
             << " frame(s) gave an odometry step (that needs two timestamped motion feedback "
                "frames: 0x221, or 0x271 + 0x281, less than 0.5 s apart)\n";
    }
    return 1;
  }
  return 0;
}

int odom_main(const ParsedArgs& args, Io io) {
  Options opt;
  opt.path = args.get("FILE");
  if (const auto source = args.get("--source")) opt.config.source = *parse_odometry_source(*source);
  const Result<Vehicle> vehicle = vehicle_from_args(args);
  if (!vehicle) return usage_error(odom_command(), io, vehicle.error().message);
  opt.config.geometry = vehicle->geometry;  // the model's (a RANGER without --model)
  opt.config.geometry.wheelbase = args.number("--wheelbase", opt.config.geometry.wheelbase);
  opt.config.geometry.track = args.number("--track", opt.config.geometry.track);
  opt.every = static_cast<long>(args.integer("--every", 1));
  opt.quiet = args.has("--quiet");
  opt.profile = vehicle->profile;
  opt.config.profile = vehicle->profile;  // the 0x221 readings of the odometry's fallback
  if (Status st = opt.config.validate(); !st) {
    return usage_error(odom_command(), io, st.error().message);
  }
  if (protocol_is_auto(args)) {
    // Two passes: the whole log identifies the settings, then the odometry replays it.
    return with_input(opt.path, "odom", io, [&](std::istream& in) {
      std::string text;
      if (!slurp(in, text)) {
        io.err << "ranger_can odom: read error\n";
        return 1;
      }
      const Result<ProtocolProfile> identified =
          profile_for_frames(args, frames_of_text(text), opt.config.geometry);
      if (!identified) return usage_error(odom_command(), io, identified.error().message);
      Options o = opt;
      o.profile = *identified;
      o.config.profile = *identified;
      std::istringstream again(text);
      return replay(again, o, io);
    });
  }
  return with_input(opt.path, "odom", io, [&](std::istream& in) { return replay(in, opt, io); });
}

}  // namespace

const CommandSpec& odom_command() {
  const OdometryConfig defaults;
  static const CommandSpec spec{
      "odom",
      "replay a candump log through the odometry, print poses (JSON lines)",
      "Replays a candump log through the driver's odometry (the very ranger::Odometry class the\n"
      "ROS node runs) and prints the pose in the odom frame (REP-103/105: m, rad, x forward, y\n"
      "left, yaw counter-clockwise) as JSON lines, one per integrated step:\n"
      "  "
      "{\"t\":s,\"x\":m,\"y\":m,\"yaw\":rad,\"vx\":m/s,\"vy\":m/s,\"wz\":rad/"
      "s,\"source\":\"wheels\"}\n"
      "and, as the last line, the final pose: {\"t\":s,\"x\":m,\"y\":m,\"yaw\":rad}.\n"
      "\n"
      "The log needs timestamps (candump -L, or candump -ta): odometry integrates over the "
      "frames'\n"
      "own times. Steps longer than 0.5 s or going backwards are not integrated. Frames are\n"
      "decoded under the protocol profile of --model, --protocol and --set (units, signs,\n"
      "lengths; --protocol auto, the default, identifies it from the whole log first), and the\n"
      "geometry is the model's unless --wheelbase/--track say otherwise.\n"
      "Malformed lines are reported on stderr as 'line N: reason' (the first 20, then a count)\n"
      "and skipped; frames with extended (29-bit) IDs (other devices) are counted and skipped.",
      {optional_arg("FILE", "the candump log; standard input when absent or '-'", any_text())},
      {
          option("--source", "wheels|motion",
                 "wheels (default): least-squares fit to the per-wheel angles (0x271) and speeds "
                 "(0x281), falling back to 0x221 while those are missing; motion: 0x221 speed and "
                 "steering with the 0x291 motion mode only",
                 parameter_rule("odometry_source")),
          option("--wheelbase", "M",
                 "front to rear axle, m (default: the model's, else " +
                     number_text(defaults.geometry.wheelbase) + ")",
                 parameter_rule("wheelbase")),
          option("--track", "M",
                 "left to right wheel centres, m (default: the model's, else " +
                     number_text(defaults.geometry.track) + ")",
                 parameter_rule("track")),
          option("--every", "N", "print every Nth step only (default 1)",
                 integer_in(1, std::numeric_limits<std::int32_t>::max())),
          flag("--quiet", "print the final pose only"),
          model_option(),
          protocol_option(),
          set_option(),
      },
      "Exit status: 0 when the log gave at least one odometry step; 1 when it gave none (empty,\n"
      "no timestamps, no motion feedback: the reason is on stderr, and no pose is printed) or\n"
      "could not be read; 2 on a usage error.",
      odom_main,
  };
  return spec;
}

int run_odom(const Args& args, Io io) {
  return run_command(odom_command(), args, io);
}

}  // namespace ranger::cli
