#include "ranger_can/wire/interpretation.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <vector>

namespace ranger::interpretation {

double ackermann_curvature_from_mean_angle(double mean_angle, double wheelbase_m, double track_m) {
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  const bool geometry_ok =
      std::isfinite(wheelbase_m) && wheelbase_m > 0.0 && std::isfinite(track_m) && track_m > 0.0;
  if (!geometry_ok || std::isnan(mean_angle)) return kNaN;
  if (mean_angle == 0.0) return 0.0;
  const double m = std::fabs(mean_angle);
  if (m >= M_PI / 2.0) return std::copysign(std::numeric_limits<double>::infinity(), mean_angle);

  // tan(alpha + beta) = L k / (1 - D k^2) with D = (L/2)^2 + (W/2)^2 and alpha + beta = 2m in
  // (0, pi), so sin(2m) > 0 and the curvature is the positive root of
  //   D s k^2 + (L/2) 2 c k - s = 0,   s = sin 2m, c = cos 2m.
  const double half_l = wheelbase_m / 2.0;
  const double half_w = track_m / 2.0;
  const double d = half_l * half_l + half_w * half_w;
  const double s = std::sin(2.0 * m);
  const double c = std::cos(2.0 * m);
  const double root = std::sqrt(half_l * half_l * c * c + d * s * s);
  // (root - h c) / (D s) loses precision when h c is close to root (c > 0, small angles); the
  // equal form s / (root + h c) does not. Both are finite and positive in their branch.
  const double k = c > 0.0 ? s / (root + half_l * c) : (root - half_l * c) / (d * s);
  return std::copysign(k, mean_angle);
}

double ackermann_curvature_from_inner_angle(double inner_angle, double wheelbase_m,
                                            double track_m) {
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  const bool geometry_ok =
      std::isfinite(wheelbase_m) && wheelbase_m > 0.0 && std::isfinite(track_m) && track_m > 0.0;
  if (!geometry_ok || std::isnan(inner_angle)) return kNaN;
  if (inner_angle == 0.0) return 0.0;
  const double a = std::fabs(inner_angle);
  const double half_l = wheelbase_m / 2.0;
  const double half_w = track_m / 2.0;
  // The angle at |k| = inf; the denominator below is positive exactly below it.
  if (a >= std::atan2(half_l, -half_w)) {
    return std::copysign(std::numeric_limits<double>::infinity(), inner_angle);
  }
  return std::copysign(std::sin(a) / (half_l * std::cos(a) + half_w * std::sin(a)), inner_angle);
}

const std::vector<protocol::Fault>& critical_faults() {
  static const std::vector<protocol::Fault> kFaults = [] {
    std::vector<protocol::Fault> faults;
    for (const protocol::FaultInfo& f : protocol::kFaultTable) {
      if (f.critical && std::find(faults.begin(), faults.end(), f.fault) == faults.end())
        faults.push_back(f.fault);
    }
    return faults;
  }();
  return kFaults;
}

std::uint32_t critical_error_mask(ErrorWordLayout layout) {
  // Built once per layout: the controller asks for every 0x211 (50 times a second).
  auto build = [](ErrorWordLayout l) {
    std::uint32_t mask = 0;
    for (const protocol::FaultInfo& f : protocol::kFaultTable) {
      if (f.critical && f.bit(l) != protocol::kNoBit) mask |= 1u << f.bit(l);
    }
    return mask;
  };
  static const std::uint32_t kMasks[] = {build(ErrorWordLayout::kManual32),
                                         build(ErrorWordLayout::kAgxV2_16),
                                         build(ErrorWordLayout::kMini32)};
  static_assert(std::size(kMasks) == kErrorWordLayoutNames.size(), "one mask per layout");
  return kMasks[static_cast<std::size_t>(layout)];
}

}  // namespace ranger::interpretation
