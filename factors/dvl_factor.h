// Doppler velocity log: the velocity over the ground of the DVL S, measured in S, against a
// state's pose and velocity. What makes a landing without lights hold still: the IMU alone
// drifts quadratically, a velocity fix bounds the drift to a random walk of the DVL's noise.
//
// Parameter blocks (layout in factors/pose_manifold.h): pose_D_B [7] and v_D [3] (m/s, in D)
// of state k at t_k, and the DVL's bias (below). Constants: the measured v_S (m/s, in S) at
// t = t_k + dt, its 1-sigma sigma_mps per axis, the sensor's mounting T_B_S (rotation q_B_S, which
// may be any rotation, e.g. 45 degrees about z; lever arm p_B_S, m, in B), the body rate w_B at t
// (rad/s, in B: the gyro minus its bias), and the IMU's motion over [t_k, t] (ImuPoseShift,
// factors/time_shifted_factor.h; identity for dt = 0):
//
//   R_D_Bt = R_D_Bk dR,   v_D_t = v_D_k + g_D dt + R_D_Bk dv
//   v_S    = R_S_B (R_Bt_D v_D_t + w_B x p_B_S)          (sim/dvl_simulator.h's model)
//   r      = (v_S - v_S_measured) / sigma_mps             (3)
//
// With the DVL's slowly varying error as a state (CreateWithBias: a third block b_S [3], m/s,
// in S; factors/vector_random_walk_factor.h walks it between states), the measurement is
// v_S_measured = v_S + b_S + noise and r = (v_S + b_S - v_S_measured) / sigma_mps. b_S holds
// what a real DVL's bottom-track velocity keeps for tens of seconds: its scale error (0.2-0.5 %
// of the speed, a constant at a constant speed), a mounting misalignment (0.5 deg at 2 m/s:
// 1.7 cm/s across track), the seabed's own look (slope, sediment).
//
// Bottom-lock loss (the DVL sees no seabed: too close or too far) is no measurement: a sample
// that is not finite never becomes a factor (estimator/dvl_factors.h). The shift is held at the
// state's bias when the factor is added (as for the camera images; the bias's effect on dv over
// a DVL interval, 0.1 m/s^2 x 0.2 s = 2 cm/s at worst, is left out of the Jacobian, not out of
// the value: the IMU factor between states carries it).
// Jacobians: automatic differentiation.
#pragma once

#include <cmath>
#include <stdexcept>

#include <ceres/autodiff_cost_function.h>
#include <Eigen/Core>
#include <Eigen/Geometry>

#include "auvdock/geometry/pose3.h"
#include "factors/pose_manifold.h"
#include "factors/time_shifted_factor.h"

namespace auvdock {

inline constexpr int kDvlResidualSize = 3;
inline constexpr int kDvlBiasSize = 3;  // b_S, m/s in S

class DvlFactor {
 public:
  // Throws std::invalid_argument for non-finite input or sigma_mps <= 0.
  DvlFactor(const Eigen::Vector3d& v_S, double sigma_mps, const Pose3& T_B_S,
            const Eigen::Vector3d& w_B, const ImuPoseShift& shift = {})
      : v_S_(v_S), sigma_mps_(sigma_mps), q_S_B_(T_B_S.q.conjugate().normalized()),
        p_B_S_(T_B_S.p), w_B_(w_B), shift_(shift) {
    if (!v_S_.allFinite() || !p_B_S_.allFinite() || !q_S_B_.coeffs().allFinite() ||
        !w_B_.allFinite() || !std::isfinite(shift_.dt_s) || shift_.dt_s < 0.0 ||
        !shift_.delta_q.coeffs().allFinite() || !(shift_.delta_q.norm() > 0.0) ||
        !shift_.delta_v.allFinite() || !shift_.gravity_D.allFinite()) {
      throw std::invalid_argument("DvlFactor: non-finite measurement or constant");
    }
    if (!(sigma_mps_ > 0.0) || !std::isfinite(sigma_mps_)) {
      throw std::invalid_argument("DvlFactor: sigma_mps must be > 0");
    }
    shift_.delta_q.normalize();
  }

  template <typename T>
  bool operator()(const T* pose_D_Bk, const T* v_D_k, T* residual) const {
    return Residual(pose_D_Bk, v_D_k, static_cast<const T*>(nullptr), residual);
  }
  // With the DVL's bias b_S [3] (m/s, in S).
  template <typename T>
  bool operator()(const T* pose_D_Bk, const T* v_D_k, const T* b_S, T* residual) const {
    return Residual(pose_D_Bk, v_D_k, b_S, residual);
  }

  static ceres::CostFunction* Create(const Eigen::Vector3d& v_S, double sigma_mps,
                                     const Pose3& T_B_S, const Eigen::Vector3d& w_B,
                                     const ImuPoseShift& shift = {}) {
    return new ceres::AutoDiffCostFunction<DvlFactor, kDvlResidualSize, kPoseSize, kVelocitySize>(
        new DvlFactor(v_S, sigma_mps, T_B_S, w_B, shift));
  }
  // The same on a third block, the DVL's bias b_S.
  static ceres::CostFunction* CreateWithBias(const Eigen::Vector3d& v_S, double sigma_mps,
                                             const Pose3& T_B_S, const Eigen::Vector3d& w_B,
                                             const ImuPoseShift& shift = {}) {
    return new ceres::AutoDiffCostFunction<DvlFactor, kDvlResidualSize, kPoseSize, kVelocitySize,
                                           kDvlBiasSize>(
        new DvlFactor(v_S, sigma_mps, T_B_S, w_B, shift));
  }

  double sigma_mps() const { return sigma_mps_; }

 private:
  template <typename T>
  bool Residual(const T* pose_D_Bk, const T* v_D_k, const T* b_S, T* residual) const {
    using Vector3T = Eigen::Matrix<T, 3, 1>;
    const Eigen::Map<const Eigen::Quaternion<T>> q_D_Bk(pose_D_Bk + 3);
    const Eigen::Quaternion<T> q_D_Bt = q_D_Bk * shift_.delta_q.cast<T>();
    Vector3T v_D_t;
    shift_.ApplyVelocity(pose_D_Bk, v_D_k, v_D_t.data());
    const Vector3T v_B = q_D_Bt.conjugate() * v_D_t + w_B_.cast<T>().cross(p_B_S_.cast<T>());
    Vector3T v_S = q_S_B_.cast<T>() * v_B;
    if (b_S != nullptr) v_S += Eigen::Map<const Vector3T>(b_S);
    Eigen::Map<Vector3T> r(residual);
    r = (v_S - v_S_.cast<T>()) / T(sigma_mps_);
    return true;
  }

  Eigen::Vector3d v_S_;
  double sigma_mps_;
  Eigen::Quaterniond q_S_B_;
  Eigen::Vector3d p_B_S_;
  Eigen::Vector3d w_B_;
  ImuPoseShift shift_;
};

}  // namespace auvdock
