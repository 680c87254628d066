// What happened in the driver, as data: every transition a front end reports (the bus opened,
// the chassis heard or silent, the control mode, why motion is refused, the re-arm latch, the
// identification, the plausibility monitors, faults, the vendor's features, the requests'
// outcomes, the stop at shutdown) is a DriverEvent with a kind, a severity, the driver clock's
// time, a sequence number and typed fields. The driver decides when something is a transition
// (event_tracker.hpp); a front end never diffs snapshots to find one.
//
// Text is made at the edge, by one function for every front end: describe(event) gives the line
// the ROS node logs at the event's severity, `ranger_can monitor` prints and `ranger_can scenario`
// writes (with to_json). EventLog is the bounded ring the driver keeps them in: a reader asks for
// the events after the last sequence number it saw and is told how many it missed when it fell
// more than the ring behind.
#pragma once

#include <chrono>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "ranger_can/control/controller.hpp"
#include "ranger_can/control/identification.hpp"
#include "ranger_can/control/plausibility.hpp"
#include "ranger_can/control/rearm.hpp"
#include "ranger_can/control/request_book.hpp"
#include "ranger_can/control/vendor_features.hpp"
#include "ranger_can/result.hpp"
#include "ranger_can/text.hpp"
#include "ranger_can/types.hpp"
#include "ranger_can/wire/protocol.hpp"

