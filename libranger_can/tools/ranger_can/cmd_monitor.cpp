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
#include "cli_signals.hpp"
#include "ranger_can/clock.hpp"
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

// The view as drawn: after a clear-screen on a terminal, else (text) after a blank line from the
// second view on.
std::string drawn(std::string view, bool clear, bool json, long views) {
  if (clear) return "\x1b[H\x1b[2J" + view;
  if (!json && views > 0) return "\n" + view;
  return view;
}

// The monitor once the identification window is over: the chassis's settings read from the
// frames heard so far (passively, as `decode` does for a log), --set over them.
Result<ChassisMonitor> identified_monitor(const ParsedArgs& args, const Vehicle& vehicle,
                                          const MonitorOptions& o, std::vector<CanFrame>& heard,
                                          Timestamp now) {
  ProtocolProfile profile = identify_log(heard, vehicle.geometry).profile;
  if (Status st = apply_set_options(profile, args); !st) return st.error();
  ChassisMonitor monitor(from_seconds(o.window), profile);
  for (const CanFrame& f : heard)
    monitor.on_frame(f, now);
  heard.clear();
  return monitor;
}

// A frame received (or the receive's error): to the monitor, or kept for the identification.
void take(const Result<CanFrame>& frame, std::optional<ChassisMonitor>& monitor,
          std::vector<CanFrame>& heard, Timestamp now) {
  if (frame) {
    if (monitor) {
      monitor->on_frame(*frame, now);
    } else {
      heard.push_back(*frame);
    }
  } else if (frame.error().code != Errc::kTimeout) {
    // The bus reports and recovers a lost interface itself; the view shows the state.
    ::usleep(20000);
  }
}

int monitor_main(const ParsedArgs& args, Io io) {
  const MonitorOptions o = options_from(args);
  const Result<Vehicle> vehicle = vehicle_from_args(args);
  if (!vehicle) return usage_error(monitor_command(), io, vehicle.error().message);

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
  std::vector<CanFrame> heard;  // while identifying
  std::optional<ChassisMonitor> monitor;
  if (!protocol_is_auto(args)) monitor.emplace(from_seconds(o.window), vehicle->profile);
  const Timestamp start = clock.now();
  const auto period = from_seconds(1.0 / o.rate);
  Timestamp next_view =
      start + (o.once ? from_seconds(o.window) : std::max(period, from_seconds(0.5)));
  long views = 0;

  while (!StopSignals::requested()) {
    const Timestamp now = clock.now();
    if (now >= next_view && !monitor) {
      auto m = identified_monitor(args, *vehicle, o, heard, now);
      if (!m) return usage_error(monitor_command(), io, m.error().message);
      monitor.emplace(std::move(*m));
    }
    if (now >= next_view) {
      const BusStatus status = (*bus)->status();
      io.out << drawn(o.json ? monitor->render_json(o.iface, status, now) + "\n"
                             : monitor->render_text(o.iface, status, now, color),
                      clear, o.json, views);
      io.out.flush();
      ++views;
      if (o.once && !monitor->heard_chassis()) {
        io.err << "ranger_can monitor: no RANGER feedback on " << o.iface << " within " << o.window
               << " s\n";
        return 1;
      }
      if (o.once || (o.count && views >= *o.count)) return 0;
      next_view += period;
      if (next_view <= now) next_view = now + period;
    }
    const auto frame =
        (*bus)->receive(std::min<std::chrono::nanoseconds>(next_view - clock.now(), 50ms));
    take(frame, monitor, heard, clock.now());
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
