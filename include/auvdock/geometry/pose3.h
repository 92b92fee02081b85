// A rigid transform T_A_B in SE(3): rotation q_A_B and translation p_A_B.
//
// Naming follows CONVENTIONS.md: T_A_B maps coordinates of frame B into frame A,
//   p_A = T_A_B * p_B = R_A_B p_B + p_A_B.
// Composition T_A_C = T_A_B * T_B_C. The rotation is a unit Eigen quaternion (x y z w in
// memory). Interpolation is linear in translation and spherical (slerp) in rotation, which is
// what trajectory evaluation needs between ground-truth samples.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace auvdock {

struct Pose3 {
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  Eigen::Vector3d p = Eigen::Vector3d::Zero();

  Pose3() = default;
  Pose3(const Eigen::Quaterniond& rotation, const Eigen::Vector3d& translation)
      : q(rotation.normalized()), p(translation) {}

  static Pose3 Identity() { return Pose3(); }

  Eigen::Matrix3d R() const { return q.toRotationMatrix(); }
  Eigen::Matrix4d Matrix() const;
  static Pose3 FromMatrix(const Eigen::Matrix4d& T);

  Pose3 Inverse() const;
  Pose3 operator*(const Pose3& other) const;
  Eigen::Vector3d operator*(const Eigen::Vector3d& x) const { return q * x + p; }
};

// Interpolates between a (alpha = 0) and b (alpha = 1).
Pose3 Interpolate(const Pose3& a, const Pose3& b, double alpha);

// Rotation angle (rad) of a^-1 * b, the geodesic distance on SO(3).
double RotationAngleBetween(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b);

}  // namespace auvdock
