// `ranger_can sim IFACE`: the virtual RANGER chassis on a CAN interface until SIGINT/SIGTERM.
//
// The chassis runs on its own thread (VirtualChassisRunner); this thread reads control commands
// (stdin and an optional FIFO), prints the chassis's state changes and writes the ground-truth
// pose. Everything the chassis does lives in libranger_can (virtual_chassis.hpp): this file is
// only the command line around it.
#include <fcntl.h>
#include <poll.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstring>
#include <deque>
#include <fstream>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include "cli_bus.hpp"
#include "cli_commands.hpp"
#include "cli_input.hpp"
#include "cli_options.hpp"
#include "cli_profile.hpp"
#include "cli_signals.hpp"
#include "ranger_can/clock.hpp"
#include "ranger_can/json.hpp"
#include "ranger_can/parse.hpp"
#include "ranger_can/sim/chassis_commands.hpp"
#include "ranger_can/sim/sim_bus_source.hpp"
#include "ranger_can/sim/switch_model.hpp"
#include "ranger_can/sim/virtual_chassis_runner.hpp"
#include "ranger_can/text.hpp"

namespace ranger::cli {

namespace {

using namespace std::chrono_literals;
using sim::apply_chassis_command;
using sim::parse_error_bit;

// The chassis commands plus the session's own (`ranger_can sim --help` and `help`).
const std::string& control_help() {
  static const std::string text =
      std::string("control ") + sim::kChassisCommandHelp +
      "  wait SEC                 hold the following commands for SEC seconds (scripting)\n"
      "  help                     this list\n"
      "  quit                     stop the simulator\n";
  return text;
}

struct SimOptions {
  std::string iface;
  sim::VirtualChassisConfig config;
  std::string variant = "manual";
  bool estop = false;
  bool stuck = false;
  std::vector<std::string> errors;  // error bits by index or name, of the variant's layout
  std::string pose_out;
  double pose_rate = 50.0;
  std::string control_fifo;
  bool read_stdin = true;
  std::optional<double> duration;
  bool quiet = false;
};

Result<std::vector<std::int16_t>> parse_ultrasonic(const std::string& text) {
  std::vector<std::int16_t> mm;
  for (const std::string& item : text::split(text, ',')) {
    auto d = parse_integer("distance", item, -4, 32767);
    if (!d) return d.error();
    mm.push_back(static_cast<std::int16_t>(*d));
  }
  if (mm.size() != 1 && mm.size() != protocol::kUltrasonicCount) {
    return Error{Errc::kInvalidArgument,
                 "give 1 or 8 comma-separated distances, got " + std::to_string(mm.size())};
  }
  return mm;
}

// The chassis: the model's (--model; a RANGER without it), speaking the profile of --protocol and
// --set, the options below, then the variant's deviation (--chassis-variant), last.
Result<SimOptions> options_from(const ParsedArgs& args) {
  SimOptions o;
  o.iface = *args.get("IFACE");
  const Result<Vehicle> vehicle = vehicle_from_args(args);
  if (!vehicle) return vehicle.error();
  if (vehicle->model) o.config = sim::chassis_for_model(*vehicle->model);
  o.config.profile = vehicle->profile;
  o.variant = args.get_or("--chassis-variant", o.variant);
  if (args.has("--mode-switch-time")) {
    o.config.mode_switch_duration = from_seconds(args.number("--mode-switch-time", 0.0));
  }
  o.config.initial_soc = args.number("--soc", o.config.initial_soc);
  o.config.drivetrain.batteries =
      static_cast<int>(args.integer("--batteries", o.config.drivetrain.batteries));
  if (const auto text = args.get("--ultrasonic")) {
    const auto mm = *parse_ultrasonic(*text);  // the table's rule accepted it
    if (mm.size() == 1) {
      o.config.ultrasonic.fill(mm[0]);
    } else {
      std::copy(mm.begin(), mm.end(), o.config.ultrasonic.begin());
    }
  }
  o.config.ultrasonic_enabled = args.has("--avoidance");
  o.config.boot_in_remote_mode = args.has("--remote");
  if (auto v = args.get("--firmware")) o.config.version = *v;
  o.estop = args.has("--estop");
  o.errors = args.all("--error");
  o.stuck = args.has("--stuck-mode-switch");
  o.config.limits.acceleration = args.number("--accel", o.config.limits.acceleration);
  o.config.garbage_seed = static_cast<std::uint32_t>(args.integer("--seed", o.config.garbage_seed));
  o.pose_out = args.get_or("--pose-out", "");
  o.pose_rate = args.number("--pose-rate", o.pose_rate);
  o.control_fifo = args.get_or("--control", "");
  o.read_stdin = !args.has("--no-stdin");
  if (args.has("--duration")) o.duration = args.number("--duration", 0.0);
  o.quiet = args.has("--quiet");
  auto config = sim::apply_variant(o.variant, o.config);
  if (!config) return config.error();
  o.config = *config;
  // The mode switch's settings (sim/switch_model.hpp), over the model's and the variant's.
  sim::SwitchModelConfig& sw = o.config.switch_model;
  if (const auto r = args.get("--switch-report")) sw.report = *sim::kSwitchReportNames.parse(*r);
  sw.flag_share = args.number("--switch-flag-share", sw.flag_share);
  sw.seed = static_cast<std::uint32_t>(args.integer("--switch-seed", sw.seed));
  if (args.has("--switch-slew")) {
    sw.turn = sim::SwitchTurn::kSlew;
    sw.slew_rate = args.number("--switch-slew", sw.slew_rate);
  }
  // The steering and the frame rates, over the model's and the variant's too.
  if (args.has("--steering-rate")) {
    o.config.limits.steering_rate = deg_to_rad(args.number("--steering-rate", 0.0));
  }
  if (args.has("--bms-period")) {
    o.config.frame_rates.period[static_cast<std::size_t>(sim::FrameGroup::kBms)] =
        from_seconds(args.number("--bms-period", 0.0));
  }
  for (const auto& e : o.errors) {
    if (auto b = parse_error_bit(e, o.config.profile.error_word); !b) return b.error();
  }
  return o;
}

// Control lines from standard input (or the Io stream in tests) and an optional FIFO.
class ControlInput {
 public:
  ControlInput(std::istream& in, bool read_in, int fifo_fd)
      : in_(in), use_stdin_fd_(&in == &std::cin), read_in_(read_in), fifo_fd_(fifo_fd) {}

