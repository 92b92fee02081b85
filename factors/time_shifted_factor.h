// A pose factor evaluated at another time than its state: an image taken dt after the state's
// time t_k (cameras that are not synchronised with each other, estimator/vision_frame.h) is
// attached to state k through the IMU's motion over [t_k, t_k + dt], so that no extra state is
// needed for it.
//
// Parameter blocks (layout in factors/pose_manifold.h): pose_D_B [7] of state k, v_D [3] of
// state k (m/s, in D). Constants: the IMU preintegrated over [t_k, t_k + dt] at the state's
// linearisation bias (dR = R_Bk_Bt, dp in B_k; imu/imu_preintegration.h) and the dock's gravity
// g_D (m/s^2, in D):
//
//   R_D_Bt = R_D_Bk dR
//   p_D_Bt = p_D_Bk + v_D dt + g_D dt^2 / 2 + R_D_Bk dp
//
// which is ImuPreintegration::Predict for the pose; the wrapped factor (any functor with a
// templated operator()(const T* pose_D_B, T* residuals), e.g. MonoReprojectionFactor or
// StereoPointFactor) is then evaluated at T_D_Bt.
//
// dt < 0 (a measurement from before the oldest state, e.g. an acoustic fix that arrived late,
// after its time had left the window): the IMU is preintegrated forward over [t, t_k], tau = -dt
// (dR = R_Bt_Bk, dp, dv in B_t), and the same relations are solved for the earlier state:
//
//   R_D_Bt = R_D_Bk dR^T
//   v_D_t  = v_D_k - g_D tau - R_D_Bt dv
//   p_D_Bt = p_D_Bk - v_D_t tau - g_D tau^2 / 2 - R_D_Bt dp
//
// What the shift leaves out, and why that is safe for |dt| up to a frame interval (and, for a
// fix whose sigma is centimetres, up to a second):
//  - the bias: the shift is held at the bias of the state when the factor is added, so
//    d(shift)/d(b) is not in the Jacobian; a gyro bias error of 0.01 rad/s moves the attitude by
//    0.5 mrad over dt = 50 ms, an accelerometer bias error of 0.1 m/s^2 the position by 0.13 mm
//    (by 5 cm over 1 s);
//  - the IMU noise over dt: its covariance (ImuPreintegration::covariance) is ~1e-8 rad^2 and
//    ~1e-9 m^2 over 50 ms for a tactical-grade IMU, orders below the vision noise.
#pragma once

#include <cmath>
#include <memory>
#include <stdexcept>

#include <ceres/autodiff_cost_function.h>
#include <Eigen/Core>
#include <Eigen/Geometry>

#include "factors/pose_manifold.h"

namespace auvdock {

// The body's motion from a state's time to dt later, from the IMU.
struct ImuPoseShift {
  double dt_s = 0.0;
  Eigen::Quaterniond delta_q = Eigen::Quaterniond::Identity();  // R_Bk_Bt
  Eigen::Vector3d delta_p = Eigen::Vector3d::Zero();            // m, in B_k
  Eigen::Vector3d delta_v = Eigen::Vector3d::Zero();            // m/s, in B_k
  Eigen::Vector3d gravity_D = Eigen::Vector3d::Zero();          // m/s^2, in D

  // The pose block at t_k + dt from the state's pose and velocity blocks.
  template <typename T>
  void Apply(const T* pose_D_Bk, const T* v_D, T* pose_D_Bt) const {
    using Vector3T = Eigen::Matrix<T, 3, 1>;
    const Eigen::Map<const Vector3T> p_k(pose_D_Bk);
    const Eigen::Map<const Eigen::Quaternion<T>> q_k(pose_D_Bk + 3);
    const Eigen::Map<const Vector3T> v(v_D);
    Eigen::Map<Vector3T> p_t(pose_D_Bt);
    Eigen::Map<Eigen::Quaternion<T>> q_t(pose_D_Bt + 3);
    if (dt_s >= 0.0) {
      const T dt(dt_s);
      p_t = p_k + v * dt + gravity_D.cast<T>() * T(0.5 * dt_s * dt_s) + q_k * delta_p.cast<T>();
      q_t = q_k * delta_q.cast<T>();
      return;
    }
    const T tau(-dt_s);
    q_t = q_k * delta_q.conjugate().cast<T>();
    const Vector3T v_t = v - gravity_D.cast<T>() * tau - q_t * delta_v.cast<T>();
    p_t = p_k - v_t * tau - gravity_D.cast<T>() * T(0.5 * dt_s * dt_s) - q_t * delta_p.cast<T>();
  }

  // The velocity at t_k + dt: v_D_t = v_D_k + g_D dt + R_D_Bk dv (for factors on the velocity,
  // e.g. factors/dvl_factor.h).
  template <typename T>
  void ApplyVelocity(const T* pose_D_Bk, const T* v_D, T* v_D_t) const {
    using Vector3T = Eigen::Matrix<T, 3, 1>;
    const Eigen::Map<const Eigen::Quaternion<T>> q_k(pose_D_Bk + 3);
    const Eigen::Map<const Vector3T> v(v_D);
    Eigen::Map<Vector3T> v_t(v_D_t);
    if (dt_s >= 0.0) {
      v_t = v + gravity_D.cast<T>() * T(dt_s) + q_k * delta_v.cast<T>();
      return;
    }
    const Eigen::Quaternion<T> q_t = q_k * delta_q.conjugate().cast<T>();
    v_t = v + gravity_D.cast<T>() * T(dt_s) - q_t * delta_v.cast<T>();
  }
};

template <typename Factor, int kResiduals>
class TimeShiftedFactor {
 public:
  // Throws std::invalid_argument for a non-finite dt or shift.
  TimeShiftedFactor(std::unique_ptr<Factor> factor, const ImuPoseShift& shift)
      : factor_(std::move(factor)), shift_(shift) {
    if (!factor_) throw std::invalid_argument("TimeShiftedFactor: no factor");
    if (!std::isfinite(shift_.dt_s) ||
        !shift_.delta_q.coeffs().allFinite() || !(shift_.delta_q.norm() > 0.0) ||
        !shift_.delta_p.allFinite() || !shift_.delta_v.allFinite() ||
        !shift_.gravity_D.allFinite()) {
      throw std::invalid_argument("TimeShiftedFactor: dt and the shift must be finite");
    }
    shift_.delta_q.normalize();
  }

  template <typename T>
  bool operator()(const T* pose_D_Bk, const T* v_D, T* residuals) const {
    T pose_D_Bt[kPoseSize];
    shift_.Apply(pose_D_Bk, v_D, pose_D_Bt);
    return (*factor_)(pose_D_Bt, residuals);
  }

  // The pose block at the image's time, for the wrapped factor's own queries
  // (DepthInCamera, SquaredMahalanobis, ...).
  void ShiftedPose(const double* pose_D_Bk, const double* v_D, double* pose_D_Bt) const {
    shift_.Apply(pose_D_Bk, v_D, pose_D_Bt);
  }
  const Factor& factor() const { return *factor_; }
  const ImuPoseShift& shift() const { return shift_; }

  static ceres::CostFunction* Create(std::unique_ptr<Factor> factor, const ImuPoseShift& shift) {
    return new ceres::AutoDiffCostFunction<TimeShiftedFactor, kResiduals, kPoseSize, kVelocitySize>(
        new TimeShiftedFactor(std::move(factor), shift));
  }

 private:
  std::unique_ptr<Factor> factor_;
  ImuPoseShift shift_;
};

}  // namespace auvdock
