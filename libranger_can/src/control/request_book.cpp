#include "ranger_can/control/request_book.hpp"

#include <utility>

#include "ranger_can/text.hpp"
#include "ranger_can/wire/protocol.hpp"

namespace ranger {
namespace {

using State = RequestOutcome::State;
using Kind = RequestOutcome::Kind;

// A settle rule's word on a sent request: answered or failed, and why.
struct Verdict {
  State state;
  std::string message;
  std::optional<std::uint32_t> error_word;
};
using Rule = std::optional<Verdict> (*)(const RequestOutcome& r, const LightsRequest& lights,
                                        const RequestEvidence& e, const RequestTiming& t);

std::string within(std::chrono::nanoseconds d) {
  return std::to_string(seconds(d)) + " s";
}

std::optional<Verdict> settle_clear_errors(const RequestOutcome& r, const LightsRequest&,
                                           const RequestEvidence& e, const RequestTiming& t) {
  const auto& status = e.feedback->system_status;
  if (status && status->received >= r.sent + kRequestAnswerDelay) {
    const std::uint32_t word = e.controller->error_bits;
    const auto names = protocol::error_bit_names(word, e.error_word);
    return Verdict{State::kAnswered,
                   names.empty() ? std::string("the chassis reports no error")
                                 : "the chassis still reports: " + text::join(names),
                   word};
  }
  if (e.now - r.sent > t.answer_timeout) {
    return Verdict{State::kFailed,
                   "the chassis did not answer (no 0x211) within " + within(t.answer_timeout),
                   std::nullopt};
  }
  return std::nullopt;
}

std::optional<Verdict> settle_lights(const RequestOutcome& r, const LightsRequest& asked,
                                     const RequestEvidence& e, const RequestTiming& t) {
  const std::optional<LightsState>& lights = *e.lights;
  const bool fresh = lights && lights->received >= r.sent + kRequestAnswerDelay;
  if (fresh && lights_match(*lights, asked)) {
    return Verdict{State::kAnswered, "the chassis reports " + describe(*lights), std::nullopt};
  }
  if (e.now - r.sent <= t.answer_timeout) return std::nullopt;
  if (!fresh) {
    return Verdict{
        State::kFailed,
        "the chassis did not report its lights (no 0x231) within " + within(t.answer_timeout),
        std::nullopt};
  }
  const bool remote = e.controller->control_mode == protocol::ControlMode::kRemote;
  return Verdict{State::kFailed,
                 "the chassis reports " + describe(*lights) +
                     (remote ? " (the remote control has the chassis)" : ""),
                 std::nullopt};
}

std::optional<Verdict> settle_park(const RequestOutcome& r, const LightsRequest&,
                                   const RequestEvidence& e, const RequestTiming& t) {
  const ControllerState& c = *e.controller;
  const bool late = e.now - r.sent > t.park_timeout;
  // The switch into park, or out of it, is done when the driver's switch is (mode_switch.hpp: the
  // wheels at the new mode's angles, or the chassis's switch time), never on 0x291 alone: a chassis
  // reporting the new mode at once (the field's MINI 3.0) still turns its wheels.
  const bool switch_done = c.mode_switch.phase == ModeSwitchPhase::kIdle;
  if (r.on && c.parked() && switch_done) {
    return Verdict{State::kAnswered,
                   "parked (0x291 reports park): motion is refused until park is released",
                   std::nullopt};
  }
  if (r.on && !c.park_requested) {
    return Verdict{State::kFailed, "park was released before the chassis reported it",
                   std::nullopt};
  }
  if (r.on && late) {
    const std::string why = c.refusal != MotionRefusal::kParked
                                ? " (" + std::string(to_string(c.refusal)) + ")"
                                : std::string();
    return Verdict{State::kFailed,
                   "the chassis did not report park (0x291) within " + within(t.park_timeout) + why,
                   std::nullopt};
  }
  if (r.on) return std::nullopt;
  if (c.park_requested) return Verdict{State::kFailed, "park was requested again", std::nullopt};
  if (c.chassis_mode != protocol::MotionMode::kPark && switch_done) {
    return Verdict{State::kAnswered, "park released: motion allowed", std::nullopt};
  }
  if (late) {
    return Verdict{State::kAnswered,
                   "park released: motion allowed (the chassis still reports park; the next "
                   "motion switches it out)",
                   std::nullopt};
  }
  return std::nullopt;
}

std::optional<Verdict> settle_firmware(const RequestOutcome&, const LightsRequest&,
                                       const RequestEvidence& e, const RequestTiming& t) {
  if (e.firmware->state == FirmwareVersion::State::kAnswered) {
    return Verdict{State::kAnswered, e.firmware->text, std::nullopt};
  }
  if (e.firmware->state == FirmwareVersion::State::kUnanswered) {
    return Verdict{
        State::kFailed,
        "the chassis did not answer the version request (0x4A1) within " + within(t.answer_timeout),
        std::nullopt};
  }
  return std::nullopt;
}

std::optional<Verdict> settle_ultrasonic(const RequestOutcome& r, const LightsRequest&,
                                         const RequestEvidence& e, const RequestTiming&) {
  const ControllerState& c = *e.controller;
  if (c.ultrasonic_failed) {
    return Verdict{State::kFailed, "the chassis did not confirm the ultrasonic setting (0x45A)",
                   std::nullopt};
  }
  if (!c.ultrasonic_requested && c.ultrasonic_enabled == r.on) {
    return Verdict{State::kAnswered,
                   std::string("ultrasonic avoidance ") + (r.on ? "enabled" : "disabled") +
                       " (confirmed by the chassis)",
                   std::nullopt};
  }
  return std::nullopt;
}

std::optional<Verdict> settle_drive_mode(const RequestOutcome& r, const LightsRequest&,
                                         const RequestEvidence& e, const RequestTiming& t) {
  const auto& mode = e.feedback->motion_mode;
  const bool fresh = mode && mode->received >= r.sent + kRequestAnswerDelay;
  const auto reported = fresh && mode->value.drive_mode
                            ? protocol::drive_mode_from_wire(*mode->value.drive_mode)
                            : std::nullopt;
  if (reported && reported == r.drive_mode) {
    return Verdict{State::kAnswered,
                   "the chassis reports drive mode " + std::string(protocol::to_string(*reported)),
                   std::nullopt};
  }
  if (e.now - r.sent <= t.answer_timeout) return std::nullopt;
  return Verdict{
      State::kFailed,
      reported ? "the chassis reports drive mode " + std::string(protocol::to_string(*reported))
               : "the chassis did not report a drive mode (0x291 byte 2) within " +
                     within(t.answer_timeout),
      std::nullopt};
}

// One rule per kind, in the order of RequestOutcome::Kind (resume is answered when applied).
constexpr Rule kRules[] = {
    settle_clear_errors,  // kClearErrors
    settle_ultrasonic,    // kUltrasonic
    nullptr,              // kResume
    settle_lights,        // kLights
    settle_park,          // kPark
    settle_firmware,      // kFirmwareVersion
    settle_drive_mode,    // kDriveMode
};

}  // namespace

std::uint64_t RequestBook::add(RequestOutcome::Kind kind, std::string what, bool on,
                               const LightsRequest& lights,
                               std::optional<protocol::DriveMode> drive_mode) {
  std::lock_guard<std::mutex> lock(mutex_);
  Entry e;
  e.outcome.id = next_id_++;
  e.outcome.kind = kind;
  e.outcome.on = on;
  e.outcome.what = std::move(what);
  e.outcome.drive_mode = drive_mode;
  e.lights = lights;
  entries_.push_back(std::move(e));
  while (entries_.size() > kCapacity)
    entries_.pop_front();
  return entries_.back().outcome.id;
}

void RequestBook::applied(std::uint64_t id, Timestamp now, const Status& status) {
  std::lock_guard<std::mutex> lock(mutex_);
  for (Entry& e : entries_) {
    RequestOutcome& r = e.outcome;
    if (r.id != id) continue;
    r.sent = now;
    if (!status) {
      r.state = State::kFailed;
      r.message = status.error().message;
    } else if (r.kind == Kind::kResume) {
      r.state = State::kAnswered;
      r.message = "re-armed";
    } else {
      r.state = State::kSent;
    }
    if (r.settled()) settled_.push_back(r);
  }
}

void RequestBook::settle(const RequestEvidence& evidence) {
  std::lock_guard<std::mutex> lock(mutex_);
  for (Entry& e : entries_) {
    RequestOutcome& r = e.outcome;
    const Rule rule = kRules[static_cast<std::size_t>(r.kind)];
    if (r.state != State::kSent || rule == nullptr) continue;
    std::optional<Verdict> v = rule(r, e.lights, evidence, timing_);
    if (!v) continue;
    r.state = v->state;
    r.message = std::move(v->message);
    if (v->error_word) r.error_word = v->error_word;
    settled_.push_back(r);
  }
}

std::vector<RequestOutcome> RequestBook::take_settled() {
  std::vector<RequestOutcome> out;
  std::lock_guard<std::mutex> lock(mutex_);
  out.swap(settled_);
  return out;
}

void RequestBook::copy_to(std::vector<RequestOutcome>& out) const {
  std::lock_guard<std::mutex> lock(mutex_);
  out.clear();
  for (const Entry& e : entries_)
    out.push_back(e.outcome);
}

}  // namespace ranger