namespace ranger {

// How much an event matters to whoever runs the robot (ROS: DEBUG, INFO, WARN, ERROR).
enum class Severity { kDebug, kInfo, kWarn, kError };
inline constexpr auto kSeverityNames = text::enum_names<Severity>({
    {Severity::kDebug, "debug"},
    {Severity::kInfo, "info"},
    {Severity::kWarn, "warn"},
    {Severity::kError, "error"},
});
inline std::string_view to_string(Severity s) {
  return kSeverityNames.name(s);
}

// Every kind of event, with the payload (EventData) it carries.
enum class EventKind {
  kBusOpened,             // BusEvent: the bus opened; waiting for the chassis
  kBusOpenFailed,         // BusEvent: it cannot be opened (error, retry period); a new error only
  kStillWaiting,          // BusEvent: nothing heard since the bus opened (every 30 s)
  kLinkConnected,         // LinkEvent: the chassis is heard for the first time
  kLinkSilent,            // LinkEvent: no 0x211 within link_timeout
  kLinkHeardAgain,        // LinkEvent: heard again after a silence
  kControlModeChanged,    // ControlModeEvent: 0x211's control mode
  kRefusalChanged,        // RefusalEvent: why motion is refused (kNone: accepted again)
  kRearmLatched,          // RearmEvent: stop causes latched (motion needs a re-arm)
  kRearmCleared,          // RearmEvent: re-armed
  kIdentificationPhase,   // IdentificationEvent: the identification moved to another phase
  kIdentified,            // IdentificationEvent: decided (evidence, the settings kept)
  kIdentificationFailed,  // IdentificationEvent: not identified (what to set)
  kSettingLearned,        // SettingLearnedEvent: a setting found out while driving
  kPlausibilityWarning,   // PlausibilityEvent: a persistent mismatch (each once)
  kPlausibilityStop,      // PlausibilityEvent: a mismatch that stopped the robot
  kCommandRefused,        // CommandRefusedEvent: a command refused (NaN, not connected, ...)
  kCommandAdjusted,       // CommandAdjustedEvent: a command saturated to what the chassis can do
  kMotionModeRequested,   // MotionModeEvent: set_motion_mode applied
  kFaultRaised,           // FaultEvent: a 0x211 fault appeared
  kFaultCleared,          // FaultEvent: ... and went away
  kFirmwareVersion,       // FirmwareEvent: the chassis answered the version request
  kParkChanged,           // ParkEvent: the chassis entered or left park
  kLightsChanged,         // LightsEvent: 0x231 reports other lights
  kRequestSettled,        // RequestEvent: a mailbox request answered or failed
  kFramesPadded,          // PaddedFramesEvent: an ID arrives longer than its layout (once per ID)
  kShutdownStop,          // ShutdownEvent: the stop sent at shutdown (or why none was)
};
inline constexpr auto kEventKindNames = text::enum_names<EventKind>({
    {EventKind::kBusOpened, "bus_opened"},
    {EventKind::kBusOpenFailed, "bus_open_failed"},
    {EventKind::kStillWaiting, "still_waiting"},
    {EventKind::kLinkConnected, "link_connected"},
    {EventKind::kLinkSilent, "link_silent"},
    {EventKind::kLinkHeardAgain, "link_heard_again"},
    {EventKind::kControlModeChanged, "control_mode_changed"},
    {EventKind::kRefusalChanged, "refusal_changed"},
    {EventKind::kRearmLatched, "rearm_latched"},
    {EventKind::kRearmCleared, "rearm_cleared"},
    {EventKind::kIdentificationPhase, "identification_phase"},
    {EventKind::kIdentified, "identified"},
    {EventKind::kIdentificationFailed, "identification_failed"},
    {EventKind::kSettingLearned, "setting_learned"},
    {EventKind::kPlausibilityWarning, "plausibility_warning"},
    {EventKind::kPlausibilityStop, "plausibility_stop"},
    {EventKind::kCommandRefused, "command_refused"},
    {EventKind::kCommandAdjusted, "command_adjusted"},
    {EventKind::kMotionModeRequested, "motion_mode_requested"},
    {EventKind::kFaultRaised, "fault_raised"},
    {EventKind::kFaultCleared, "fault_cleared"},
    {EventKind::kFirmwareVersion, "firmware_version"},
    {EventKind::kParkChanged, "park_changed"},
    {EventKind::kLightsChanged, "lights_changed"},
    {EventKind::kRequestSettled, "request_settled"},
    {EventKind::kFramesPadded, "frames_padded"},
    {EventKind::kShutdownStop, "shutdown_stop"},
});
inline std::string_view to_string(EventKind k) {
  return kEventKindNames.name(k);
}

// ---- the payloads ----------------------------------------------------------------------------

struct BusEvent {
  std::string bus;                     // the bus spec: "can0", "sim", "replay:FILE"
  bool socketcan = false;              // a SocketCAN interface (the bring-up hint)
  std::string error;                   // kBusOpenFailed: why
  std::chrono::nanoseconds retry{0};   // kBusOpenFailed: the reconnect interval
  std::chrono::nanoseconds waited{0};  // kStillWaiting: since the bus opened
};
struct LinkEvent {
  std::string bus;
  LinkState from = LinkState::kNeverConnected;
  LinkState to = LinkState::kConnected;
  std::chrono::nanoseconds link_timeout{0};  // kLinkSilent: how long nothing came
};
struct ControlModeEvent {
  std::optional<protocol::ControlMode> from;  // nullopt: not known (never reported, or undefined)
  std::optional<protocol::ControlMode> to;
  std::uint8_t raw = 0;  // 0x211's byte (an undefined value shows here)
};
struct RefusalEvent {
  MotionRefusal from = MotionRefusal::kLinkLost;
  MotionRefusal to = MotionRefusal::kNone;
  std::string detail;  // describe_refusal at the time: what it means and what to do
};
struct RearmEvent {
  StopCauses causes = 0;   // kRearmLatched: the causes that latched now; kRearmCleared: all
  bool by_resume = false;  // kRearmCleared: resume() (else the commander's zero twist)
};
struct IdentificationEvent {
  IdentificationPhase phase = IdentificationPhase::kListening;
  // The identification's status at the time (message, evidence, decided and kept settings).
  std::shared_ptr<const IdentificationStatus> status;
  std::string settings;    // kIdentified: the settings in use now (describe(profile))
  std::string commission;  // kIdentificationFailed: the commissioning command (SocketCAN only)
};
struct SettingLearnedEvent {
  IdentifiedSetting setting;
  std::string settings;  // the settings in use now
};
struct PlausibilityEvent {
  PlausibilityFinding finding;
};
struct CommandRefusedEvent {
  Errc code = Errc::kNotFinite;  // kNotFinite (the chassis is stopped), kInterfaceDown, ...
  std::string message;
  std::uint64_t count = 1;  // refused since the previous event of this kind (reports are spaced)
};
struct CommandAdjustedEvent {
  std::uint32_t flags = 0;  // KinematicsFlag bits
};
struct MotionModeEvent {
  std::optional<protocol::MotionMode> mode;  // nullopt: automatic selection
};
struct FaultEvent {
  std::string name;  // the fault table's name ("over_current"), or "reserved_bit_N"
  std::optional<protocol::Fault> fault;  // its meaning (nullopt for a reserved bit)
  int motor = 0;                         // a motor-numbered fault's motor
  std::string description;
  bool critical = false;         // the chassis does not drive until it is cleared
  std::uint32_t error_word = 0;  // 0x211's whole word now
};
struct FirmwareEvent {
  std::string version;
};
struct ParkEvent {
  bool parked = false;
};
struct LightsEvent {
  LightsState lights;
};
struct RequestEvent {
  RequestOutcome outcome;
};
struct PaddedFramesEvent {
  std::uint32_t id = 0;
  std::string_view name;  // the frame table's name
};
struct ShutdownEvent {
  bool sent = false;
  std::uint32_t frame_id = 0;  // the stop's frame
  std::string why_not;         // !sent: why nothing was sent
};

using EventData =
    std::variant<BusEvent, LinkEvent, ControlModeEvent, RefusalEvent, RearmEvent,
                 IdentificationEvent, SettingLearnedEvent, PlausibilityEvent, CommandRefusedEvent,
                 CommandAdjustedEvent, MotionModeEvent, FaultEvent, FirmwareEvent, ParkEvent,
                 LightsEvent, RequestEvent, PaddedFramesEvent, ShutdownEvent>;

struct DriverEvent {
  std::uint64_t sequence = 0;  // 1, 2, ... per driver (EventLog numbers them)
  Timestamp time{0};           // driver clock
  EventKind kind = EventKind::kBusOpened;
  Severity severity = Severity::kInfo;
  EventData data;

