#include "auvdock/geometry/pose3.h"

#include "auvdock/geometry/so3.h"

namespace auvdock {

Eigen::Matrix4d Pose3::Matrix() const {
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  T.topLeftCorner<3, 3>() = R();
  T.topRightCorner<3, 1>() = p;
  return T;
}

Pose3 Pose3::FromMatrix(const Eigen::Matrix4d& T) {
  return Pose3(Eigen::Quaterniond(Eigen::Matrix3d(T.topLeftCorner<3, 3>())),
               T.topRightCorner<3, 1>());
}

Pose3 Pose3::Inverse() const {
  const Eigen::Quaterniond q_inv = q.conjugate();
  return Pose3(q_inv, -(q_inv * p));
}

Pose3 Pose3::operator*(const Pose3& other) const {
  return Pose3(q * other.q, q * other.p + p);
}

Pose3 Interpolate(const Pose3& a, const Pose3& b, double alpha) {
  return Pose3(a.q.slerp(alpha, b.q), (1.0 - alpha) * a.p + alpha * b.p);
}

double RotationAngleBetween(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  return LogQuaternion(a.conjugate() * b).norm();
}

}  // namespace auvdock
