// SO(3) helpers on Eigen types: hat, exponential and logarithm maps, Euler angles.
//
// Math (Sola, "A micro Lie theory for state estimation in robotics", 2018):
//   Exp(w) = I + sin|w|/|w| [w]x + (1 - cos|w|)/|w|^2 [w]x^2      (Rodrigues)
//   Log(R) = the rotation vector w with Exp(w) = R, |w| in [0, pi].
// Quaternions are Eigen::Quaterniond (Hamilton, stored x y z w in memory); conversion to
// file orders (w x y z in EuRoC, x y z w in TUM) happens in io/ only.
//
// Euler angles follow the marine / aerospace Z-Y-X convention used by the seeds:
//   R_D_B = Rz(yaw) * Ry(pitch) * Rx(roll),  body x forward, y right, z down.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace auvdock {

// Skew-symmetric matrix [w]x with [w]x v = w x v.
Eigen::Matrix3d Hat(const Eigen::Vector3d& w);

// Rotation vector -> unit quaternion, exact for every angle, stable near zero.
Eigen::Quaterniond ExpQuaternion(const Eigen::Vector3d& w);
inline Eigen::Matrix3d ExpSO3(const Eigen::Vector3d& w) {
  return ExpQuaternion(w).toRotationMatrix();
}

// Unit quaternion -> rotation vector with angle in [0, pi] (the shortest one).
Eigen::Vector3d LogQuaternion(const Eigen::Quaterniond& q);
inline Eigen::Vector3d LogSO3(const Eigen::Matrix3d& R) {
  return LogQuaternion(Eigen::Quaterniond(R));
}

// Z-Y-X Euler angles (roll, pitch, yaw) in radians <-> rotation.
Eigen::Quaterniond QuaternionFromRollPitchYaw(double roll, double pitch, double yaw);
// Returns (roll, pitch, yaw); yaw and roll in (-pi, pi], pitch in [-pi/2, pi/2].
Eigen::Vector3d RollPitchYawFromQuaternion(const Eigen::Quaterniond& q);

// Wraps an angle to (-pi, pi].
double WrapAngle(double a);

}  // namespace auvdock
