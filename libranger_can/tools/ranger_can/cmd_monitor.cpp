// `ranger_can monitor IFACE`: a live view of a RANGER chassis, refreshed about 5 times a second;
// what to reach for first when something does not move. The view itself is ChassisMonitor
// (cli_monitor_view.hpp); this file opens the bus, keeps time and decides when to draw.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include "cli_bus.hpp"
#include "cli_commands.hpp"
#include "cli_monitor_view.hpp"
#include "cli_options.hpp"
#include "cli_profile.hpp"
#include "cli_session.hpp"
#include "cli_signals.hpp"
#include "ranger_can/clock.hpp"
#include "ranger_can/control/diagnostics.hpp"
#include "ranger_can/parse.hpp"

namespace ranger::cli {

namespace {

using namespace std::chrono_literals;

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

MonitorOptions options_from(const ParsedArgs& args) {
  MonitorOptions o;
  o.iface = *args.get("IFACE");
  o.once = args.has("--once");
  if (args.has("--count")) o.count = static_cast<long>(args.integer("--count", 1));
  o.rate = args.number("--rate", o.rate);
  o.window = args.number("--window", o.window);
  o.json = args.has("--json");
  o.no_color = args.has("--no-color");
  o.no_clear = args.has("--no-clear");
  return o;
}

std::chrono::nanoseconds seconds(double s) {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::duration<double>(s));
}

// --diagnostics: the driver listens (sends nothing) for the window, at least the identification's
// listening time and a little, then the groups /diagnostics shows are printed.
int print_diagnostics(const ParsedArgs& args, const MonitorOptions& o, const Vehicle& vehicle,
                      Io io) {
  DriverConfig config;
  apply_vehicle(vehicle, config);
  if (protocol_is_auto(args)) config.protocol = ProtocolChoice::kAuto;
  StopSignals signals;
  auto session = DriverSession::open(o.iface, config, /*listen_only=*/true);
  if (!session) {
    io.err << "ranger_can monitor: " << session.error().message << "\n";
    return 1;
  }
  (*session)->run_for(std::max(seconds(o.window), config.identification.listen_time + 300ms));
  const auto snapshot = (*session)->snapshot();
  (*session)->stop();
  ChassisDiagnostics diagnostics({o.iface, "", ""});
  for (const DiagnosticGroup& group : diagnostics.report(*snapshot))
    io.out << to_text(group);
  return snapshot->controller.link == LinkState::kConnected ? 0 : 1;
}

int monitor_main(const ParsedArgs& args, Io io) {
  const MonitorOptions o = options_from(args);
  const Result<Vehicle> vehicle = vehicle_from_args(args);
  if (!vehicle) return usage_error(monitor_command(), io, vehicle.error().message);
  if (args.has("--diagnostics")) return print_diagnostics(args, o, *vehicle, io);

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
  // With --protocol auto (the default) the first half second of frames (or the --once window)
  // identifies the chassis's settings passively, as `decode` does for a log; the view starts then.
  const bool identify = protocol_is_auto(args);
  std::vector<CanFrame> heard;  // while identifying
  std::optional<ChassisMonitor> monitor;
  if (!identify) monitor.emplace(seconds(o.window), vehicle->profile);
  const Timestamp start = clock.now();
  const auto period = seconds(1.0 / o.rate);
  Timestamp next_view = start + (o.once ? seconds(o.window) : std::max(period, seconds(0.5)));
  long views = 0;

  while (!StopSignals::requested()) {
    const Timestamp now = clock.now();
    if (now >= next_view && !monitor) {
      ProtocolProfile profile = identify_log(heard, vehicle->geometry).profile;
      if (Status st = apply_set_options(profile, args); !st) {
        return usage_error(monitor_command(), io, st.error().message);
      }
      monitor.emplace(seconds(o.window), profile);
      for (const CanFrame& f : heard)
        monitor->on_frame(f, now);
      heard.clear();
    }
    if (now >= next_view) {
      const BusStatus status = (*bus)->status();
      std::string view = o.json ? monitor->render_json(o.iface, status, now) + "\n"
                                : monitor->render_text(o.iface, status, now, color);
      if (clear) {
        view = "\x1b[H\x1b[2J" + view;
      } else if (!o.json && views > 0) {
        view = "\n" + view;
      }
      io.out << view;
      io.out.flush();
      ++views;
      if (o.once) {
        if (!monitor->heard_chassis()) {
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
      if (monitor) {
        monitor->on_frame(*frame, clock.now());
      } else {
        heard.push_back(*frame);
      }
    } else if (frame.error().code != Errc::kTimeout) {
      // The bus reports and recovers a lost interface itself; the view shows the state.
      ::usleep(20000);
    }
  }
  return 0;
}

}  // namespace

const CommandSpec& monitor_command() {
  static const CommandSpec spec{
      "monitor",
      "live view of a chassis on a CAN interface",
      "Shows what a RANGER chassis on IFACE reports, refreshed live until Ctrl-C: control and\n"
      "motion mode, speed and steering (with 'left'/'right' spelled out), per-wheel angle/speed\n"
      "and motor rpm/current/temperature, battery and BMS alarms, 0x211 errors by name,\n"
      "ultrasonic distances, the commands the host sends (0x111 age and rate), frame rates per\n"
      "ID against the manual's periods, and the bus state. Frames are read under the protocol\n"
      "profile of --model, --protocol and --set (docs/PROTOCOL_INTERPRETATIONS.md).",
      {required_arg("IFACE", "the CAN interface of the chassis", "can0")},
      {
          flag("--once",
               "listen for --window seconds, print one view, exit (0 if the chassis was heard, 1 "
               "if not)"),
          option("--count", "N", "print N views, then exit", integer_in(1, 1000000000)),
          option("--rate", "HZ", "views per second (default 5)", number_in(0.1, 100.0)),
          option("--window", "SEC", "frame-rate window and --once listening time (default 1)",
                 number_in(0.05, 3600.0)),
          flag("--json", "one JSON object per view instead of text"),
          flag("--diagnostics",
               "listen through the driver (nothing sent) for --window seconds (at least 1.5), "
               "print the diagnostic groups the ROS node's /diagnostics shows, exit (0 if the "
               "chassis was heard, 1 if not); IFACE may also be sim[:VARIANT] or replay:FILE"),
          flag("--no-color",
               "no ANSI colours (default: colours on a terminal unless NO_COLOR is set)"),
          flag("--no-clear",
               "do not clear the screen between views (default: clear on a terminal)"),
          model_option(),
          protocol_option(),
          set_option(),
      },
      "",
      monitor_main,
  };
  return spec;
}

int run_monitor(const Args& args, Io io) {
  return run_command(monitor_command(), args, io);
}

}  // namespace ranger::cli