  // Waits up to `timeout` for input and appends every complete line that arrived.
  void poll_lines(std::chrono::milliseconds timeout, std::vector<std::string>& lines) {
    if (read_in_ && !use_stdin_fd_) {  // an in-memory stream never blocks: take what it has
      std::string line;
      while (std::getline(in_, line))
        lines.push_back(line);
      read_in_ = false;
    }
    std::vector<pollfd> fds;
    const bool stdin_ok = read_in_ && use_stdin_fd_ && stdin_readable_without_stopping();
    if (stdin_ok) fds.push_back({STDIN_FILENO, POLLIN, 0});
    if (fifo_fd_ >= 0) fds.push_back({fifo_fd_, POLLIN, 0});
    if (fds.empty()) {
      ::poll(nullptr, 0, static_cast<int>(timeout.count()));
      return;
    }
    if (::poll(fds.data(), fds.size(), static_cast<int>(timeout.count())) <= 0) return;
    for (const auto& p : fds) {
      if ((p.revents & (POLLIN | POLLHUP)) == 0) continue;
      std::string& buffer = p.fd == STDIN_FILENO ? stdin_buffer_ : fifo_buffer_;
      char chunk[4096];
      const ssize_t n = ::read(p.fd, chunk, sizeof chunk);
      if (n == 0 && p.fd == STDIN_FILENO) read_in_ = false;  // EOF: keep running, stop reading
      if (n <= 0) continue;
      buffer.append(chunk, static_cast<std::size_t>(n));
      std::size_t nl;
      while ((nl = buffer.find('\n')) != std::string::npos) {
        lines.push_back(buffer.substr(0, nl));
        buffer.erase(0, nl + 1);
      }
      if (buffer.size() > 65536) buffer.clear();  // no newline in sight: not a command stream
    }
  }

