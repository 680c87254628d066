// The driver's request book: every request posted through its mailbox (clear-errors, ultrasonic,
// resume, lights, park, the firmware version) with its outcome, for the snapshot and the events.
//
// Callers add a request on their own thread (add); the driver thread records what became of it
// when the mailbox was applied (applied) and settles what was sent against the chassis's feedback
// after every tick (settle). Settling is one loop over the book and one rule per request kind,
// looked up in a table: a rule reads the request and what the chassis reports now, and says
// whether it is answered or failed, with the words for it. Thread-safe (one short lock).
#pragma once

#include <chrono>
#include <cstdint>
#include <deque>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "ranger_can/control/controller.hpp"
#include "ranger_can/control/feedback.hpp"
#include "ranger_can/control/vendor_features.hpp"
#include "ranger_can/result.hpp"
#include "ranger_can/text.hpp"
#include "ranger_can/types.hpp"
#include "ranger_can/wire/profile.hpp"

namespace ranger {

// What became of a request posted through the mailbox.
struct RequestOutcome {
  enum class Kind { kClearErrors, kUltrasonic, kResume, kLights, kPark, kFirmwareVersion };
  enum class State { kPending, kSent, kAnswered, kFailed };
  std::uint64_t id = 0;
  Kind kind = Kind::kResume;
  bool on = false;   // kUltrasonic, kPark: on (true) or off
  std::string what;  // for people: "clear_errors 0x00", "ultrasonic on", "lights front on, ..."
  State state = State::kPending;
  std::string message;  // why it failed, or what the answer was
  // clear_errors: the 0x211 error word the chassis reported after it received the 0x441.
  std::optional<std::uint32_t> error_word;
  Timestamp sent{0};  // driver clock

  bool settled() const { return state == State::kAnswered || state == State::kFailed; }
};
inline constexpr auto kRequestKindNames = text::enum_names<RequestOutcome::Kind>({
    {RequestOutcome::Kind::kClearErrors, "clear_errors"},
    {RequestOutcome::Kind::kUltrasonic, "ultrasonic"},
    {RequestOutcome::Kind::kResume, "resume"},
    {RequestOutcome::Kind::kLights, "lights"},
    {RequestOutcome::Kind::kPark, "park"},
    {RequestOutcome::Kind::kFirmwareVersion, "firmware_version"},
});
inline constexpr auto kRequestStateNames = text::enum_names<RequestOutcome::State>({
    {RequestOutcome::State::kPending, "pending"},
    {RequestOutcome::State::kSent, "sent"},
    {RequestOutcome::State::kAnswered, "answered"},
    {RequestOutcome::State::kFailed, "failed"},
});
inline std::string_view to_string(RequestOutcome::Kind k) {
  return kRequestKindNames.name(k);
}
inline std::string_view to_string(RequestOutcome::State s) {
  return kRequestStateNames.name(s);
}

// The timing a settle rule judges by (the driver's configuration).
struct RequestTiming {
  std::chrono::nanoseconds answer_timeout{std::chrono::milliseconds(500)};
  // How long a park switch may take: the controller's switch attempts and the answer timeout.
  std::chrono::nanoseconds park_timeout{std::chrono::milliseconds(5000)};
};

// What the chassis reports now, for the settle rules.
struct RequestEvidence {
  Timestamp now{0};
  const ControllerState* controller = nullptr;
  const ChassisFeedback* feedback = nullptr;
  const std::optional<LightsState>* lights = nullptr;
  const FirmwareVersion* firmware = nullptr;
  ErrorWordLayout error_word = ErrorWordLayout::kManual32;
};

class RequestBook {
 public:
  static constexpr std::size_t kCapacity = 16;  // the most recent requests are kept

  explicit RequestBook(RequestTiming timing = {}) : timing_(timing) {}

  // Records a new request (`what` says it for people; `lights`: what a lights request asks for);
  // returns its id (1, 2, ...).
  std::uint64_t add(RequestOutcome::Kind kind, std::string what, bool on = false,
                    const LightsRequest& lights = {});
  // The driver applied request `id` at `now`: sent (or failed with the status's message). A
  // resume that went through is answered at once ("re-armed").
  void applied(std::uint64_t id, Timestamp now, const Status& status);
  // Settles the sent requests against the evidence: one loop, one rule per kind (a table).
  void settle(const RequestEvidence& evidence);
  // The requests that settled (answered or failed) since the last call, in the order they did.
  std::vector<RequestOutcome> take_settled();

  // Copies of every request, oldest first (into a snapshot).
  void copy_to(std::vector<RequestOutcome>& out) const;

 private:
  struct Entry {
    RequestOutcome outcome;
    LightsRequest lights;  // kLights: what was asked for
  };
  RequestTiming timing_;
  mutable std::mutex mutex_;
  std::deque<Entry> entries_;
  std::vector<RequestOutcome> settled_;  // since take_settled()
  std::uint64_t next_id_ = 1;
};

}  // namespace ranger
