#include "ranger_can/sim/frame_schedule.hpp"

#include "ranger_can/wire/protocol.hpp"

namespace ranger::sim {
namespace {

// The frames of a group share their manual period (the frame table).
constexpr bool same_period(std::initializer_list<std::uint32_t> ids) {
  for (const std::uint32_t id : ids) {
    if (protocol::frame_period_ms(id) != protocol::frame_period_ms(*ids.begin())) return false;
  }
  return protocol::frame_period_ms(*ids.begin()) > 0;
}
static_assert(same_period({protocol::kSystemStatusId, protocol::kMotionFeedbackId,
                           protocol::kMotorHighSpeedBaseId + 1, protocol::kSteeringAnglesId,
                           protocol::kWheelSpeedsId, protocol::kMotionModeFeedbackId,
                           protocol::kLightStateId, protocol::kRemoteControlStateId}));
static_assert(same_period({protocol::kUltrasonic1to4Id, protocol::kUltrasonic5to8Id}));
static_assert(same_period({protocol::kMotorLowSpeedBaseId + 1}));
static_assert(same_period({protocol::kBmsBaseId, protocol::kBmsBaseId + 1}));

}  // namespace

const std::array<FrameGroupRow, kFrameGroupCount> kFrameGroups = {{
    {FrameGroup::kFast, protocol::kSystemStatusId,
     "0x211 0x221 0x251-0x258 0x271 0x281 0x291; 0x231 0x241 (vendor frames); 0x311 0x312 "
     "(odometers)",
     20, "the topic contract, 0x211/0x291 stall table: 20.9 ms over 1,037,269 frames"},
    {FrameGroup::kUltrasonic, protocol::kUltrasonic1to4Id, "0x411 0x412", 0,
     "not observed (the MINI 3.0 sends no ultrasonic frames)"},
    {FrameGroup::kSlow, protocol::kMotorLowSpeedBaseId + 1, "0x261-0x268", 0, "not reported"},
    {FrameGroup::kBms, protocol::kBmsBaseId, "0x361 0x362 (battery slots 0x363-0x36A)", 250,
     "the topic contract, /battery_state: 87,555 frames of 0x361, about every 250 ms"},
}};

FrameRates manual_frame_rates() {
  FrameRates r;
  for (const FrameGroupRow& row : kFrameGroups) {
    r.period[static_cast<std::size_t>(row.group)] =
        std::chrono::milliseconds(protocol::frame_period_ms(row.first_id));
  }
  return r;
}

FrameRates field_frame_rates() {
  FrameRates r = manual_frame_rates();
  for (const FrameGroupRow& row : kFrameGroups) {
    if (row.field_period_ms > 0) {
      r.period[static_cast<std::size_t>(row.group)] =
          std::chrono::milliseconds(row.field_period_ms);
    }
  }
  return r;
}

}  // namespace ranger::sim