 private:
  // A background job reading its terminal would be stopped by SIGTTIN: only read a terminal
  // while we are its foreground process group.
  static bool stdin_readable_without_stopping() {
    if (::isatty(STDIN_FILENO) == 0) return true;
    return ::tcgetpgrp(STDIN_FILENO) == ::getpgrp();
  }

  std::istream& in_;
  bool use_stdin_fd_;
  bool read_in_;
  int fifo_fd_;
  std::string stdin_buffer_;
  std::string fifo_buffer_;
};

// Opens (creating if needed) the control FIFO. O_RDWR keeps a writer open ourselves, so the FIFO
// never reports end-of-file between two `echo cmd > FIFO`.
Result<int> open_fifo(const std::string& path, bool& created) {
  created = false;
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    if (::mkfifo(path.c_str(), 0600) != 0) {
      return Error{Errc::kIoError,
                   "--control: cannot create FIFO '" + path + "': " + std::strerror(errno)};
    }
    created = true;
  } else if (!S_ISFIFO(st.st_mode)) {
    return Error{Errc::kInvalidArgument, "--control: '" + path + "' exists and is not a FIFO"};
  }
  const int fd = ::open(path.c_str(), O_RDWR | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    return Error{Errc::kIoError,
                 "--control: cannot open FIFO '" + path + "': " + std::strerror(errno)};
  }
  return fd;
}

std::string stamp_prefix(Timestamp since_boot) {
  return text::format("[%9.3f] ", seconds(since_boot));
}

// The control FIFO, open for the run; removed at its end if the run created it.
struct Fifo {
  int fd = -1;
  bool created = false;
  std::string path;
  Fifo() = default;
  Fifo(const Fifo&) = delete;
  Fifo& operator=(const Fifo&) = delete;
  ~Fifo() {
    if (fd >= 0) ::close(fd);
    if (created) ::unlink(path.c_str());
  }
};

// The run after start-up: control lines in, state changes and the pose out, until `quit`, a
// signal, --duration or the chassis's failure.
class SimLoop {
 public:
  SimLoop(const SimOptions& o, Io io, sim::VirtualChassisRunner& runner, const Clock& clock,
          Timestamp boot, int fifo_fd, std::ofstream& pose_file)
      : o_(o),
        io_(io),
        runner_(runner),
        clock_(clock),
        boot_(boot),
        input_(io.in, o.read_stdin, fifo_fd),
        pose_file_(pose_file),
        pose_period_(from_seconds(1.0 / o.pose_rate)),
        next_pose_(boot),
        typing_(&io.in == &std::cin && o.read_stdin && ::isatty(STDIN_FILENO) != 0) {}

  // The exit status.
  int run() {
    std::vector<std::string> lines;
    while (!quit_) {
      if (StopSignals::requested()) {
        if (!o_.quiet) {
          io_.out << "ranger_can sim: "
                  << (StopSignals::signal_number() == SIGTERM ? "SIGTERM" : "SIGINT")
                  << ", stopping\n";
        }
        return 0;
      }
      if (o_.duration && clock_.now() - boot_ >= std::chrono::duration<double>(*o_.duration)) {
        return 0;
      }
      if (!runner_.running()) {
        io_.err << "ranger_can sim: " << runner_.failure() << "\n";
        return 1;
      }
      lines.clear();
      input_.poll_lines(10ms, lines);
      for (auto& l : lines)
        held_.push_back(std::move(l));
      while (!held_.empty() && clock_.now() >= hold_until_ && !quit_) {
        const std::string line = held_.front();
        held_.pop_front();
        execute(line);
      }
      print_events();
      if (pose_file_.is_open() && clock_.now() >= next_pose_) write_pose();
    }
    return 0;
  }

  void print_events() {
    auto events = runner_.with_chassis([](sim::VirtualChassis& c) { return c.take_events(); });
    if (o_.quiet) return;
    out_.clear();
    for (const auto& e : events)
      out_ += stamp_prefix(e.time - boot_) + e.text + "\n";
    if (!out_.empty()) {
      io_.out << out_;
      io_.out.flush();
    }
  }

