#include "ros2_wire.hpp"

#include <algorithm>
#include <cstring>
#include <utility>

#include "ranger_can/control/vocabulary.hpp"

namespace ranger::python {
namespace {

static_assert(sizeof(double) == 8, "CDR's float64 is an IEEE 754 double");

// A CDR little-endian writer (see ros2_wire.hpp): the encapsulation header, then aligned fields.
class CdrWriter {
 public:
  explicit CdrWriter(std::size_t reserve) {
    out_.reserve(reserve);
    out_.append("\x00\x01\x00\x00", 4);  // CDR_LE, options 0
  }
  void u32(std::uint32_t v) { put(v); }
  void i32(std::int32_t v) { put(v); }
  void f64(double v) { put(v); }
  void string(const std::string& s) {
    u32(static_cast<std::uint32_t>(s.size() + 1));
    out_.append(s);
    out_.push_back('\0');
  }
  void stamp(std::int64_t sec, std::uint32_t nanosec) {  // builtin_interfaces/Time
    i32(static_cast<std::int32_t>(sec));
    u32(nanosec);
  }
  void header(std::int64_t sec, std::uint32_t nanosec, const std::string& frame_id) {
    stamp(sec, nanosec);
    string(frame_id);
  }
  std::string take() { return std::move(out_); }

 private:
  template <class T>
  void put(T v) {  // little endian only: the hosts we build for (static_assert below)
    const std::size_t body = out_.size() - 4;
    out_.append((sizeof(T) - body % sizeof(T)) % sizeof(T), '\0');
    char bytes[sizeof(T)];
    std::memcpy(bytes, &v, sizeof(T));
    out_.append(bytes, sizeof(T));
  }
  std::string out_;
};

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "the encoder writes host order as CDR_LE");

// A planar pose: geometry_msgs/Pose (position, orientation) or Transform (translation, rotation),
// which lie alike on the wire: (x, y, 0) and the yaw's quaternion (0, 0, qz, qw).
void planar_pose(CdrWriter& w, double x, double y, double qz, double qw) {
  for (double c : {x, y, 0.0, 0.0, 0.0, qz, qw})
    w.f64(c);
}

// A covariance as the library makes it (ranger::pose_covariance, diagonal_covariance).
void covariance(CdrWriter& w, const Covariance& c) {
  for (double v : c)
    w.f64(v);
}

// The encapsulation identifiers (the first two bytes, big endian) whose body read_twist reads:
// plain CDR (XCDR1) and plain CDR2 (XCDR2), each in both byte orders. For a message of doubles
// only, starting at the body's offset 0, the two lay the values out alike.
struct Encapsulation {
  std::uint16_t id;
  bool little_endian;
};
constexpr std::array<Encapsulation, 4> kTwistEncapsulations{{
    {0x0000, false},  // CDR_BE
    {0x0001, true},   // CDR_LE
    {0x0006, false},  // CDR2_BE
    {0x0007, true},   // CDR2_LE
}};

double read_f64(const char* at, bool little_endian) {
  unsigned char bytes[8];
  std::memcpy(bytes, at, 8);
  if (!little_endian) std::reverse(bytes, bytes + 8);  // the host is little endian (above)
  double v;
  std::memcpy(&v, bytes, 8);
  return v;
}

}  // namespace

std::optional<std::array<double, 6>> read_twist(std::string_view bytes) {
  constexpr std::size_t kHeader = 4, kBody = 6 * 8;
  if (bytes.size() < kHeader + kBody) return std::nullopt;
  const auto id = static_cast<std::uint16_t>((static_cast<unsigned char>(bytes[0]) << 8) |
                                             static_cast<unsigned char>(bytes[1]));
  const auto* encapsulation = std::find_if(kTwistEncapsulations.begin(), kTwistEncapsulations.end(),
                                           [id](const Encapsulation& e) { return e.id == id; });
  if (encapsulation == kTwistEncapsulations.end()) return std::nullopt;
  std::array<double, 6> twist{};
  for (std::size_t i = 0; i < twist.size(); ++i)
    twist[i] = read_f64(bytes.data() + kHeader + 8 * i, encapsulation->little_endian);
  return twist;
}

MotionWireEncoder::MotionWireEncoder(MotionWireSetup setup) : setup_(std::move(setup)) {}

std::string MotionWireEncoder::odometry(const OdometryValues& v) const {
  const auto& [sec, nanosec, x, y, qz, qw, vx, vy, wz, var_x, var_y, var_yaw] = v;
  CdrWriter w(720 + setup_.odom_frame.size() + setup_.base_frame.size());
  w.header(sec, nanosec, setup_.odom_frame);
  w.string(setup_.base_frame);
  planar_pose(w, x, y, qz, qw);  // pose: PoseWithCovariance
  covariance(w, pose_covariance({var_x, var_y, var_yaw}, setup_.pose_covariance_diagonal));
  // twist: TwistWithCovariance
  for (double c : {vx, vy, 0.0, 0.0, 0.0, wz})
    w.f64(c);
  covariance(w, diagonal_covariance(setup_.twist_covariance_diagonal));
  return w.take();
}

std::string MotionWireEncoder::transform(const OdometryValues& v) const {
  const auto& [sec, nanosec, x, y, qz, qw, vx, vy, wz, var_x, var_y, var_yaw] = v;
  CdrWriter w(96 + setup_.odom_frame.size() + setup_.base_frame.size());
  w.u32(1);  // transforms: one TransformStamped
  w.header(sec, nanosec, setup_.odom_frame);
  w.string(setup_.base_frame);
  planar_pose(w, x, y, qz, qw);
  return w.take();
}

std::string MotionWireEncoder::joint_state(const JointValues& v) const {
  const auto& [sec, nanosec, position, velocity] = v;
  std::size_t names = 0;
  for (const std::string& n : setup_.joint_names)
    names += n.size() + 8;
  CdrWriter w(48 + names + 16 * position.size());
  w.header(sec, nanosec, "");
  w.u32(static_cast<std::uint32_t>(setup_.joint_names.size()));
  for (const std::string& n : setup_.joint_names)
    w.string(n);
  const std::size_t count = std::min(setup_.joint_names.size(), position.size());
  w.u32(static_cast<std::uint32_t>(count));
  for (std::size_t i = 0; i < count; ++i)
    w.f64(position[i]);
  w.u32(static_cast<std::uint32_t>(count));
  for (std::size_t i = 0; i < count; ++i)
    w.f64(velocity[i]);
  w.u32(0);  // effort
  return w.take();
}

}  // namespace ranger::python
