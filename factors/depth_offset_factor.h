// Pressure depth with an estimated offset: the depth factor (factors/depth_factor.h) for a
// sensor whose zero is not the dock survey's (the tide since the survey, the air pressure, the
// water's density, a pressure-sensor bias). The offset b is a state of its own, one per
// estimator state, joined to its neighbours by a random walk (factors/scalar_random_walk_factor.h);
// the lights, the acoustic fixes or a prior fix it, and the depth then gives the height where
// they do not (the last metre of a landing).
//
// Parameter blocks (layout in factors/pose_manifold.h): pose_D_B [7] and v_D [3] of state k,
// the offset b [1] of state k (m, added to the measured depth's model). Constants: the depth
// factor (measured depth d, sigma_m, origin_depth_m, down direction g_hat, lever arm p_B_S) and
// the IMU's motion from the state's time t_k to the sample's t (factors/time_shifted_factor.h;
// the identity for t = t_k):
//
//   T_D_Bt = shift(T_D_Bk, v_D)                 (time_shifted_factor.h)
//   p_D_S  = p_D_Bt + R_D_Bt p_B_S
//   r = (origin_depth_m + g_hat . p_D_S + b - d) / sigma_m
// so the simulator's biased sensor (sim/depth_simulator.h: d = true depth + bias) has b = bias.
// Jacobians: automatic differentiation; dr/db = 1 / sigma_m.
// Units: metres, seconds.
#pragma once

#include <memory>
#include <stdexcept>

#include <ceres/autodiff_cost_function.h>

#include "factors/depth_factor.h"
#include "factors/pose_manifold.h"
#include "factors/time_shifted_factor.h"

namespace auvdock {

inline constexpr int kDepthOffsetSize = 1;

class DepthOffsetFactor {
 public:
  // Throws std::invalid_argument for a non-finite shift.
  DepthOffsetFactor(const DepthFactor& depth, const ImuPoseShift& shift)
      : shifted_(std::make_unique<DepthFactor>(depth), shift), sigma_m_(depth.sigma_m()) {}

  template <typename T>
  bool operator()(const T* pose_D_Bk, const T* v_D, const T* offset_m, T* residual) const {
    if (!shifted_(pose_D_Bk, v_D, residual)) return false;
    residual[0] += offset_m[0] / T(sigma_m_);
    return true;
  }

  double sigma_m() const { return sigma_m_; }

  static ceres::CostFunction* Create(const DepthFactor& depth, const ImuPoseShift& shift) {
    return new ceres::AutoDiffCostFunction<DepthOffsetFactor, kDepthResidualSize, kPoseSize,
                                           kVelocitySize, kDepthOffsetSize>(
        new DepthOffsetFactor(depth, shift));
  }

 private:
  TimeShiftedFactor<DepthFactor, kDepthResidualSize> shifted_;
  double sigma_m_;
};

}  // namespace auvdock