  // How many bad control lines went unshown; what the chassis sent and received.
  void report_end() {
    if (bad_lines_ > kMaxReportedLines && !typing_) {
      io_.err << "ranger_can sim: " << bad_lines_ << " bad control line(s) (the first "
              << kMaxReportedLines << " shown)\n";
    }
    if (o_.quiet) return;
    const auto c = runner_.with_chassis([](sim::VirtualChassis& ch) { return ch.counters(); });
    io_.out << "ranger_can sim: stopped; " << c.frames_sent << " frames sent, " << c.frames_received
            << " received (" << c.frames_rejected << " rejected, " << c.frames_ignored
            << " ignored)";
    if (c.send_failures > 0) io_.out << ", " << c.send_failures << " send failures";
    io_.out << "\n";
    io_.out.flush();
  }

 private:
  // Bad control lines are reported one by one to a person typing; from a pipe or a FIFO only
  // the first kMaxReportedLines are, then counted, so no input makes sim print without bound.
  void control_error(const std::string& message) {
    ++bad_lines_;
    if (typing_ || bad_lines_ <= kMaxReportedLines) {
      io_.err << "ranger_can sim: " << message << "\n";
    } else if (bad_lines_ == kMaxReportedLines + 1) {
      io_.err << "ranger_can sim: more bad control lines: counted, not shown\n";
    }
  }

  // `wait SEC`: hold the following lines.
  void hold(const std::vector<std::string>& w) {
    auto v = parse_double_in("wait SEC", w.size() > 1 ? w[1] : "", 0.0, 1e6);
    if (!v || w.size() > 2) {
      control_error(v ? "usage: wait SEC" : v.error().message);
      return;
    }
    hold_until_ = clock_.now() + from_seconds(*v);
  }

  void execute(const std::string& line) {
    const std::vector<std::string> w = text::split_words(line);
    const std::string first = w.empty() ? "" : w[0];
    if (first == "quit" || first == "exit") {
      quit_ = true;
    } else if (first == "help") {
      io_.out << control_help();
      io_.out.flush();
    } else if (first == "wait") {
      hold(w);
    } else {
      auto r = runner_.with_chassis(
          [&](sim::VirtualChassis& c) { return apply_chassis_command(line, c); });
      if (!r) {
        control_error(r.error().message);
      } else if (!r->empty()) {
        io_.out << *r << "\n";
        io_.out.flush();
      }
    }
  }

  void write_pose() {
    const auto s = runner_.with_chassis([](sim::VirtualChassis& c) { return c.snapshot(); });
    out_.clear();
    JsonWriter w(out_);
    w.begin_object().key("t").seconds(wall_.now()).key("sim_t").number(seconds(s.time - boot_));
    w.key("x").number(s.pose.x).key("y").number(s.pose.y).key("yaw").number(s.pose.yaw);
    w.key("vx").number(s.twist.vx).key("vy").number(s.twist.vy).key("wz").number(s.twist.wz);
    w.key("distance").number(s.distance_travelled).end_object();
    pose_file_ << out_ << "\n";
    pose_file_.flush();
    next_pose_ += pose_period_;
    if (next_pose_ < clock_.now()) next_pose_ = clock_.now() + pose_period_;
  }

