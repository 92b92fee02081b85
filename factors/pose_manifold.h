// The manifold of a body pose T_D_B stored as one 7-double Ceres parameter block, and the state
// layout every factor and the estimator share.
//
// Parameter blocks of one estimator state (all in the dock frame D, z down):
//   pose     [7] = p_D_B (x, y, z; m), q_D_B (x, y, z, w; Eigen's memory order, unit norm)
//   velocity [3] = v_D_B (m/s), the body's velocity expressed in D
//   bias     [6] = b_g (rad/s), b_a (m/s^2), in the body (IMU) frame B
//
// Tangent space of the pose (6): delta = (dp_D, dtheta_D), a position step in D and a rotation
// vector in D applied on the left ("global" perturbation):
//   Plus(x, delta)  = (p + dp,  Exp(dtheta) * q)
//   Minus(y, x)     = (p_y - p_x,  Log(q_y * q_x^-1))
// The rotation is therefore perturbed in the dock frame, so a pose covariance reported in this
// tangent space reads directly as position (m) and attitude (rad) uncertainty about the dock's
// axes: its (1, 1) entry is the lateral variance and, for a level vehicle, (5, 5) the yaw
// variance - what the docking go/no-go needs. Log returns the angle in [0, pi], so Minus picks
// the shorter of q and -q.
//
// Jacobians at delta = 0 (rows of the ambient block in the order p, qx, qy, qz, qw):
//   dPlus/ddelta   = [ I3  0 ; 0  M/2 ],    M = [ q_w I - [q_v]x ; -q_v^T ]  (4 x 3, M^T M = I)
//   dMinus/dy|y=x  = [ I3  0 ; 0  2 M^T ],  so that MinusJacobian * PlusJacobian = I6.
#pragma once

#include <cmath>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <ceres/manifold.h>

#include "auvdock/geometry/pose3.h"
#include "auvdock/imu/imu_preintegration.h"

namespace auvdock {

inline constexpr int kPoseSize = 7;
inline constexpr int kPoseTangentSize = 6;
inline constexpr int kVelocitySize = 3;
inline constexpr int kBiasSize = 6;

// Unit quaternion of the rotation vector phi (rad); exact near zero.
template <typename T>
Eigen::Quaternion<T> QuaternionExp(const Eigen::Matrix<T, 3, 1>& phi) {
  using std::cos;
  using std::sin;
  using std::sqrt;
  const T theta_sq = phi.squaredNorm();
  T real, imag_scale;
  if (theta_sq > T(1e-16)) {
    const T theta = sqrt(theta_sq);
    real = cos(T(0.5) * theta);
    imag_scale = sin(T(0.5) * theta) / theta;
  } else {
    // Taylor series to second order (the next term is theta^4 / 3840).
    real = T(1.0) - theta_sq / T(8.0);
    imag_scale = T(0.5) - theta_sq / T(48.0);
  }
  return Eigen::Quaternion<T>(real, imag_scale * phi.x(), imag_scale * phi.y(),
                              imag_scale * phi.z());
}

// Rotation vector (rad, angle in [0, pi]) of a unit quaternion; q and -q give the same answer.
template <typename T>
Eigen::Matrix<T, 3, 1> QuaternionLog(const Eigen::Quaternion<T>& q_in) {
  using std::atan2;
  using std::sqrt;
  Eigen::Quaternion<T> q = q_in;
  if (q.w() < T(0.0)) q.coeffs() = -q.coeffs();
  const Eigen::Matrix<T, 3, 1> v = q.vec();
  const T sin_sq = v.squaredNorm();
  if (sin_sq > T(1e-16)) {
    const T sin_half = sqrt(sin_sq);
    const T angle = T(2.0) * atan2(sin_half, q.w());
    return v * (angle / sin_half);
  }
  // Near identity: angle / sin(angle / 2) = 2 / w (1 + sin^2 / (6 w^2)) to second order.
  return v * (T(2.0) / q.w() * (T(1.0) + sin_sq / (T(6.0) * q.w() * q.w())));
}

// The pose a block holds (the quaternion normalised), and a pose written into a block.
inline Pose3 PoseFromBlock(const double* pose) {
  return Pose3(Eigen::Map<const Eigen::Quaterniond>(pose + 3).normalized(),
               Eigen::Map<const Eigen::Vector3d>(pose));
}

// The biases a bias block holds (b_g, b_a).
inline ImuBias BiasFromBlock(const double* bias) {
  ImuBias b;
  b.gyro = Eigen::Map<const Eigen::Vector3d>(bias);
  b.accel = Eigen::Map<const Eigen::Vector3d>(bias + 3);
  return b;
}

inline void PoseToBlock(const Pose3& T, double* pose) {
  Eigen::Map<Eigen::Vector3d> p(pose);
  Eigen::Map<Eigen::Quaterniond> q(pose + 3);
  p = T.p;
  q = T.q.normalized();
}

class PoseManifold final : public ceres::Manifold {
 public:
  int AmbientSize() const override { return kPoseSize; }
  int TangentSize() const override { return kPoseTangentSize; }

  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override {
    Eigen::Map<const Eigen::Vector3d> p(x);
    Eigen::Map<const Eigen::Quaterniond> q(x + 3);
    Eigen::Map<const Eigen::Vector3d> dp(delta);
    Eigen::Map<const Eigen::Vector3d> dtheta(delta + 3);
    Eigen::Map<Eigen::Vector3d> p_out(x_plus_delta);
    Eigen::Map<Eigen::Quaterniond> q_out(x_plus_delta + 3);
    p_out = p + dp;
    q_out = (QuaternionExp<double>(dtheta) * q).normalized();
    return true;
  }

