// se2.h — the algebra of planar poses (SE(2)), written once for the engine,
// the log input and the bindings: taking a pose from one frame to another
// (compose, inverse), the shorter way between two headings, the pose between
// two poses (the --poses interpolation), and the heading of a quaternion
// (TUM files).
//
//   laser = vasco::compose(robot, mount);   // the mount is in the robot's frame
//   mount = vasco::compose(vasco::inverse(robot), laser);
#ifndef VASCO_GPU_INTERNAL_SE2_H
#define VASCO_GPU_INTERNAL_SE2_H

#include <cmath>
#include <limits>

#include "vasco_gpu/pose_series.h"

namespace vasco {

// compose(a, b): b expressed in a's frame, taken to the frame a is in.
inline Pose2 compose(const Pose2 &a, const Pose2 &b) {
  const double c = std::cos(a.theta), s = std::sin(a.theta);
  return {a.x + c * b.x - s * b.y, a.y + s * b.x + c * b.y, a.theta + b.theta};
}

// inverse(a): compose(a, inverse(a)) is the identity (up to rounding).
inline Pose2 inverse(const Pose2 &a) {
  const double c = std::cos(a.theta), s = std::sin(a.theta);
  return {-c * a.x - s * a.y, s * a.x - c * a.y, -a.theta};
}

// b - a taken into [-pi, pi): the shorter way round. Exact for a difference
// already in that range (remainder() is exact).
inline double angle_difference(double a, double b) {
  constexpr double kPi = 3.14159265358979323846;
  double d = std::remainder(b - a, 2 * kPi);
  if (d >= kPi) d -= 2 * kPi;
  return d;
}

// The pose a fraction u of the way from a to b: x and y linear, theta along
// the shorter arc; u = 0 gives a's x and y and theta.
inline Pose2 pose_between(const Pose2 &a, const Pose2 &b, double u) {
  return {a.x + u * (b.x - a.x), a.y + u * (b.y - a.y), a.theta + u * angle_difference(a.theta, b.theta)};
}

// The norm of a quaternion, without overflow for large components.
inline double quaternion_norm(double qx, double qy, double qz, double qw) {
  return std::hypot(std::hypot(qx, qy), std::hypot(qz, qw));
}

// theta of a quaternion's rotation about z (the yaw). Normalised first, so
// that the 1 - 2(qy^2 + qz^2) form is right for a quaternion written with
// few digits; NaN for one that is no rotation.
inline double yaw_of_quaternion(double qx, double qy, double qz, double qw) {
  const double n = quaternion_norm(qx, qy, qz, qw);
  if (!(n > 0) || !std::isfinite(n)) return std::numeric_limits<double>::quiet_NaN();
  qx /= n;
  qy /= n;
  qz /= n;
  qw /= n;
  return std::atan2(2 * (qw * qz + qx * qy), 1 - 2 * (qy * qy + qz * qz));
}

}  // namespace vasco

#endif  // VASCO_GPU_INTERNAL_SE2_H
