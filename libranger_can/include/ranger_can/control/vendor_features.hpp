// What the vendor's revision adds to a chassis (agx_v2): the lights (0x121 command, 0x231 state),
// the remote control's switches and sticks (0x241) and the firmware version (0x4A1), as the
// driver keeps them (VendorFeatures, on the driver thread) and shows them in its snapshot.
//
// Whether the chassis has them is heard, not configured: present as soon as it sends 0x231 or
// 0x241, absent once it has been heard (0x211) for `frames_wait` without either. The version is
// asked once the chassis is known to have them and the driver speaks; a lights or version request
// waits until that is known, then goes out or fails naming the protocol.
#pragma once

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "ranger_can/control/feedback.hpp"
#include "ranger_can/result.hpp"
#include "ranger_can/text.hpp"
#include "ranger_can/types.hpp"
#include "ranger_can/wire/codec.hpp"
#include "ranger_can/wire/protocol.hpp"

namespace ranger {

class ChassisController;
class RequestBook;

// A 0x211 that arrives this soon after a request was sent may have left the chassis before the
// request reached it: the answer is the first one after this.
inline constexpr std::chrono::nanoseconds kRequestAnswerDelay =
    std::chrono::milliseconds(protocol::frame_period_ms(protocol::kSystemStatusId));

// Whether the chassis speaks the vendor's additions (0x231 light state, 0x241 remote state, 0x4A1
// version answers).
enum class VendorFrames {
  kUnknown,  // not heard long enough to tell
  kPresent,  // 0x231 or 0x241 received
  kAbsent,   // heard for DriverConfig::vendor_frames_wait without either
};
inline constexpr auto kVendorFramesNames = text::enum_names<VendorFrames>({
    {VendorFrames::kUnknown, "unknown"},
    {VendorFrames::kPresent, "present"},
    {VendorFrames::kAbsent, "absent"},
});
inline std::string_view to_string(VendorFrames v) {
  return kVendorFramesNames.name(v);
}

// The remote control's switches and sticks (0x241), sticks and knob normalised to -1..1
// (protocol::kRemoteAxisFullScale; saturated).
struct RemoteState {
  protocol::RemoteSwitch swa = protocol::RemoteSwitch::kUndefined;
  protocol::RemoteSwitch swb = protocol::RemoteSwitch::kUndefined;
  protocol::RemoteSwitch swc = protocol::RemoteSwitch::kUndefined;
  protocol::RemoteSwitch swd = protocol::RemoteSwitch::kUndefined;
  double left_vertical = 0.0;     // + forward
  double left_horizontal = 0.0;   // + right
  double right_vertical = 0.0;    // + forward
  double right_horizontal = 0.0;  // + right
  double knob = 0.0;              // VRA
  Timestamp received{0};          // driver clock
};
RemoteState remote_state_from(const RemoteControlState& rc, Timestamp received);

// The lights as 0x231 reports them.
struct LightsState {
  bool can_control = false;  // byte 0: the lights follow CAN (0x121) commands
  protocol::LightMode front = protocol::LightMode::kOff;
  std::uint8_t front_brightness = 0;  // custom mode's brightness, 0..100
  protocol::LightMode rear = protocol::LightMode::kOff;
  std::uint8_t rear_brightness = 0;
  Timestamp received{0};  // driver clock
};

// What set_lights asks for.
struct LightsRequest {
  protocol::LightMode front = protocol::LightMode::kOn;
  std::uint8_t front_brightness = 0;  // custom mode only: 0..100
  protocol::LightMode rear = protocol::LightMode::kOn;
  std::uint8_t rear_brightness = 0;
};
// A custom light brightness: 0..100 (%).
inline constexpr int kMaxLightBrightness = 100;
// The one check of a brightness (every front end's, the driver's): 0..kMaxLightBrightness, else
// kInvalidArgument "<side>_brightness 101 outside 0..100: nothing sent"; what is sent: the value
// in custom mode, 0 in any other.
Result<std::uint8_t> light_brightness(std::string_view side, protocol::LightMode mode,
                                      long long value);
// "front on, rear custom 40"
std::string describe(protocol::LightMode front, std::uint8_t front_brightness,
                     protocol::LightMode rear, std::uint8_t rear_brightness);
std::string describe(const LightsState& lights);
// The lights show what was asked for (a brightness counts in custom mode only).
bool lights_match(const LightsState& state, const LightsRequest& request);
// The same lights (modes, brightness where it counts, CAN control), whenever reported.
bool same_lights(const LightsState& a, const LightsState& b);

// The chassis's firmware version (0x4A1), asked once the chassis is heard speaking the vendor's
// revision.
struct FirmwareVersion {
  enum class State {
    kNotAsked,     // the chassis is not heard yet, or not long enough to tell
    kAsked,        // 0x4A1 request sent, the answer not complete
    kAnswered,     // `text` is the chassis's answer
    kUnanswered,   // no answer within request_answer_timeout
    kUnsupported,  // the chassis does not speak the vendor's revision (VendorFrames::kAbsent)
  };
  State state = State::kNotAsked;
  std::string text;  // the answer's frames, in order
};
inline constexpr auto kFirmwareStateNames = text::enum_names<FirmwareVersion::State>({
    {FirmwareVersion::State::kNotAsked, "not_asked"},
    {FirmwareVersion::State::kAsked, "asked"},
    {FirmwareVersion::State::kAnswered, "answered"},
    {FirmwareVersion::State::kUnanswered, "unanswered"},
    {FirmwareVersion::State::kUnsupported, "unsupported"},
});
inline std::string_view to_string(FirmwareVersion::State s) {
  return kFirmwareStateNames.name(s);
}

// A lights or version request the driver holds until it knows whether the chassis has the
// vendor's frames.
struct VendorAction {
  enum class Kind { kLights, kVersion } kind = Kind::kVersion;
  std::uint64_t id = 0;  // the request's (RequestBook)
  LightsRequest lights;
};

class VendorFeatures {
 public:
  // `frames_wait`: DriverConfig::vendor_frames_wait; `answer_timeout`: how long the version's
  // answer may take.
  VendorFeatures(std::chrono::nanoseconds frames_wait, std::chrono::nanoseconds answer_timeout)
      : frames_wait_(frames_wait), answer_timeout_(answer_timeout) {}