  const SimOptions& o_;
  Io io_;
  sim::VirtualChassisRunner& runner_;
  const Clock& clock_;
  SystemClock wall_;
  Timestamp boot_;
  ControlInput input_;
  std::ofstream& pose_file_;
  std::deque<std::string> held_;  // lines waiting behind a `wait`
  Timestamp hold_until_{0};
  std::chrono::nanoseconds pose_period_;
  Timestamp next_pose_;
  bool quit_ = false;
  const bool typing_;
  std::size_t bad_lines_ = 0;
  std::string out_;
};

int sim_main(const ParsedArgs& args, Io io) {
  const Result<SimOptions> parsed = options_from(args);
  if (!parsed) return usage_error(sim_command(), io, parsed.error().message);
  const SimOptions& o = *parsed;

  std::ofstream pose_file;
  if (!o.pose_out.empty()) {
    pose_file.open(o.pose_out, std::ios::out | std::ios::trunc);
    if (!pose_file) {
      io.err << "ranger_can sim: cannot write --pose-out '" << o.pose_out
             << "': " << std::strerror(errno) << "\n";
      return 1;
    }
  }
  Fifo fifo;
  if (!o.control_fifo.empty()) {
    auto fd = open_fifo(o.control_fifo, fifo.created);
    fifo.path = o.control_fifo;
    if (!fd) {
      io.err << "ranger_can sim: " << fd.error().message << "\n";
      return 1;
    }
    fifo.fd = *fd;
  }
  auto bus = open_interface(o.iface);
  if (!bus) {
    io.err << "ranger_can sim: " << bus.error().message << "\n";
    return 1;
  }

  StopSignals signals;
  SteadyClock clock;
  sim::VirtualChassisRunner runner(**bus, o.config, clock);
  const Timestamp boot = clock.now();
  runner.with_chassis([&](sim::VirtualChassis& c) {
    if (o.estop) c.set_emergency_stop(true);
    if (o.stuck) c.set_mode_switch_stuck(true);
    for (const auto& e : o.errors) {
      if (auto b = parse_error_bit(e, c.profile().error_word)) c.set_error_bit(*b, true);
    }
  });
  if (!o.quiet) {
    io.out << "ranger_can sim: virtual RANGER on " << (*bus)->name() << " (variant " << o.variant
           << ", protocol " << describe(o.config.profile)
           << "; Ctrl-C to stop; 'help' lists control commands)\n";
    io.out.flush();
  }
  SimLoop loop(o, io, runner, clock, boot, fifo.fd, pose_file);
  const int exit_code = loop.run();
  runner.stop();
  loop.print_events();
  loop.report_end();
  return exit_code;
}

template <typename T>
Status check_with(Result<T> (*parse)(const std::string&), const std::string& text) {
  auto r = parse(text);
  if (!r) return r.error();
  return ok_status();
}

}  // namespace

