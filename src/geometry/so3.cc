#include "auvdock/geometry/so3.h"

#include <algorithm>
#include <cmath>

namespace auvdock {

Eigen::Matrix3d Hat(const Eigen::Vector3d& w) {
  Eigen::Matrix3d W;
  W << 0.0, -w.z(), w.y(),  //
      w.z(), 0.0, -w.x(),   //
      -w.y(), w.x(), 0.0;
  return W;
}

Eigen::Quaterniond ExpQuaternion(const Eigen::Vector3d& w) {
  const double theta_sq = w.squaredNorm();
  double real, imag_factor;
  if (theta_sq < 1e-16) {
    // Taylor expansion: cos(t/2) ~ 1 - t^2/8, sin(t/2)/t ~ 1/2 - t^2/48.
    real = 1.0 - theta_sq / 8.0;
    imag_factor = 0.5 - theta_sq / 48.0;
  } else {
    const double theta = std::sqrt(theta_sq);
    real = std::cos(0.5 * theta);
    imag_factor = std::sin(0.5 * theta) / theta;
  }
  Eigen::Quaterniond q(real, imag_factor * w.x(), imag_factor * w.y(), imag_factor * w.z());
  q.normalize();
  return q;
}

Eigen::Vector3d LogQuaternion(const Eigen::Quaterniond& q_in) {
  Eigen::Quaterniond q = q_in.normalized();
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();  // same rotation, angle in [0, pi]
  const Eigen::Vector3d v = q.vec();
  const double sin_half = v.norm();
  if (sin_half < 1e-10) {
    // theta ~ 2 sin(theta/2); first-order is exact to 1e-20 here.
    return 2.0 * v / q.w();
  }
  const double theta = 2.0 * std::atan2(sin_half, q.w());
  return theta / sin_half * v;
}

Eigen::Quaterniond QuaternionFromRollPitchYaw(double roll, double pitch, double yaw) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                            Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                            Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()));
}

Eigen::Vector3d RollPitchYawFromQuaternion(const Eigen::Quaterniond& q) {
  const Eigen::Matrix3d R = q.normalized().toRotationMatrix();
  const double pitch = std::asin(std::clamp(-R(2, 0), -1.0, 1.0));
  const double roll = std::atan2(R(2, 1), R(2, 2));
  const double yaw = std::atan2(R(1, 0), R(0, 0));
  return Eigen::Vector3d(roll, pitch, yaw);
}

double WrapAngle(double a) {
  a = std::fmod(a + M_PI, 2.0 * M_PI);
  if (a <= 0.0) a += 2.0 * M_PI;
  return a - M_PI;
}

}  // namespace auvdock