  // Every decoded message (0x211 starts the vendor frames' wait; 0x4A1 answers the version).
  void on_message(const Message& message, Timestamp now);
  // A lights or version request: applied once the vendor frames are known (update()).
  void post(const VendorAction& action) { deferred_.push_back(action); }
  // Before the controller's tick: the chassis's reports (remote, lights, presence), the version
  // (asked once when `may_send`; `revision` names the protocol in a refusal), then the waiting
  // requests, whose outcomes go to `book`.
  void update(Timestamp now, ChassisController& controller, bool may_send,
              const std::string& revision, RequestBook& book);

  VendorFrames frames() const { return frames_; }
  const std::optional<RemoteState>& remote() const { return remote_; }
  const std::optional<LightsState>& lights() const { return lights_; }
  const FirmwareVersion& firmware() const { return firmware_; }

 private:
  void take_reports(Timestamp now, const ChassisFeedback& fb);
  void track_version(Timestamp now, ChassisController& controller, bool may_send);
  // Applies a lights or version request; false while the vendor frames are not known yet.
  bool apply(const VendorAction& a, Timestamp now, ChassisController& controller,
             const std::string& revision, RequestBook& book);

  std::chrono::nanoseconds frames_wait_;
  std::chrono::nanoseconds answer_timeout_;
  std::optional<Timestamp> first_status_;  // first 0x211 (frames_wait counts from it)
  VendorFrames frames_ = VendorFrames::kUnknown;
  std::optional<RemoteState> remote_;
  std::optional<LightsState> lights_;
  FirmwareVersion firmware_;
  Timestamp version_asked_{0};
  Timestamp last_version_frame_{0};
  std::vector<VendorAction> deferred_;  // waiting for frames_ to be known
};

}  // namespace ranger
