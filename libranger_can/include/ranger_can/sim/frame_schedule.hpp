// The virtual chassis's frame-rate schedule: which feedback frames it sends, in which groups, at
// which period, per chassis. One part of the virtual chassis (virtual_chassis.hpp owns the time
// and sends each group when it falls due; which frames of a group a chassis has is its profile's
// frame layout).
//
// The table (kFrameGroups) names every group, its frames, the manual's period (the frame table of
// wire/protocol.hpp, which the DBC files and the driver's freshness follow) and the period a real
// RANGER MINI 3.0 showed (field notes of zeroworks-robotics/ranger_ros2, docs/, the topic
// contract of 2026-09-10: docs/FIELD_FACTS.md):
//
// clang-format off
//   group       frames                                     manual   field (MINI 3.0)
//   fast        0x211 0x221 0x251.. 0x271 0x281 0x291       20 ms    20 ms (20.9 measured)
//               0x231 0x241 (vendor) 0x311 0x312 (odometers)
//   ultrasonic  0x411 0x412                                 50 ms    none (no ultrasonic)
//   slow        0x261..                                    100 ms    not reported: the manual's
//   bms         0x361 0x362 (and the slots 0x363..)        500 ms    250 ms (87,555 frames)
// clang-format on
//
// A chassis runs one column (FrameRates): the manual's by default, the field's for the MINI 3.0
// (sim:mini_v3, --model ranger_mini_v3); the variant mini_v3_manual keeps the manual's.
#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <string_view>

#include "ranger_can/text.hpp"

namespace ranger::sim {

enum class FrameGroup { kFast, kUltrasonic, kSlow, kBms };
inline constexpr std::size_t kFrameGroupCount = 4;
inline constexpr auto kFrameGroupNames = text::enum_names<FrameGroup>({
    {FrameGroup::kFast, "fast"},
    {FrameGroup::kUltrasonic, "ultrasonic"},
    {FrameGroup::kSlow, "slow"},
    {FrameGroup::kBms, "bms"},
});
inline std::string_view to_string(FrameGroup g) {
  return kFrameGroupNames.name(g);
}

struct FrameGroupRow {
  FrameGroup group;
  std::uint32_t first_id;         // the group's first frame (its manual period is this frame's)
  std::string_view frames;        // every frame of the group, for people
  int field_period_ms;            // what a real RANGER MINI 3.0 showed; 0: not observed
  std::string_view field_source;  // where the notes say so
};

// The table, one row per group in FrameGroup's order.
extern const std::array<FrameGroupRow, kFrameGroupCount> kFrameGroups;

// The period of each group a chassis sends at.
struct FrameRates {
  std::array<std::chrono::nanoseconds, kFrameGroupCount> period{};
  std::chrono::nanoseconds of(FrameGroup g) const { return period[static_cast<std::size_t>(g)]; }
};

// The manual's column (the frame table of wire/protocol.hpp).
FrameRates manual_frame_rates();
// The field's column: the manual's where the field observed nothing.
FrameRates field_frame_rates();

}  // namespace ranger::sim
