#include "ranger_can/control/vendor_features.hpp"

#include <algorithm>
#include <utility>
#include <variant>

#include "ranger_can/control/controller.hpp"
#include "ranger_can/control/request_book.hpp"

namespace ranger {
namespace {

double axis(std::int8_t raw) {
  return std::clamp(raw / protocol::kRemoteAxisFullScale, -1.0, 1.0);
}

std::string light_text(protocol::LightMode mode, std::uint8_t brightness) {
  std::string out(protocol::to_string(mode));
  if (mode == protocol::LightMode::kCustom) out += " " + std::to_string(brightness);
  return out;
}

bool same_light(protocol::LightMode m1, std::uint8_t b1, protocol::LightMode m2, std::uint8_t b2) {
  return m1 == m2 && (m1 != protocol::LightMode::kCustom || b1 == b2);
}

}  // namespace

RemoteState remote_state_from(const RemoteControlState& rc, Timestamp received) {
  RemoteState r;
  r.swa = rc.swa;
  r.swb = rc.swb;
  r.swc = rc.swc;
  r.swd = rc.swd;
  r.left_vertical = axis(rc.stick_left_v);
  r.left_horizontal = axis(rc.stick_left_h);
  r.right_vertical = axis(rc.stick_right_v);
  r.right_horizontal = axis(rc.stick_right_h);
  r.knob = axis(rc.var_a);
  r.received = received;
  return r;
}

Result<std::uint8_t> light_brightness(std::string_view side, protocol::LightMode mode,
                                      long long value) {
  if (value < 0 || value > kMaxLightBrightness) {
    return Error{Errc::kInvalidArgument,
                 std::string(side) + "_brightness " + std::to_string(value) + " outside 0.." +
                     std::to_string(kMaxLightBrightness) + ": nothing sent"};
  }
  return static_cast<std::uint8_t>(mode == protocol::LightMode::kCustom ? value : 0);
}

std::string describe(protocol::LightMode front, std::uint8_t front_brightness,
                     protocol::LightMode rear, std::uint8_t rear_brightness) {
  return "front " + light_text(front, front_brightness) + ", rear " +
         light_text(rear, rear_brightness);
}

std::string describe(const LightsState& l) {
  return describe(l.front, l.front_brightness, l.rear, l.rear_brightness);
}

bool lights_match(const LightsState& s, const LightsRequest& r) {
  return same_light(s.front, s.front_brightness, r.front, r.front_brightness) &&
         same_light(s.rear, s.rear_brightness, r.rear, r.rear_brightness);
}

bool same_lights(const LightsState& a, const LightsState& b) {
  return a.can_control == b.can_control &&
         same_light(a.front, a.front_brightness, b.front, b.front_brightness) &&
         same_light(a.rear, a.rear_brightness, b.rear, b.rear_brightness);
}

void VendorFeatures::on_message(const Message& message, Timestamp now) {
  if (std::holds_alternative<SystemStatus>(message) && !first_status_) first_status_ = now;
  if (std::holds_alternative<VersionResponse>(message)) last_version_frame_ = now;
}

void VendorFeatures::update(Timestamp now, ChassisController& controller, bool may_send,
                            const std::string& revision, RequestBook& book) {
  take_reports(now, controller.feedback());
  track_version(now, controller, may_send);
  std::vector<VendorAction> waiting;
  for (const VendorAction& a : deferred_) {
    if (!apply(a, now, controller, revision, book)) waiting.push_back(a);
  }
  deferred_.swap(waiting);
}

void VendorFeatures::take_reports(Timestamp now, const ChassisFeedback& fb) {
  if (fb.remote_control_state) {
    remote_ = remote_state_from(fb.remote_control_state->value, fb.remote_control_state->received);
  }
  if (fb.light_state) {
    const LightState& l = fb.light_state->value;
    lights_ = LightsState{l.enable,    l.front_mode,  l.front_custom,
                          l.rear_mode, l.rear_custom, fb.light_state->received};
  }
  if (fb.light_state || fb.remote_control_state) {
    frames_ = VendorFrames::kPresent;
  } else if (first_status_ && now - *first_status_ >= frames_wait_) {
    frames_ = VendorFrames::kAbsent;
  }
}

void VendorFeatures::track_version(Timestamp now, ChassisController& controller, bool may_send) {
  using VS = FirmwareVersion::State;
  const std::string& answer = controller.feedback().version;
  // Asked once the chassis is heard speaking the vendor's revision, and we speak.
  if (firmware_.state == VS::kNotAsked && frames_ == VendorFrames::kAbsent) {
    firmware_.state = VS::kUnsupported;
  } else if (firmware_.state == VS::kNotAsked && frames_ == VendorFrames::kPresent && may_send &&
             controller.request_version(now)) {
    firmware_.state = VS::kAsked;
    version_asked_ = now;
  }
  const bool complete = !answer.empty() && now - last_version_frame_ >= kRequestAnswerDelay;
  if (firmware_.state == VS::kAsked) {
    firmware_.text = answer;
    if (complete) {
      firmware_.state = VS::kAnswered;
    } else if (answer.empty() && now - version_asked_ > answer_timeout_) {
      firmware_.state = VS::kUnanswered;
    }
  } else if (!answer.empty()) {
    // A replayed log answers nothing, but may hold the answers of the session it recorded.
    firmware_.text = answer;
    if (complete) firmware_.state = VS::kAnswered;
  }
}

bool VendorFeatures::apply(const VendorAction& a, Timestamp now, ChassisController& controller,
                           const std::string& revision, RequestBook& book) {
  if (frames_ == VendorFrames::kUnknown) return false;
  Status st = ok_status();
  if (frames_ == VendorFrames::kAbsent) {
    st = Error{Errc::kInvalidArgument,
               std::string(a.kind == VendorAction::Kind::kLights ? "lights" : "firmware version") +
                   ": unsupported by protocol " + revision +
                   ": the chassis sends none of the vendor's frames (0x231 light state, 0x241 "
                   "remote state)"};
  } else if (a.kind == VendorAction::Kind::kLights) {
    LightCommand c;
    c.enable = true;
    c.front_mode = a.lights.front;
    c.front_custom = a.lights.front_brightness;
    c.rear_mode = a.lights.rear;
    c.rear_custom = a.lights.rear_brightness;
    st = controller.set_lights(c, now);
  } else {
    st = controller.request_version(now);
    if (st) {
      firmware_ = FirmwareVersion{FirmwareVersion::State::kAsked, ""};
      version_asked_ = now;
    }
  }
  book.applied(a.id, now, st);
  return true;
}

}  // namespace ranger
