// `ranger_can monitor IFACE`: a live view of a RANGER chassis, refreshed about 5 times a second;
// what to reach for first when something does not move. The view itself is ChassisMonitor
// (cli_monitor_view.hpp); this file opens the bus, keeps time and decides when to draw.
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <iostream>
#include <optional>
#include <string>

#include "cli_args.hpp"
#include "cli_bus.hpp"
#include "cli_commands.hpp"
#include "cli_monitor_view.hpp"
#include "cli_signals.hpp"
#include "ranger_can/clock.hpp"

namespace ranger::cli {

namespace {

using namespace std::chrono_literals;

constexpr const char* kUsage =
    "usage: ranger_can monitor IFACE [options]\n"
    "\n"
    "Shows what a RANGER chassis on IFACE (e.g. can0, vcan0) reports, refreshed live until\n"
    "Ctrl-C: control and motion mode, speed and steering (with 'left'/'right' spelled out),\n"
    "per-wheel angle/speed and motor rpm/current/temperature, battery and BMS alarms, 0x211\n"
    "errors by name, ultrasonic distances, the commands the host sends (0x111 age and rate),\n"
    "frame rates per ID against the manual's periods, and the bus state.\n"
    "\n"
    "options:\n"
    "  --once         listen for --window seconds, print one view, exit (0 if the chassis was\n"
    "                 heard, 1 if not)\n"
    "  --count N      print N views, then exit\n"
    "  --rate HZ      views per second (default 5)\n"
    "  --window SEC   frame-rate window and --once listening time (default 1)\n"
    "  --json         one JSON object per view instead of text\n"
    "  --no-color     no ANSI colours (default: colours on a terminal unless NO_COLOR is set)\n"
    "  --no-clear     do not clear the screen between views (default: clear on a terminal)\n"
    "  -h, --help     this text\n";

struct MonitorOptions {
  std::string iface;
  bool once = false;
  std::optional<long> count;
  double rate = 5.0;
  double window = 1.0;
  bool json = false;
  bool no_color = false;
  bool no_clear = false;
};

Result<MonitorOptions> parse_options(const Args& args) {
  MonitorOptions o;
  std::optional<std::string> iface;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    auto value = [&]() -> Result<std::string> {
      if (i + 1 >= args.size()) return Error{Errc::kInvalidArgument, a + " needs a value"};
      return args[++i];
    };
    if (a == "--once") {
      o.once = true;
    } else if (a == "--json") {
      o.json = true;
    } else if (a == "--no-color") {
      o.no_color = true;
    } else if (a == "--no-clear") {
      o.no_clear = true;
    } else if (a == "--count") {
      auto v = value();
      if (!v) return v.error();
      auto n = parse_integer(a, *v, 1, 1000000000);
      if (!n) return n.error();
      o.count = static_cast<long>(*n);
    } else if (a == "--rate" || a == "--window") {
      auto v = value();
      if (!v) return v.error();
      auto d = parse_double_in(a, *v, a == "--rate" ? 0.1 : 0.05, a == "--rate" ? 100.0 : 3600.0);
      if (!d) return d.error();
      (a == "--rate" ? o.rate : o.window) = *d;
    } else if (a.size() > 1 && a[0] == '-') {
      return Error{Errc::kInvalidArgument, "unknown option '" + a + "'"};
    } else if (iface) {
      return Error{Errc::kInvalidArgument, "unexpected argument '" + a + "'"};
    } else {
      iface = a;
    }
  }
  if (!iface) return Error{Errc::kInvalidArgument, "missing IFACE (e.g. can0)"};
  o.iface = *iface;
  return o;
}

std::chrono::nanoseconds seconds(double s) {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::duration<double>(s));
}

}  // namespace

int run_monitor(const Args& args, Io io) {
  for (const auto& a : args) {
    if (a == "-h" || a == "--help") {
      io.out << kUsage;
      return 0;
    }
  }
  auto parsed = parse_options(args);
  if (!parsed) {
    io.err << "ranger_can monitor: " << parsed.error().message << "\n"
           << "usage: ranger_can monitor IFACE [--once] [--count N] [--rate HZ] [--json]   "
              "('ranger_can monitor --help' for more)\n";
    return 2;
  }
  const MonitorOptions& o = *parsed;

  auto bus = open_interface(o.iface);
  if (!bus) {
    io.err << "ranger_can monitor: " << bus.error().message << "\n";
    return 1;
  }

  const bool terminal = &io.out == &std::cout && ::isatty(STDOUT_FILENO) != 0;
  const bool color = terminal && !o.no_color && !o.json && std::getenv("NO_COLOR") == nullptr;
  const bool clear = terminal && !o.no_clear && !o.once && !o.json;

  StopSignals signals;
  SteadyClock clock;
  ChassisMonitor monitor(seconds(o.window));
  const Timestamp start = clock.now();
  const auto period = seconds(1.0 / o.rate);
  Timestamp next_view = start + (o.once ? seconds(o.window) : period);
  long views = 0;

  while (!StopSignals::requested()) {
    const Timestamp now = clock.now();
    if (now >= next_view) {
      const BusStatus status = (*bus)->status();
      std::string view = o.json ? monitor.render_json(o.iface, status, now) + "\n"
                                : monitor.render_text(o.iface, status, now, color);
      if (clear) {
        view = "\x1b[H\x1b[2J" + view;
      } else if (!o.json && views > 0) {
        view = "\n" + view;
      }
      io.out << view;
      io.out.flush();
      ++views;
      if (o.once) {
        if (!monitor.heard_chassis()) {
          io.err << "ranger_can monitor: no RANGER feedback on " << o.iface << " within "
                 << o.window << " s\n";
          return 1;
        }
        return 0;
      }
      if (o.count && views >= *o.count) return 0;
      next_view += period;
      if (next_view <= now) next_view = now + period;
    }
    auto frame = (*bus)->receive(std::min<std::chrono::nanoseconds>(next_view - clock.now(), 50ms));
    if (frame) {
      monitor.on_frame(*frame, clock.now());
    } else if (frame.error().code != Errc::kTimeout) {
      // The bus reports and recovers a lost interface itself; the view shows the state.
      ::usleep(20000);
    }
  }
  return 0;
}

}  // namespace ranger::cli
