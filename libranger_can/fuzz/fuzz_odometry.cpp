// Fuzzes the odometry with arbitrary feedback sequences (0x221, 0x271, 0x281, 0x291 with any
// bytes, plus foreign frames) and hostile timestamps: repeated, backwards, jumping, zero, and
// anywhere in the +-2^62 ns range a bus or a candump log can produce.
//
// Properties (each a FUZZ_CHECK): no undefined behaviour (UBSan), and after every frame the pose,
// twist, covariances and travelled distance are finite; the yaw is normalised to (-pi, pi];
// variances and distance never decrease; a frame reported as integrated counted one step.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>

#include "fuzz_input.hpp"
#include "ranger_can/control/odometry.hpp"
#include "ranger_can/wire/protocol.hpp"

namespace {

namespace protocol = ranger::protocol;
using ranger::CanFrame;

constexpr std::int64_t kStampLimit = (std::int64_t{1} << 62) - 1;  // candump_log.cpp bound
const bool kTrace = std::getenv("RANGER_FUZZ_TRACE") != nullptr;

bool finite3(const std::array<double, 3>& a) {
  return std::isfinite(a[0]) && std::isfinite(a[1]) && std::isfinite(a[2]);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzedDataProvider in(data, size);
  ranger::OdometryConfig config;
  config.source =
      in.ConsumeBool() ? ranger::OdometrySource::kWheels : ranger::OdometrySource::kMotion;
  ranger::Odometry odometry(config);

  std::int64_t stamp = in.ConsumeIntegralInRange<std::int64_t>(-kStampLimit, kStampLimit);
  ranger::OdometryState previous = odometry.state();
  while (in.remaining_bytes() > 0) {
    CanFrame f;
    static constexpr std::uint32_t kIds[] = {
        protocol::kMotionFeedbackId, protocol::kSteeringAnglesId, protocol::kWheelSpeedsId,
        protocol::kMotionModeFeedbackId, protocol::kSystemStatusId};
    f.id = kIds[in.ConsumeIntegralInRange<std::size_t>(0, 4)];
    const int dlc = protocol::layout_dlc(f.id);
    f.dlc = in.ConsumeIntegralInRange<int>(0, 15) == 0
                ? in.ConsumeIntegralInRange<std::uint8_t>(0, 8)
                : static_cast<std::uint8_t>(dlc);
    for (std::size_t i = 0; i < f.dlc; ++i)
      f.data[i] = in.ConsumeIntegral<std::uint8_t>();
    if (f.id == protocol::kMotionModeFeedbackId && in.ConsumeBool()) f.data[0] %= 3;

    switch (in.ConsumeIntegralInRange<int>(0, 7)) {
      case 0:
        break;  // same instant
      case 1:
        stamp = in.ConsumeIntegralInRange<std::int64_t>(-kStampLimit, kStampLimit);
        break;
      case 2:
        stamp = 0;
        break;  // "unknown"
      case 3:
        stamp -= in.ConsumeIntegralInRange<std::int64_t>(0, 1000000000);
        break;
      default:
        stamp += in.ConsumeIntegralInRange<std::int64_t>(0, 600000000);
        break;
    }
    stamp = std::clamp(stamp, -kStampLimit, kStampLimit);
    f.stamp = ranger::Timestamp{stamp};

    const bool advanced = odometry.on_frame(f);
    const ranger::OdometryState& s = odometry.state();
    if (kTrace) {  // RANGER_FUZZ_TRACE=1: what happened, for reading a reproducer
      std::fprintf(stderr, "%lld %03X [%d]", static_cast<long long>(stamp), f.id, f.dlc);
      for (std::size_t i = 0; i < f.dlc; ++i)
        std::fprintf(stderr, " %02X", f.data[i]);
      std::fprintf(stderr, " -> twist %g %g %g pose %g %g %g\n", s.twist.vx, s.twist.vy, s.twist.wz,
                   s.pose.x, s.pose.y, s.pose.yaw);
    }
    FUZZ_CHECK(std::isfinite(s.pose.x) && std::isfinite(s.pose.y) && std::isfinite(s.pose.yaw));
    FUZZ_CHECK(s.pose.yaw > -M_PI && s.pose.yaw <= M_PI);
    FUZZ_CHECK(std::isfinite(s.twist.vx) && std::isfinite(s.twist.vy) && std::isfinite(s.twist.wz));
    FUZZ_CHECK(finite3(s.pose_variance) && finite3(s.twist_variance));
    for (int i = 0; i < 3; ++i)
      FUZZ_CHECK(s.pose_variance[i] >= previous.pose_variance[i]);
    FUZZ_CHECK(std::isfinite(s.distance) && s.distance >= previous.distance);
    FUZZ_CHECK(s.steps == previous.steps + (advanced ? 1 : 0));
    previous = s;
  }
  return 0;
}
