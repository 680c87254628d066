#include "ranger_can/control/vocabulary.hpp"

#include <chrono>
#include <limits>

#include "ranger_can/wire/interpretation.hpp"

namespace ranger {
namespace {

std::vector<NamedFlag> flags_of(std::uint32_t word, const std::vector<protocol::NamedBit>& bits,
                                std::vector<NamedFlag> out = {}) {
  for (const protocol::NamedBit& bit : bits)
    out.push_back({bit.name, ((word >> bit.index) & 1u) != 0});
  return out;
}

// A BMS report older than this many of its periods counts as absent.
constexpr int kStalePeriods = 3;

}  // namespace

std::vector<NamedFlag> fault_flags(std::uint32_t error_word, ErrorWordLayout layout) {
  std::vector<NamedFlag> out;
  for (const protocol::FaultInfo& f : protocol::kFaultTable) {
    const int bit = f.bit(layout);
    if (bit != protocol::kNoBit) out.push_back({f.name, ((error_word >> bit) & 1u) != 0});
  }
  return out;
}

std::vector<std::string> fault_names(std::uint32_t error_word, ErrorWordLayout layout) {
  return protocol::error_bit_names(error_word, layout);
}

std::vector<NamedFlag> driver_status_flags(std::uint8_t status) {
  return flags_of(status, protocol::driver_status_bits());
}

std::vector<NamedFlag> bms_flags(std::uint8_t status1, std::uint8_t status2) {
  return flags_of(status2, protocol::bms_status2_bits(),
                  flags_of(status1, protocol::bms_status1_bits()));
}

bool bms_present(const ChassisFeedback& feedback, int slot, Timestamp now) {
  if (slot < 0 || slot > kBatteryCount) return false;
  const int period_ms = protocol::frame_period_ms(protocol::kBmsBaseId);
  return is_fresh(feedback.bms[static_cast<std::size_t>(slot)], now,
                  std::chrono::milliseconds(kStalePeriods * period_ms));
}

double ultrasonic_range(std::int16_t raw) {
  return interpretation::ultrasonic_distance_m(raw).value_or(
      std::numeric_limits<double>::quiet_NaN());
}

std::string_view ultrasonic_status(std::int16_t raw) {
  return protocol::ultrasonic_status_name(raw);
}

Covariance diagonal_covariance(const std::array<double, 6>& diagonal) {
  Covariance out{};
  for (std::size_t i = 0; i < diagonal.size(); ++i)
    out[i * 7] = diagonal[i];
  return out;
}

Covariance pose_covariance(const OdometryState& odometry, const std::array<double, 6>& floor) {
  Covariance out = diagonal_covariance(floor);
  out[0] += odometry.pose_variance[0];   // x
  out[7] += odometry.pose_variance[1];   // y
  out[35] += odometry.pose_variance[2];  // yaw
  return out;
}

}  // namespace ranger
