// `ranger_can monitor IFACE`: a live view of a RANGER chassis, refreshed about 5 times a second;
// what to reach for first when something does not move. The view itself is ChassisMonitor
// (cli_monitor_view.hpp); this file opens the bus, keeps time and decides when to draw. Beside
// the view, a read-only driver (ranger::Driver on a socket of its own, in lock-step: it sends
// nothing) reports the driver's events — the link, the control mode, faults, the identification,
// padding — as text lines (with the view's time) or, with --json, as JSON objects of their own.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <deque>
#include <iostream>
#include <memory>
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
#include "ranger_can/control/driver.hpp"
#include "ranger_can/parse.hpp"
#include "ranger_can/text.hpp"

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

// IFACE once more, for the driver that reports the events: read-only (it sends nothing).
class ListeningSource : public BusSource {
 public:
  explicit ListeningSource(std::string iface) : iface_(std::move(iface)) {}
  Result<std::unique_ptr<Bus>> open() override { return open_interface(iface_); }
  std::string name() const override { return iface_; }
  bool read_only() const override { return true; }

 private:
  std::string iface_;
};

// The read-only driver's iterations and its events as the monitor shows them: JSON objects, or
// text lines with the view's time ("   1.234 warn: chassis on can0 went silent ..."; the debug
// ones left out). On a screen that is cleared for every view, the last few lines are shown under
// the view instead.
class EventLines {
 public:
  EventLines(Driver& driver, Timestamp start, bool json, bool under_view)
      : driver_(driver), start_(start), json_(json), under_view_(under_view) {}

  // Runs the driver at `now` (at most every 10 ms: it reads what queued meanwhile); what is new
  // to print now.
  std::string step(Timestamp now) {
    if (now < next_step_) return "";
    driver_.step(now);
    next_step_ = now + std::chrono::milliseconds(10);
    return take();
  }
  // What is new since the last call: printed now (returned), or kept for the view.
  std::string take() {
    std::vector<DriverEvent> events;
    driver_.events_since(seen_, events);
    std::string out;
    for (const DriverEvent& e : events) {
      seen_ = e.sequence;
      if (json_) {
        out += to_json(e, start_) + "\n";
      } else if (e.severity != Severity::kDebug) {
        out += text::format("%8.3f ", seconds(e.time - start_)) +
               std::string(to_string(e.severity)) + ": " + describe(e) + "\n";
      }
    }
    if (!under_view_) return out;
    recent_.push_back(out);
    while (recent_.size() > kRecent)
      recent_.pop_front();
    return "";
  }
  // The recent lines, for the bottom of a cleared screen ("" when they are printed as they come).
  std::string recent() const {
    std::string out;
    for (const std::string& lines : recent_)
      out += lines;
    return out.empty() ? out : "events:\n" + out;
  }

 private:
  static constexpr std::size_t kRecent = 8;
  Driver& driver_;
  Timestamp start_;
  bool json_, under_view_;
  std::uint64_t seen_ = 0;
  Timestamp next_step_{0};
  std::deque<std::string> recent_;
};

// The read-only driver beside the view: the vehicle and protocol the options give (auto: it
// identifies the chassis from what it hears, as the view does).
DriverConfig listening_config(const Vehicle& vehicle, bool identify) {
  DriverConfig c;
  apply_vehicle(vehicle, c);
  c.controller.listen_only = true;
  c.controller.auto_command_mode = false;
  if (identify) c.protocol = ProtocolChoice::kAuto;
  return c;
}

// --diagnostics: the driver listens (sends nothing) for the window, at least the identification's
// listening time and a little, then the groups /diagnostics shows are printed.
int diagnostics_main(const ParsedArgs& args, Io io) {
  const MonitorOptions o = options_from(args);
  const Result<Vehicle> vehicle = vehicle_from_args(args);
  if (!vehicle) return usage_error(monitor_command(), io, vehicle.error().message);
  const DriverConfig config = listening_config(*vehicle, protocol_is_auto(args));
  StopSignals signals;
  auto session = DriverSession::open(o.iface, config, /*listen_only=*/true);
  if (!session) {
    io.err << "ranger_can monitor: " << session.error().message << "\n";
    return 1;
  }
  (*session)->run_for(std::max(from_seconds(o.window), config.identification.listen_time + 300ms));
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
  Driver driver(listening_config(*vehicle, protocol_is_auto(args)),
                std::make_shared<ListeningSource>(o.iface), clock);
  // With --protocol auto (the default) the first half second of frames (or the --once window)
  // identifies the chassis's settings passively, as `decode` does for a log; the view starts then.
  std::vector<CanFrame> heard;  // while identifying
  std::optional<ChassisMonitor> monitor;
  if (!protocol_is_auto(args)) monitor.emplace(from_seconds(o.window), vehicle->profile);
  const Timestamp start = clock.now();
  EventLines events(driver, start, o.json, clear);
  const auto period = from_seconds(1.0 / o.rate);
  Timestamp next_view =
      start + (o.once ? from_seconds(o.window) : std::max(period, from_seconds(0.5)));
  long views = 0;

  while (!StopSignals::requested()) {
    const Timestamp now = clock.now();
    io.out << events.step(now);
    if (now >= next_view && !monitor) {
      auto m = identified_monitor(args, *vehicle, o, heard, now);
      if (!m) return usage_error(monitor_command(), io, m.error().message);
      monitor.emplace(std::move(*m));
    }
    if (now >= next_view) {
      const BusStatus status = (*bus)->status();
      io.out << drawn(o.json ? monitor->render_json(o.iface, status, now) + "\n"
                             : monitor->render_text(o.iface, status, now, color) + events.recent(),
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

// --diagnostics prints the groups once; otherwise the live view.
int monitor_or_diagnostics(const ParsedArgs& args, Io io) {
  return args.has("--diagnostics") ? diagnostics_main(args, io) : monitor_main(args, io);
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
      "profile of --model, --protocol and --set (docs/PROTOCOL_INTERPRETATIONS.md).\n"
      "The driver's events (the link, the control mode, faults by name, the identification,\n"
      "frames longer than their layout, ...) come between the views as lines 'SEC severity:\n"
      "text' (SEC since the start), under the view when the screen is cleared, and as JSON\n"
      "objects of their own with --json ({\"seq\",\"t\",\"event\",\"severity\",\"text\",...}).",
      {required_arg("IFACE", "the CAN interface of the chassis", "can0")},
      {
          flag("--once",
               "listen for --window seconds, print one view, exit (0 if the chassis was heard, 1 "
               "if not)"),
          option("--count", "N", "print N views, then exit", integer_in(1, 1000000000)),
          option("--rate", "HZ", "views per second (default 5)", number_in(0.1, 100.0)),
          option("--window", "SEC", "frame-rate window and --once listening time (default 1)",
                 number_in(0.05, 3600.0)),
          flag("--json", "one JSON object per view (and per event) instead of text"),
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
      monitor_or_diagnostics,
  };
  return spec;
}

int run_monitor(const Args& args, Io io) {
  return run_command(monitor_command(), args, io);
}

}  // namespace ranger::cli
