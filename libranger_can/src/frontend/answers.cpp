#include "ranger_can/frontend/answers.hpp"

#include <cctype>

#include "ranger_can/control/vocabulary.hpp"
#include "ranger_can/sim/chassis_commands.hpp"
#include "ranger_can/text.hpp"
#include "ranger_can/types.hpp"

namespace ranger {
namespace {

using State = RequestOutcome::State;

// "name<separator>value, ..." of (name, value) pairs.
std::string join_pairs(const std::vector<std::pair<std::string, std::string>>& pairs,
                       const char* separator) {
  std::vector<std::string> items;
  for (const auto& [name, value] : pairs)
    items.push_back(name + separator + value);
  return text::join(items);
}

}  // namespace

ServiceAnswer answer_of(const RequestOutcome& outcome, std::string_view unconfirmed) {
  ServiceAnswer a;
  a.success = outcome.state == State::kAnswered;
  a.message = !outcome.message.empty()
                  ? outcome.message
                  : std::string(unconfirmed) + " (" + std::string(to_string(outcome.state)) + ")";
  return a;
}

ServiceAnswer request_answer(const RequestOutcome& outcome) {
  using K = RequestOutcome::Kind;
  switch (outcome.kind) {
    case K::kResume:
      return resume_answer(outcome);
    case K::kUltrasonic:
      return answer_of(outcome, "the chassis did not confirm the ultrasonic setting in time");
    case K::kLights:
      return answer_of(outcome, "the chassis did not report its lights in time");
    case K::kPark:
      return answer_of(outcome,
                       outcome.on ? "park not confirmed in time" : "release not confirmed in time");
    case K::kDriveMode:
      return answer_of(outcome, "drive mode not confirmed in time");
    case K::kFirmwareVersion:
      return answer_of(outcome, "the chassis did not report its firmware version in time");
    case K::kClearErrors:
      break;
  }
  return answer_of(outcome, "clear_errors not confirmed in time");
}

std::optional<ServiceAnswer> resume_refused_offline(const DriverSnapshot& snapshot,
                                                    const std::string& port) {
  if (snapshot.bus_open) return std::nullopt;
  return ServiceAnswer{false, "resume refused: not connected to " + port +
                                  (snapshot.bus_error.empty() ? "" : ": " + snapshot.bus_error)};
}

ServiceAnswer resume_answer(const RequestOutcome& outcome) {
  ServiceAnswer a = answer_of(outcome, "resume not applied");
  if (a.success) a.message = "re-armed: cmd_vel drives the chassis again";
  return a;
}

ServiceAnswer clear_errors_answer(std::uint8_t code, const RequestOutcome& outcome,
                                  ErrorWordLayout layout) {
  const std::string asked =
      "clear_errors code " + std::to_string(code) + " (" + error_clear_description(code) + ")";
  if (outcome.state == State::kAnswered && outcome.error_word) {
    const auto names = fault_names(*outcome.error_word, layout);
    return {true, asked + ": the chassis answered with error word " +
                      text::hex(*outcome.error_word, 8) +
                      (names.empty() ? " (no errors)" : " (" + text::join(names) + ")")};
  }
  return {false, asked + ": " +
                     (outcome.state == State::kFailed ? outcome.message
                                                      : std::string("the chassis did not answer"))};
}

const std::vector<std::pair<std::uint8_t, std::optional<protocol::MotionMode>>>&
motion_mode_numbers() {
  using M = protocol::MotionMode;
  static const std::vector<std::pair<std::uint8_t, std::optional<M>>> kNumbers = {
      {0, M::kAckermann},
      {1, M::kOblique},
      {2, M::kSpin},
      {4, M::kSideSlip},
      {kAutomaticModeNumber, std::nullopt}};
  return kNumbers;
}

std::string unknown_motion_mode_number(int number, const ProtocolProfile& profile) {
  std::vector<std::string> valid;  // the ones valid on this chassis (the settings in use)
  for (const auto& [n, mode] : motion_mode_numbers()) {
    if (mode && can_drive_in(*mode, profile)) {
      valid.push_back(std::to_string(n) + " (" + std::string(protocol::to_string(*mode)) + ")");
    }
  }
  return "mode " + std::to_string(number) + " unknown: under protocol " + profile.revision +
         " use " + text::join(valid) + " or " + std::to_string(kAutomaticModeNumber) +
         " (automatic)";
}

std::string motion_mode_pinned(std::optional<protocol::MotionMode> mode) {
  return mode ? "motion mode pinned to " + std::string(protocol::to_string(*mode)) +
                    " (the switch happens at standstill)"
              : "automatic motion-mode selection";
}

std::optional<ServiceAnswer> ultrasonic_request_refused(bool enable, bool disable) {
  if (enable != disable) return std::nullopt;
  return ServiceAnswer{false, std::string(enable ? "contradictory request (enable and disable both "
                                                   "true)"
                                                 : "empty request (neither enable nor disable)") +
                                  ": set exactly one of them; nothing sent"};
}

namespace {

std::string upper(std::string s) {
  for (char& c : s)
    c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

// "0 (OFF), 1 (ON), ...": a table's numbers as the services' refusals list them.
template <class Table>
std::string numbered(const Table& table) {
  std::vector<std::string> items;
  for (const auto& row : table)
    items.push_back(std::to_string(static_cast<int>(row.value)) + " (" +
                    upper(std::string(row.name)) + ")");
  return text::join(items);
}

Result<protocol::LightMode> light_mode_of(const char* side, long long number) {
  for (const auto& row : protocol::kLightModeNames) {
    if (static_cast<long long>(row.value) == number) return row.value;
  }
  return Error{Errc::kInvalidArgument, std::string(side) + "_mode " + std::to_string(number) +
                                           " is not one of " + numbered(protocol::kLightModeNames) +
                                           ": nothing sent"};
}

}  // namespace

Result<LightsRequest> lights_request(protocol::LightMode front, long long front_brightness,
                                     protocol::LightMode rear, long long rear_brightness) {
  auto fb = light_brightness("front", front, front_brightness);
  if (!fb) return fb.error();
  auto rb = light_brightness("rear", rear, rear_brightness);
  if (!rb) return rb.error();
  return LightsRequest{front, *fb, rear, *rb};
}

Result<LightsRequest> lights_request(long long front_mode, long long front_brightness,
                                     long long rear_mode, long long rear_brightness) {
  const auto front = light_mode_of("front", front_mode);
  if (!front) return front.error();
  const auto rear = light_mode_of("rear", rear_mode);
  if (!rear) return rear.error();
  return lights_request(*front, front_brightness, *rear, rear_brightness);
}

Result<protocol::DriveMode> drive_mode_request(long long number) {
  for (const auto& row : protocol::kDriveModeNames) {
    if (static_cast<long long>(row.value) == number) return row.value;
  }
  return Error{Errc::kInvalidArgument, "drive mode " + std::to_string(number) + " is not one of " +
                                           numbered(protocol::kDriveModeNames) + ": nothing sent"};
}

LogLine answer_line(std::string_view service, const ServiceAnswer& answer) {
  const std::string name(service);
  const bool named =
      answer.message.rfind(name + ":", 0) == 0 || answer.message.rfind(name + " ", 0) == 0;
  return {answer.success ? Severity::kInfo : Severity::kWarn,
          named ? answer.message : name + ": " + answer.message};
}

bool is_answer_event(EventKind kind) {
  return kind == EventKind::kRequestSettled || kind == EventKind::kMotionModeRequested;
}

std::vector<LogLine> describe_protocol_setup(const NodeParameters& params) {
  const auto& pp = params.protocol;
  const auto& c = params.driver.controller;
  std::vector<LogLine> out;
  out.push_back(
      {Severity::kInfo,
       text::format("model %s (%s): wheelbase %.3f m, track %.3f m, wheel radius %.3f m, max "
                    "speed %.2f m/s",
                    pp.model.c_str(), pp.model_display_name.c_str(), c.geometry.wheelbase,
                    c.geometry.track, c.geometry.wheel_radius, c.limits.max_linear_speed)});
  if (params.driver.protocol == ProtocolChoice::kAuto) {
    out.push_back(
        {Severity::kInfo,
         text::format(
             "protocol auto: the settings are identified from the chassis before anything "
             "moves (listening first, then a few degrees of steering at zero speed; "
             "identify_timeout %.1f s); nothing is driven until then, and the plausibility "
             "monitors check them while driving",
             seconds(params.driver.identification.timeout))});
    if (!pp.model_settings.empty()) {
      out.push_back({Severity::kInfo,
                     "the " + pp.model_display_name + "'s own readings (" +
                         join_pairs(pp.model_settings, "=") +
                         ") are not assumed with protocol auto: the identification decides what "
                         "it can at rest, the plausibility monitors the rest on first motion; set "
                         "protocol: " +
                         c.profile.revision + " to force the model's profile"});
    }
  } else if (pp.auto_overridden) {
    out.push_back({Severity::kWarn,
                   "protocol auto, but interpretation parameters are set (" +
                       join_pairs(pp.settings, ": ") +
                       "): the driver cannot keep single settings forced on top of an "
                       "identification, so identification is off and the settings are forced: " +
                       describe(c.profile) +
                       " (the plausibility monitors still check them while "
                       "driving)"});
  } else {
    out.push_back({Severity::kInfo, "protocol settings " + describe(c.profile) + " (" + pp.source +
                                        "); the plausibility monitors check them while driving"});
  }
  return out;
}

LogLine describe_injection(const std::string& line, const Result<std::string>& said) {
  if (!said) {
    return {Severity::kWarn, "sim/inject \"" + line + "\" not applied: " + said.error().message +
                                 " (valid commands: " + text::join(sim::chassis_command_names()) +
                                 "; see ranger_base/README.md)"};
  }
  return {Severity::kInfo, "sim/inject \"" + line + "\" applied to the virtual chassis" +
                               (said->empty() ? "" : ": ") + *said};
}

}  // namespace ranger