const CommandSpec& sim_command() {
  const sim::VirtualChassisConfig defaults;
  const SimOptions option_defaults;
  const auto seconds_of = [](std::chrono::nanoseconds d) { return number_text(seconds(d)); };
  static const CommandSpec spec{
      "sim",
      "run the virtual RANGER chassis on a CAN interface, with fault injection",
      "Runs a virtual RANGER chassis on IFACE until SIGINT/SIGTERM, 'quit' or --duration: it\n"
      "speaks the chassis side of the whole protocol (boots in standby, obeys 0x421, 0x111 per\n"
      "motion mode, 0x141 with a timed switch, 0x441, 0x451; sends every feedback frame at the\n"
      "manual's period) and stops by itself 500 ms after the last 0x111. State changes are\n"
      "printed as '[seconds since boot] what happened'. Faults are injected with the options\n"
      "below or with control commands read from standard input and/or a FIFO (--control).\n"
      "\n"
      "The chassis is the model of --model (default: a RANGER) speaking the protocol of\n"
      "--protocol and --set (default: the model's; docs/PROTOCOL_INTERPRETATIONS.md); the\n"
      "variant of --chassis-variant applies last. Variants (also the bus spec sim:VARIANT):\n" +
          sim::variants_help() +
          "\n"
          "Try it:  ranger_can sim vcan0 &   ranger_can monitor vcan0   ranger_can send vcan0 "
          "control can",
      {required_arg("IFACE", "the CAN interface to run the chassis on", "vcan0")},
      {
          option("--chassis-variant", "VARIANT",
                 "how this chassis differs (see the list above; default manual)",
                 one_of(sim::variant_names())),
          model_option(),
          protocol_option(false),
          set_option(),
          option("--mode-switch-time", "SEC",
                 "time a motion-mode switch takes once at rest (default " +
                     seconds_of(defaults.mode_switch_duration) + ")",
                 parameter_rule("sim/mode_switch_duration")),
          option("--soc", "PCT",
                 "initial battery state of charge, 0-100 (default " +
                     number_text(defaults.initial_soc) + ")",
                 parameter_rule("sim/initial_soc")),
          option("--batteries", "N",
                 "batteries fitted, 1-" + std::to_string(protocol::kBatteryCount) + " (default " +
                     std::to_string(defaults.drivetrain.batteries) + ")",
                 integer_in(1, protocol::kBatteryCount)),
          option("--ultrasonic", "MM[,MM..]",
                 "sensor distances in mm: one value for all 8, or 8 values (negative: -1 offline, "
                 "-2 checksum, -3 abnormal, -4 exception)",
                 checked_by([](const std::string& t) { return check_with(parse_ultrasonic, t); })),
          flag("--avoidance", "start with ultrasonic obstacle avoidance enabled"),
          flag("--remote", "boot with the remote control in charge (remote mode)"),
          option("--firmware", "TEXT",
                 "the firmware version the chassis answers 0x4A1 with (agx_v2 variants; "
                 "default 'ranger_sim 0.1.0'; the control command 'version TEXT' changes it)"),
          flag("--estop", "boot with the emergency stop pressed"),
          option(
              "--error", "BIT|NAME", "boot with this 0x211 error bit raised",
              checked_by([](const std::string& t) { return check_with(sim::check_error_bit, t); }))
              .repeated(),
          flag("--stuck-mode-switch", "motion-mode switches never complete"),
          option("--switch-report", "REPORT",
                 "what 0x291 says of a mode switch: mode_left (the mode being left, switching = 1 "
                 "throughout; the RANGER's default) or at_once (the new mode at once, the flag on "
                 "some switches: the field's, ranger_mini_v3's and field_switch's default)",
                 one_of(sim::kSwitchReportNames.names())),
          option("--switch-flag-share", "F",
                 "share of switches whose 0x291 raises the flag under at_once (the field: 439/941)",
                 number_in(0.0, 1.0)),
          option("--switch-seed", "N", "seed of the per-switch draw of the flag (default 1)",
                 integer_in(0, 0xFFFFFFFFLL)),
          option(
              "--switch-slew", "RAD/S",
              "the wheels turn to the new mode's angles at this peak rate (the field: 3.26, with "
              "t = d / rate + 0.064 s) instead of over --mode-switch-time",
              number_in(0.1, 100.0)),
          option("--accel", "M/S2",
                 "acceleration limit (default " + number_text(defaults.limits.acceleration) + ")",
                 number_in(0.01, 20.0)),
          option("--steering-rate", "DEG/S",
                 "steering slew rate while driving (default the model's: " +
                     number_text(rad_to_deg(defaults.limits.steering_rate)) +
                     "; ranger_mini_v3 the field's 3.26 rad/s = 186.8, with its profile)",
                 number_in(1.0, 3600.0)),
          option("--bms-period", "S",
                 "0x361/0x362 every S seconds (default the frame-rate schedule's: the manual's "
                 "0.5; ranger_mini_v3 the field's 0.25)",
                 number_in(0.02, 10.0)),
          option("--seed", "N",
                 "seed of the garbage-frame generator (default " +
                     std::to_string(defaults.garbage_seed) + ")",
                 integer_in(0, 0xFFFFFFFFLL)),
          option("--pose-out", "FILE",
                 "write the ground-truth pose as JSON lines:\n"
                 "{\"t\":s,\"sim_t\":s,\"x\":m,\"y\":m,\"yaw\":rad,\n"
                 "\"vx\":m/s,\"vy\":m/s,\"wz\":rad/s,\"distance\":m}\n"
                 "(t: Unix time; sim_t: since the chassis booted)"),
          option("--pose-rate", "HZ",
                 "pose lines per second (default " + number_text(option_defaults.pose_rate) + ")",
                 number_in(0.1, 1000.0)),
          option("--control", "FIFO", "also read control commands from FIFO (created if missing)"),
          flag("--no-stdin", "do not read control commands from standard input"),
          option("--duration", "SEC", "stop after SEC seconds", number_in(0.0, 1e7)),
          flag("--quiet", "do not print state changes"),
      },
      control_help(),
      sim_main,
  };
  return spec;
}

int run_sim(const Args& args, Io io) {
  return run_command(sim_command(), args, io);
}

}  // namespace ranger::cli
