// `ranger_can identify IFACE`: runs the driver with `--protocol auto` until the identification
// ends (control/identification.hpp) and prints the decision with its evidence.
#include <ostream>
#include <string>

#include "cli_commands.hpp"
#include "cli_options.hpp"
#include "cli_profile.hpp"
#include "cli_session.hpp"
#include "cli_signals.hpp"
#include "ranger_can/text.hpp"

namespace ranger::cli {

namespace {

using namespace std::chrono_literals;

using text::duration_text;

// The identification as text: the decision, every setting (decided or kept), the evidence.
void print_identification(const IdentificationStatus& s, const ProtocolProfile& profile,
                          bool simulated, std::ostream& out) {
  if (s.decided_ok()) {
    out << "identified in " << duration_text(s.elapsed()) << (simulated ? " (simulated time)" : "")
        << ": " << describe(profile) << "\n";
    out << "confidence: " << text::fixed(s.confidence, 3) << "\n";
  } else {
    out << "not identified after " << duration_text(s.elapsed())
        << (simulated ? " (simulated time)" : "") << "\n";
  }
  out << "settings:\n";
  std::size_t width = 0;
  for (const ProfileSetting& p : profile_settings())
    width = std::max(width, p.name.size());
  for (const ProfileSetting& p : profile_settings()) {
    const auto value = get_setting(profile, p.name);
    std::string how = "kept (the " + s.revision + " preset's)";
    for (const IdentifiedSetting& d : s.decided) {
      if (d.name == p.name) how = "decided";
    }
    const std::string v = value ? *value : "?";
    out << "  " << p.name << std::string(width + 2 - p.name.size(), ' ') << v
        << std::string(v.size() < 16 ? 16 - v.size() : 1, ' ') << how << "\n";
  }
  out << "evidence:\n";
  for (const std::string& e : s.evidence)
    out << "  - " << e << "\n";
}

std::string firmware_text(const FirmwareVersion& v) {
  switch (v.state) {
    case FirmwareVersion::State::kAnswered:
      return v.text;
      break;
    case FirmwareVersion::State::kUnsupported:
      return "unknown (the chassis sends none of the vendor's frames: no 0x4A1 version)";
    case FirmwareVersion::State::kUnanswered:
      return "unknown (no answer to the 0x4A1 version request)";
    default:
      return "unknown (" + std::string(to_string(v.state)) + ")";
  }
}

int identify_main(const ParsedArgs& args, Io io) {
  const std::string iface = *args.get("IFACE");
  DriverConfig config;
  const Result<Vehicle> vehicle = vehicle_from_args(args);  // --model: a MINI's geometry
  if (!vehicle) return usage_error(identify_command(), io, vehicle.error().message);
  apply_vehicle(*vehicle, config);
  config.protocol = ProtocolChoice::kAuto;
  config.identify_revision = protocol_revision(args);
  config.identification.timeout = from_seconds(args.number("--timeout", 10.0));
  config.identification.spin_check = !args.has("--no-spin-check");
  if (Status st = config.validate(); !st)
    return usage_error(identify_command(), io, st.error().message);
  StopSignals signals;
  auto session = DriverSession::open(iface, config);
  if (!session) {
    io.err << "ranger_can identify: " << session.error().message << "\n";
    return 1;
  }
  DriverSession& s = **session;
  // Identified, then the firmware version (asked once the settings are decided) answered, or
  // known to be unavailable.
  const bool finished = s.run_until(
      [](const DriverSnapshot& snap) {
        if (!snap.identification || !snap.identification->done()) return false;
        const auto v = snap.firmware.state;
        return !snap.identification->decided_ok() || v == FirmwareVersion::State::kAnswered ||
               v == FirmwareVersion::State::kUnanswered ||
               v == FirmwareVersion::State::kUnsupported;
      },
      config.identification.timeout + 3s);
  s.stop();
  const auto snap = s.snapshot();
  if (!finished || !snap->identification) {
    io.err << "ranger_can identify: "
           << (s.interrupted() ? "interrupted" : "the identification did not end") << "\n";
    return 1;
  }
  const IdentificationStatus& id = *snap->identification;
  ProtocolProfile profile = id.profile;
  if (Status st = apply_set_options(profile, args); !st) {
    return usage_error(identify_command(), io, st.error().message);
  }
  print_identification(id, profile, s.simulated(), io.out);
  io.out << "firmware: " << firmware_text(snap->firmware) << "\n";
  if (!id.decided_ok()) {
    io.err << "ranger_can identify: " << id.message << "\n";
    return 1;
  }
  return 0;
}

}  // namespace

const CommandSpec& identify_command() {
  static const CommandSpec spec{
      "identify",
      "identify which protocol settings a chassis speaks, before anything moves",
      "Runs the driver with --protocol auto until it has identified the chassis, then prints the\n"
      "decision: every protocol setting (decided from evidence, or kept at the preset's value),\n"
      "the confidence and the evidence, one line each, then the chassis's firmware version\n"
      "(0x4A1, asked once the settings are decided; agx_v2 chassis only).\n"
      "\n"
      "The driver first listens without sending anything (the IDs only the vendor's revision\n"
      "sends, frame lengths, the 0x211 byte-7 counter, the BMS voltage scale), then takes CAN\n"
      "command mode and checks the steering at standstill: a switch to spin mode (every wheel at\n"
      "+-atan(wheelbase/track)) and a few degrees of steering at zero speed, read back from\n"
      "0x271 and 0x221. No wheel rolls. IFACE is any bus: can0, sim, sim:VARIANT (simulated\n"
      "time, deterministic), replay:FILE (a log: the frames alone decide).",
      {required_arg("IFACE", "the bus: a SocketCAN interface, sim, sim:VARIANT or replay:FILE",
                    "can0")},
      {model_option(), protocol_option(), set_option(),
       option("--timeout", "S", "give up after S seconds (default 10): the node's identify_timeout",
              number_in(2.0, 600.0)),
       flag("--no-spin-check", "skip the spin-mode check of the 0x271 unit and sign")},
      "With --protocol manual or agx_v2 the identification starts from that preset instead of\n"
      "deciding it; --set values are applied after it.\n"
      "Exit status: 0 identified; 1 not identified (the message says what to set instead), the\n"
      "bus could not be opened, or interrupted; 2 on a usage error.",
      identify_main,
  };
  return spec;
}

int run_identify(const Args& args, Io io) {
  return run_command(identify_command(), args, io);
}

}  // namespace ranger::cli