  // The payload as `T` (nullptr if it carries another).
  template <typename T>
  const T* as() const {
    return std::get_if<T>(&data);
  }
};

// The line for people, as the ROS node logs it ("chassis on can0 went silent (no system status
// for 0.10 s): motion stopped, no odometry until it is heard again").
std::string describe(const DriverEvent& event);
// One JSON object (no newline): {"seq":N,"t":S,"event":"kind","severity":"warn","text":"..."}
// and the payload's main fields; t in seconds since `origin` (three decimals).
std::string to_json(const DriverEvent& event, Timestamp origin = Timestamp{0});

// Why motion is refused, and what to do about it, in words (system_state's
// motion_inhibited_detail, diagnostics, RefusalEvent::detail); "" while the chassis is driven as
// asked. The identification's words come from `identification` (may be null).
std::string describe_refusal(const ControllerState& controller,
                             const IdentificationStatus* identification);

// The bounded ring of recent events (thread-safe): the driver appends after every iteration,
// readers take what is new to them.
class EventLog {
 public:
  explicit EventLog(std::size_t capacity = 256) : capacity_(capacity) {}

  // Numbers the events (sequence) and appends them; the oldest fall out beyond the capacity.
  void append(std::vector<DriverEvent>& events);
  // The events numbered after `after`, oldest first, appended to `out`. Returns how many of them
  // fell out of the ring before they were read (0 for a reader that keeps up).
  std::uint64_t read(std::uint64_t after, std::vector<DriverEvent>& out) const;
  // The newest event's number (0: none yet).
  std::uint64_t last_sequence() const;

 private:
  const std::size_t capacity_;
  mutable std::mutex mutex_;
  std::deque<DriverEvent> ring_;
  std::uint64_t last_ = 0;
};

}  // namespace ranger
