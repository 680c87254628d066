#include "ranger_can/control/frame_stats.hpp"

#include <algorithm>

namespace ranger {

FrameStats::FrameStats(std::chrono::nanoseconds window)
    : window_(window.count() > 0 ? window : std::chrono::seconds(1)), bucket_(window_ / kBuckets) {
  if (bucket_.count() <= 0) bucket_ = std::chrono::nanoseconds(1);
  index_.fill(-1);
}

bool FrameStats::record(std::uint32_t id, Timestamp now, bool decoded, int extra_bytes) {
  ++total_;
  const std::size_t key = id & 0x7FFu;
  if (index_[key] < 0) {
    index_[key] = static_cast<std::int16_t>(entries_.size());
    Entry e;
    e.counts.id = id & 0x7FFu;
    e.last_bucket = bucket_of(now);
    entries_.push_back(e);
  }
  Entry& e = entries_[static_cast<std::size_t>(index_[key])];
  const std::int64_t b = bucket_of(now);
  if (b > e.last_bucket) {
    // Empty the buckets that passed without a frame (all of them after a long silence).
    const std::int64_t passed = std::min<std::int64_t>(b - e.last_bucket, kBuckets + 1);
    for (std::int64_t k = 1; k <= passed; ++k) {
      e.buckets[static_cast<std::size_t>((e.last_bucket + k) % (kBuckets + 1))] = 0;
    }
    e.last_bucket = b;
  }
  ++e.buckets[static_cast<std::size_t>(e.last_bucket % (kBuckets + 1))];
  ++e.counts.frames;
  if (!decoded) ++e.counts.rejected;
  if (extra_bytes > 0) {
    ++e.counts.padded;
    return e.counts.padded == 1;
  }
  return false;
}

double FrameStats::rate(std::uint32_t id, Timestamp now) const {
  const std::int16_t i = index_[id & 0x7FFu];
  if (i < 0) return 0.0;
  const Entry& e = entries_[static_cast<std::size_t>(i)];
  const std::int64_t newest = bucket_of(now);
  // Buckets newest-kBuckets .. newest-1 are whole, `newest` has run for `partial` (in (0, b]);
  // older counts have expired. The counts cover exactly kBuckets b + partial.
  std::uint64_t sum = 0;
  for (std::int64_t b = std::max(e.last_bucket - kBuckets, newest - kBuckets);
       b <= std::min(e.last_bucket, newest); ++b) {
    sum += e.buckets[static_cast<std::size_t>(b % (kBuckets + 1))];
  }
  const auto partial = now - Timestamp(newest * bucket_.count());
  return static_cast<double>(sum) / seconds(bucket_ * kBuckets + partial);
}

std::vector<FrameIdCounts> FrameStats::counts() const {
  std::vector<FrameIdCounts> out;
  out.reserve(entries_.size());
  for (const Entry& e : entries_)
    out.push_back(e.counts);
  std::sort(out.begin(), out.end(),
            [](const FrameIdCounts& a, const FrameIdCounts& b) { return a.id < b.id; });
  return out;
}

}  // namespace ranger
