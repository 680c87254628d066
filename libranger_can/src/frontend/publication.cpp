#include "ranger_can/frontend/publication.hpp"

#include <algorithm>

#include "ranger_can/control/vocabulary.hpp"

namespace ranger {

SteadyDuration publication_period(double rate_hz) {
  return std::chrono::duration_cast<SteadyDuration>(std::chrono::duration<double>(1.0 / rate_hz));
}

SteadyDuration publication_early(SteadyDuration period) {
  return std::min<SteadyDuration>(std::chrono::milliseconds(5), period / 4);
}

void PublicationSchedule::set_period(SteadyDuration period) {
  period_ = period;
  early_ = publication_early(period);
}

void PublicationSchedule::advance(SteadyTime now) {
  next_ += period_;
  if (next_ < now) next_ = now + period_;
}

MotionDecision MotionPacer::decide(const DriverSnapshot& s, SteadyTime now) {
  MotionDecision d;
  if (!s.motion_known) {  // nothing to publish, nothing to wait for
    schedule_.advance(now);
    return d;
  }
  const Timestamp joints = joints_stamp(s.feedback);
  d.odometry = s.odometry.stamp > published_odometry_;
  d.joints = (s.joints.has_steering || s.joints.has_wheels) && joints > published_joints_;
  if (d.publish()) {
    published_odometry_ = std::max(published_odometry_, s.odometry.stamp);
    if (d.joints) published_joints_ = joints;
    schedule_.advance(now);
  } else {
    d.wait_for_estimate = true;
  }
  return d;
}

}  // namespace ranger
