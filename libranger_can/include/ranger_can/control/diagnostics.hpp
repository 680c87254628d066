// Diagnostics as data: a DriverSnapshot turned into the diagnostic groups every front end shows
// — one per concern (CAN link, control mode, protocol settings, chassis errors, battery, frame
// rates), each with a level, a one-line message and key/values. The ROS 1 node maps them one to
// one onto diagnostic_msgs (/diagnostics, ranger_base/src/diagnostics.cpp), the ROS 2 node the
// same way, `ranger_can monitor IFACE --diagnostics` prints them. Also the snapshot's other words
// a front end shows: why motion is refused, the stop causes by name.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <sstream>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include "ranger_can/control/driver.hpp"
#include "ranger_can/text.hpp"

namespace ranger {

// diagnostic_msgs/DiagnosticStatus's levels, with its numbers.
enum class DiagnosticLevel : std::uint8_t { kOk = 0, kWarn = 1, kError = 2, kStale = 3 };
inline constexpr auto kDiagnosticLevelNames = text::enum_names<DiagnosticLevel>({
    {DiagnosticLevel::kOk, "OK"},
    {DiagnosticLevel::kWarn, "WARN"},
    {DiagnosticLevel::kError, "ERROR"},
    {DiagnosticLevel::kStale, "STALE"},
});
inline std::string_view to_string(DiagnosticLevel level) {
  return kDiagnosticLevelNames.name(level);
}

struct DiagnosticGroup {
  std::string name;  // "CAN link" (a ROS front end prefixes its node name)
  DiagnosticLevel level = DiagnosticLevel::kOk;
  std::string message;
  std::vector<std::pair<std::string, std::string>> values;

  void add(std::string key, std::string value) {
    values.emplace_back(std::move(key), std::move(value));
  }
  void add(std::string key, const char* value) { add(std::move(key), std::string(value)); }
  // A number as diagnostic_updater writes it (a stream's default format: "0.97", "50", "1e+06").
  template <typename N, typename = std::enable_if_t<std::is_arithmetic_v<N>>>
  void add(std::string key, N value) {
    std::ostringstream out;
    out << value;
    add(std::move(key), out.str());
  }
  void summary(DiagnosticLevel l, std::string m) {
    level = l;
    message = std::move(m);
  }
  // diagnostic_updater's mergeSummary: the higher level wins; two problems are both said ("; ").
  void merge_summary(DiagnosticLevel l, const std::string& m);
  // The value of `key`; nullptr when the group has none.
  const std::string* value(std::string_view key) const;
};
// "CAN link: OK: CAN bus active; chassis connected", then "  Port: can0" per value.
std::string to_text(const DiagnosticGroup& group);

// The groups, in the order a report gives them.
inline constexpr std::array<std::string_view, 6> kDiagnosticGroups = {
    "CAN link", "Control mode", "Protocol", "Chassis errors", "Battery", "Frame rates"};
inline constexpr std::string_view kDiagLink = kDiagnosticGroups[0];
inline constexpr std::string_view kDiagControl = kDiagnosticGroups[1];
inline constexpr std::string_view kDiagProtocol = kDiagnosticGroups[2];
inline constexpr std::string_view kDiagErrors = kDiagnosticGroups[3];
inline constexpr std::string_view kDiagBattery = kDiagnosticGroups[4];
inline constexpr std::string_view kDiagFrameRates = kDiagnosticGroups[5];

// What the snapshot does not say: the bus as the front end named it (the commissioning command
// names a CAN interface), where the protocol settings came from (the node's parameters), and the
// namespace that tells robots on one ROS master apart.
struct DiagnosticContext {
  std::string port_name;        // "can0", "sim", "replay:FILE"
  std::string settings_source;  // "" : the snapshot's ProtocolChoice ("auto" / "forced")
  std::string ns;               // "/robot1"; "" is "/"
};
// "ranger:<namespace>:<port_name>", e.g. "ranger:/robot1:sim": the hardware_id of every group.
std::string hardware_id(const std::string& ns, const std::string& port_name);

// ---- the groups, one function each ------------------------------------------------------------
DiagnosticGroup diagnose_link(const DriverSnapshot& s);
DiagnosticGroup diagnose_control(const DriverSnapshot& s);
// The settings in use and where they came from; with `protocol: auto` the identification (phase,
// decision with its evidence, the settings left undecided); the plausibility monitors (every
// warning with the value to try, and the stop). ERROR while the identification failed (its
// message names what to set and the commissioning command) or a plausibility stop holds; WARN
// while a monitor warns.
DiagnosticGroup diagnose_protocol(const DriverSnapshot& s, const DiagnosticContext& context);
DiagnosticGroup diagnose_errors(const DriverSnapshot& s);
DiagnosticGroup diagnose_battery(const DriverSnapshot& s);

// Received frames per ID: the snapshot's rates (FrameStats, over its window), the rejected and
// padded counts; WARN while frames are being rejected (since the previous call).
class FrameRateMonitor {
 public:
  DiagnosticGroup diagnose(const DriverSnapshot& s);

 private:
  std::map<std::uint32_t, std::uint64_t> previous_rejected_;
};

// Every group of a front end, with what they remember between reports (the frame-rate rejects).
class ChassisDiagnostics {
 public:
  explicit ChassisDiagnostics(DiagnosticContext context) : context_(std::move(context)) {}
  // Group `index` of kDiagnosticGroups from `s`.
  DiagnosticGroup group(std::size_t index, const DriverSnapshot& s);
  std::vector<DiagnosticGroup> report(const DriverSnapshot& s);  // every group, in order
  const DiagnosticContext& context() const { return context_; }

 private:
  DiagnosticContext context_;
  FrameRateMonitor rates_;
};

// ---- the snapshot in words --------------------------------------------------------------------
// The identification is listening: nothing is sent, and the controller hears nothing on purpose
// (its link reads never-connected; motion is refused with `identifying`) until the chassis has
// been heard.
bool listening(const ControllerState& state);
// Why motion is refused, by stable name ("estop", "identifying", ...; "" while driven).
std::string refusal_name(const ControllerState& state);
// Why motion is refused, and what to do about it, in words (ranger_msgs' motion_inhibited_detail,
// diagnostics; the driver's refusal events carry the same): driver_events.hpp's describe_refusal
// of the snapshot's controller state and identification.
std::string describe_refusal(const DriverSnapshot& snapshot);
// The stop causes of a set by name ("emergency_stop", "remote", ...), in the library's order.
std::vector<std::string> cause_names(StopCauses causes);

}  // namespace ranger