  bool PlusJacobian(const double* x, double* jacobian) const override {
    Eigen::Map<Eigen::Matrix<double, kPoseSize, kPoseTangentSize, Eigen::RowMajor>> J(jacobian);
    J.setZero();
    J.topLeftCorner<3, 3>().setIdentity();
    J.bottomRightCorner<4, 3>() = 0.5 * LeftProductMatrix(x + 3);
    return true;
  }

  bool Minus(const double* y, const double* x, double* y_minus_x) const override {
    Eigen::Map<const Eigen::Vector3d> p_y(y);
    Eigen::Map<const Eigen::Vector3d> p_x(x);
    Eigen::Map<const Eigen::Quaterniond> q_y(y + 3);
    Eigen::Map<const Eigen::Quaterniond> q_x(x + 3);
    Eigen::Map<Eigen::Vector3d> dp(y_minus_x);
    Eigen::Map<Eigen::Vector3d> dtheta(y_minus_x + 3);
    dp = p_y - p_x;
    dtheta = QuaternionLog<double>(q_y * q_x.conjugate());
    return true;
  }

  bool MinusJacobian(const double* x, double* jacobian) const override {
    Eigen::Map<Eigen::Matrix<double, kPoseTangentSize, kPoseSize, Eigen::RowMajor>> J(jacobian);
    J.setZero();
    J.topLeftCorner<3, 3>().setIdentity();
    J.bottomRightCorner<3, 4>() = 2.0 * LeftProductMatrix(x + 3).transpose();
    return true;
  }

 private:
  // M(q) = d(vec(a * q)) / d(a_v) at a = identity, rows (x, y, z, w): [q_w I - [q_v]x ; -q_v^T].
  static Eigen::Matrix<double, 4, 3> LeftProductMatrix(const double* q_xyzw) {
    const double qx = q_xyzw[0], qy = q_xyzw[1], qz = q_xyzw[2], qw = q_xyzw[3];
    Eigen::Matrix<double, 4, 3> M;
    M << qw, qz, -qy,  //
        -qz, qw, qx,   //
        qy, -qx, qw,   //
        -qx, -qy, -qz;
    return M;
  }
};

}  // namespace auvdock
