// Received-frame statistics per CAN ID: counts (decoded, rejected, longer than their layout) and
// the rate over a sliding window. What the driver's diagnostics and `ranger_can monitor` show;
// O(1) per frame, no allocation after an ID was first seen.
#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <vector>

#include "ranger_can/types.hpp"

namespace ranger {

struct FrameIdCounts {
  std::uint32_t id = 0;
  std::uint64_t frames = 0;    // every data frame with this ID
  std::uint64_t rejected = 0;  // the codec refused it (short, impossible content)
  std::uint64_t padded = 0;    // longer than its layout: decoded from the leading bytes
};

class FrameStats {
 public:
  // Rates average over the last `window` (ten whole buckets of a tenth of it) plus the part of the
  // current bucket that has passed.
  explicit FrameStats(std::chrono::nanoseconds window = std::chrono::seconds(1));

  // One received data frame of `id` (11-bit) at `now`. Returns true when this is the first frame
  // of `id` longer than its layout (so the owner can report padding once per ID).
  bool record(std::uint32_t id, Timestamp now, bool decoded, int extra_bytes);

  // Frames per second of `id` over the window ending at `now` (0 for an unseen ID).
  double rate(std::uint32_t id, Timestamp now) const;
  // Every ID seen, ascending.
  std::vector<FrameIdCounts> counts() const;
  std::uint64_t total() const { return total_; }
  std::chrono::nanoseconds window() const { return window_; }

 private:
  static constexpr int kBuckets = 10;
  struct Entry {
    FrameIdCounts counts;
    std::array<std::uint32_t, kBuckets + 1> buckets{};  // ten whole ones and the current one
    std::int64_t last_bucket = 0;                       // absolute bucket index of the newest count
  };
  // Bucket k holds the frames of (k b, (k+1) b]: a frame at `now` is in the current bucket, the
  // one exactly a window ago is not (a steady stream then counts exactly window / period).
  std::int64_t bucket_of(Timestamp t) const { return (t.count() - 1) / bucket_.count(); }

  std::chrono::nanoseconds window_;
  std::chrono::nanoseconds bucket_;
  std::array<std::int16_t, 0x800> index_;  // 11-bit ID -> entries_ index, -1 = unseen
  std::vector<Entry> entries_;
  std::uint64_t total_ = 0;
};

}  // namespace ranger
