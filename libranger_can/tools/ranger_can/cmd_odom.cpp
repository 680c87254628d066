// `ranger_can odom [FILE]`: replays a candump log through the driver's odometry (the very
// ranger::Odometry class the ROS node runs) and prints the pose as JSON lines.
#include <istream>
#include <limits>
#include <optional>
#include <ostream>
#include <string>

#include "cli_args.hpp"
#include "cli_commands.hpp"
#include "cli_input.hpp"
#include "cli_json.hpp"
#include "ranger_can/wire/candump_log.hpp"
#include "ranger_can/control/odometry.hpp"

namespace ranger::cli {

namespace {

constexpr const char* kUsage =
    "usage: ranger_can odom [FILE|-] [--source wheels|motion] [--wheelbase M] [--track M]\n"
    "                       [--every N] [--quiet]\n"
    "\n"
    "Replays a candump log (FILE, or standard input when absent or '-') through the driver's\n"
    "odometry and prints the pose in the odom frame (REP-103/105: m, rad, x forward, y left,\n"
    "yaw counter-clockwise) as JSON lines, one per integrated step:\n"
    "  "
    "{\"t\":s,\"x\":m,\"y\":m,\"yaw\":rad,\"vx\":m/s,\"vy\":m/s,\"wz\":rad/"
    "s,\"source\":\"wheels\"}\n"
    "and, as the last line, the final pose: {\"t\":s,\"x\":m,\"y\":m,\"yaw\":rad}.\n"
    "\n"
    "The log needs timestamps (candump -L, or candump -ta): odometry integrates over the frames'\n"
    "own times. Steps longer than 0.5 s or going backwards are not integrated. Malformed lines "
    "are\n"
    "reported on stderr as 'line N: reason' and skipped.\n"
    "\n"
    "options:\n"
    "  --source S     wheels (default): least-squares fit to the per-wheel angles (0x271) and\n"
    "                 speeds (0x281), falling back to 0x221 while those are missing;\n"
    "                 motion: 0x221 speed and steering with the 0x291 motion mode only\n"
    "  --wheelbase M  front to rear axle, m (default 0.890)\n"
    "  --track M      left to right wheel centres, m (default 0.560)\n"
    "  --every N      print every Nth step only (default 1)\n"
    "  --quiet        print the final pose only\n"
    "  -h, --help     this text\n"
    "\n"
    "Exit status: 0 success; 1 the input could not be read or had no timestamped frames; 2 "
    "usage.\n";

struct Options {
  OdometryConfig config;
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
    if (!odom.on_frame(e.frame)) return;
    ++steps;
    if (!opt.quiet && steps % static_cast<std::uint64_t>(opt.every) == 0) {
      out.clear();
      append_pose(out, odom.state(), true);
      io.out << out;
    }
  });
  out.clear();
  append_pose(out, odom.state(), false);
  io.out << out;
  io.out.flush();
  if (!report_candump_end(summary, "odom", io.err)) return 1;
  if (timestamped == 0 && summary.lines > 0) {
    io.err << "ranger_can odom: the log has no timestamps; record it with 'candump -L' (or -ta)\n";
    return 1;
  }
  return 0;
}

}  // namespace

int run_odom(const Args& args, Io io) {
  Options opt;
  auto usage_error = [&](const std::string& message) {
    io.err << "ranger_can odom: " << message << "\n\n" << kUsage;
    return 2;
  };
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "-h" || a == "--help") {
      io.out << kUsage;
      return 0;
    }
    const bool takes_value =
        a == "--source" || a == "--wheelbase" || a == "--track" || a == "--every";
    if (takes_value && i + 1 >= args.size()) return usage_error(a + " needs a value");
    if (a == "--source") {
      const Result<OdometrySource> s = parse_odometry_source(args[++i]);
      if (!s) return usage_error("--source: " + s.error().message);
      opt.config.source = *s;
    } else if (a == "--wheelbase" || a == "--track") {
      const Result<double> v = parse_double_in(a, args[++i], 1e-3, 10.0);
      if (!v) return usage_error(v.error().message);
      (a == "--wheelbase" ? opt.config.geometry.wheelbase : opt.config.geometry.track) = *v;
    } else if (a == "--every") {
      const Result<std::int64_t> n =
          parse_integer(a, args[++i], 1, std::numeric_limits<std::int32_t>::max());
      if (!n) return usage_error(n.error().message);
      opt.every = static_cast<long>(*n);
    } else if (a == "--quiet") {
      opt.quiet = true;
    } else if (a.size() > 1 && a[0] == '-') {
      return usage_error("unknown option '" + a + "'");
    } else if (opt.path) {
      return usage_error("more than one input file ('" + *opt.path + "', '" + a + "')");
    } else {
      opt.path = a;
    }
  }
  if (Status st = opt.config.validate(); !st) return usage_error(st.error().message);

  return with_input(opt.path, "odom", io, [&](std::istream& in) { return replay(in, opt, io); });
}

}  // namespace ranger::cli
