// The words a front end answers and logs with, made once: the service answers of the ROS 1 and
// ROS 2 nodes (resume, clear_errors, set_motion_mode, the vendor requests) and the start-up
// log's protocol lines. A front end maps them onto its own types (a ROS response's success and
// message, a log call at the line's severity), so the same request gets the same answer, and the
// same start the same log, whichever front end ran it.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "ranger_can/control/driver.hpp"
#include "ranger_can/control/driver_events.hpp"
#include "ranger_can/frontend/node_parameters.hpp"

namespace ranger {

struct ServiceAnswer {
  bool success = false;
  std::string message;
};

// A line for the log at its severity.
struct LogLine {
  Severity severity = Severity::kInfo;
  std::string text;
};

// A request after the front end's wait for it: success once answered. The message is the
// driver's (the answer, or why it failed), else `unconfirmed` and the state it reached, e.g.
// "park not confirmed in time (sent)".
ServiceAnswer answer_of(const RequestOutcome& outcome, std::string_view unconfirmed);

// Any request's answer after the wait, by its kind (RequestOutcome::kind, on): clear_errors'
// as clear_errors_answer, resume's as resume_answer, the others as answer_of with their words for
// "not confirmed in time" ("park not confirmed in time", "the chassis did not report its lights in
// time", ...).
ServiceAnswer request_answer(const RequestOutcome& outcome);

// `resume` on a bus that is not open: refused before asking, naming the port and the bus's error.
std::optional<ServiceAnswer> resume_refused_offline(const DriverSnapshot& snapshot,
                                                    const std::string& port);
// `resume`'s answer: "re-armed: cmd_vel drives the chassis again", or why not (the driver names
// the cause still active).
ServiceAnswer resume_answer(const RequestOutcome& outcome);

// `clear_errors CODE`'s answer: the error word the chassis answered with and its faults by name
// (under `layout`), or why not.
ServiceAnswer clear_errors_answer(std::uint8_t code, const RequestOutcome& outcome,
                                  ErrorWordLayout layout);

// set_motion_mode's numbers (ranger_msgs/SetMotionMode: ACKERMANN 0, OBLIQUE 1, SPIN 2,
// SIDE_SLIP 4, AUTOMATIC 255 = nullopt), and the refusal of a number it does not know, listing the
// modes this chassis drives under `profile`.
inline constexpr std::uint8_t kAutomaticModeNumber = 255;
const std::vector<std::pair<std::uint8_t, std::optional<protocol::MotionMode>>>&
motion_mode_numbers();
std::string unknown_motion_mode_number(int number, const ProtocolProfile& profile);
// set_motion_mode accepted: "motion mode pinned to spin (the switch happens at standstill)".
std::string motion_mode_pinned(std::optional<protocol::MotionMode> mode);

// The services' checks, made before anything is sent; each refusal ends ": nothing sent".
// set_ultrasonic: exactly one of enable and disable.
std::optional<ServiceAnswer> ultrasonic_request_refused(bool enable, bool disable);
// set_lights from ranger_msgs/SetLights' numbers: a mode is one of kLightModeNames' numbers, a
// brightness 0..kMaxLightBrightness (it counts in custom mode only: 0 is sent otherwise).
Result<LightsRequest> lights_request(long long front_mode, long long front_brightness,
                                     long long rear_mode, long long rear_brightness);
// The same from the modes' names (the binding's and the CLI's spelling).
Result<LightsRequest> lights_request(protocol::LightMode front, long long front_brightness,
                                     protocol::LightMode rear, long long rear_brightness);
// set_drive_mode from ranger_msgs/SetDriveMode's number: 0 CURRENT, 1 VOLTAGE.
Result<protocol::DriveMode> drive_mode_request(long long number);

// The log line of a service's answer: info for a success, a warning for a refusal or a failure,
// in the answer's words, prefixed "<service>: " unless they name the service already. Each
// answer is logged once this way; the driver's events that are the same answer
// (is_answer_event) are not logged besides.
LogLine answer_line(std::string_view service, const ServiceAnswer& answer);
// request_settled and motion_mode_requested: a service's answer (answer_line logs it).
bool is_answer_event(EventKind kind);

// The start-up log's lines about the vehicle model and where the protocol settings come from
// (auto: identified before anything moves; forced; auto overridden by interpretation parameters,
// a warning).
std::vector<LogLine> describe_protocol_setup(const NodeParameters& params);
// A `sim/inject` line and what the virtual chassis said (sim::apply_chassis_command): applied
// (info), or not applied, why, and the valid commands (a warning).
LogLine describe_injection(const std::string& line, const Result<std::string>& said);

}  // namespace ranger
