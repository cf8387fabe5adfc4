// Tests of the algebra of planar poses (vasco_gpu/internal/se2.h): compose,
// inverse and the yaw of a quaternion. Expected values are worked out by hand
// here. (angle_difference and pose_between: pose_series_test.cc.)
#include "vasco_gpu/internal/se2.h"

#include <gtest/gtest.h>

#include <cmath>

namespace {

using vasco::Pose2;

constexpr double kPi = 3.14159265358979323846;

TEST(PoseAlgebra, ComposeAndInverse) {
  // theta = 0: a plain translation, exact.
  Pose2 c = vasco::compose({1, 2, 0}, {3, 4, 0.5});
  EXPECT_EQ(c.x, 4);
  EXPECT_EQ(c.y, 6);
  EXPECT_EQ(c.theta, 0.5);
  // A quarter turn: b's x goes to +y, its y to -x: (1 - 4, 2 + 3).
  c = vasco::compose({1, 2, kPi / 2}, {3, 4, 0.5});
  EXPECT_NEAR(c.x, -3, 1e-15);
  EXPECT_NEAR(c.y, 5, 1e-15);
  EXPECT_EQ(c.theta, kPi / 2 + 0.5);
  // No angle normalisation.
  EXPECT_EQ(vasco::compose({0, 0, 3}, {0, 0, 3}).theta, 6);
  // inverse of (1, 2, pi/2): (-cos*1 - sin*2, sin*1 - cos*2, -pi/2) = (-2, 1, -pi/2).
  const Pose2 a = {1, 2, kPi / 2};
  const Pose2 ia = vasco::inverse(a);
  EXPECT_NEAR(ia.x, -2, 1e-15);
  EXPECT_NEAR(ia.y, 1, 1e-15);
  EXPECT_EQ(ia.theta, -kPi / 2);
  const Pose2 id = vasco::compose(a, ia);
  EXPECT_NEAR(id.x, 0, 1e-15);
  EXPECT_NEAR(id.y, 0, 1e-15);
  EXPECT_EQ(id.theta, 0);
  const Pose2 b = {-0.7, 3.25, -2.5};
  const Pose2 id2 = vasco::compose(vasco::inverse(b), b);
  EXPECT_NEAR(id2.x, 0, 1e-14);  // a few roundings of values near 2
  EXPECT_NEAR(id2.y, 0, 1e-14);
  EXPECT_EQ(id2.theta, 0);
}

// A quaternion with roll and pitch: its yaw is the Z of Z-Y-X Euler angles.
TEST(PoseAlgebra, YawOfAQuaternionWithRollAndPitch) {
  const double roll = 0.1, pitch = 0.2, yaw = 0.7;
  const double cr = std::cos(roll / 2), sr = std::sin(roll / 2), cp = std::cos(pitch / 2), sp = std::sin(pitch / 2),
               cy = std::cos(yaw / 2), sy = std::sin(yaw / 2);
  // q = qz(yaw) * qy(pitch) * qx(roll), written out.
  const double qw = cr * cp * cy + sr * sp * sy, qx = sr * cp * cy - cr * sp * sy, qy = cr * sp * cy + sr * cp * sy,
               qz = cr * cp * sy - sr * sp * cy;
  EXPECT_NEAR(vasco::yaw_of_quaternion(qx, qy, qz, qw), yaw, 1e-14);
  EXPECT_NEAR(vasco::yaw_of_quaternion(3 * qx, 3 * qy, 3 * qz, 3 * qw), yaw, 1e-14);  // normalised first
  EXPECT_TRUE(std::isnan(vasco::yaw_of_quaternion(0, 0, 0, 0)));
}

}  // namespace
