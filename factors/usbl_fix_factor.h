// An acoustic position fix (USBL: the transponder S on the vehicle, located from the dock's
// transceiver) as a factor on the body pose: the absolute horizontal position that vision gives
// only near the dock, at a fix's own time.
//
// Parameter block (layout in factors/pose_manifold.h): pose_D_B [7] = p_D_B (m), q_D_B (x y z w).
// Constants: the fix p_fix_D (m, dock frame D), its 1-sigma per axis sigma_m (the sensor's
// range-dependent figure: sigma_min + fraction x slant range, carried by the fix) and the
// transponder's lever arm p_B_S (m, in B).
//
//   p_D_S = p_D_B + R_D_B p_B_S
//   r = (p_D_S - p_fix_D) / sigma_m                       (3 residuals)
// which is the simulator's model (sim/acoustic_simulator.h). A fix measured at t after the
// state's time attaches through the IMU's motion (factors/time_shifted_factor.h).
// Jacobians: automatic differentiation (linear in p_D_B, smooth in q_D_B).
#pragma once

#include <cmath>
#include <stdexcept>

#include <ceres/autodiff_cost_function.h>
#include <Eigen/Core>
#include <Eigen/Geometry>

#include "factors/pose_manifold.h"

namespace auvdock {

inline constexpr int kUsblResidualSize = 3;

class UsblFixFactor {
 public:
  // Throws std::invalid_argument for non-finite input or sigma_m <= 0.
  UsblFixFactor(const Eigen::Vector3d& p_fix_D, double sigma_m, const Eigen::Vector3d& p_B_S)
      : p_fix_D_(p_fix_D), sigma_m_(sigma_m), p_B_S_(p_B_S) {
    if (!p_fix_D_.allFinite() || !p_B_S_.allFinite()) {
      throw std::invalid_argument("UsblFixFactor: non-finite fix or lever arm");
    }
    if (!(sigma_m_ > 0.0) || !std::isfinite(sigma_m_)) {
      throw std::invalid_argument("UsblFixFactor: sigma_m must be > 0");
    }
  }

  template <typename T>
  bool operator()(const T* pose_D_B, T* residual) const {
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> p_D_B(pose_D_B);
    const Eigen::Map<const Eigen::Quaternion<T>> q_D_B(pose_D_B + 3);
    const Eigen::Matrix<T, 3, 1> p_D_S = p_D_B + q_D_B * p_B_S_.cast<T>();
    for (int i = 0; i < 3; ++i) residual[i] = (p_D_S[i] - T(p_fix_D_[i])) / T(sigma_m_);
    return true;
  }

  static ceres::CostFunction* Create(const Eigen::Vector3d& p_fix_D, double sigma_m,
                                     const Eigen::Vector3d& p_B_S) {
    return new ceres::AutoDiffCostFunction<UsblFixFactor, kUsblResidualSize, kPoseSize>(
        new UsblFixFactor(p_fix_D, sigma_m, p_B_S));
  }

 private:
  Eigen::Vector3d p_fix_D_;
  double sigma_m_;
  Eigen::Vector3d p_B_S_;
};

}  // namespace auvdock
