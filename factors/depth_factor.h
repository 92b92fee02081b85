// Pressure depth of the depth sensor S against the dock's known depth: the vertical fix that a
// single light under a camera cannot give (the last metre of a landing) and a cheap one always.
//
// Parameter block (layout in factors/pose_manifold.h): pose_D_B [7] = p_D_B (m), q_D_B (x y z w).
// Constants: the measured depth d (m below the surface, positive down), its 1-sigma sigma_m, the
// dock's depth origin_depth_m (of the origin of D; dock.yaml), the unit down direction g_hat in D
// (g_D / |g_D|) and the sensor's lever arm p_B_S (m, in B).
//
//   p_D_S = p_D_B + R_D_B p_B_S
//   r = (origin_depth_m + g_hat . p_D_S - d) / sigma_m
// which is the simulator's model (sim/depth_simulator.h) without its offset. A slowly varying
// offset (tide, a pressure bias, the water density) is not in this factor: an offset of b metres
// biases the height by up to b where the lights do not fix it. factors/depth_offset_factor.h
// carries it as a state (EstimatorOptions::estimate_depth_offset).
// Jacobians: automatic differentiation (the residual is linear in p_D_B, smooth in q_D_B).
#pragma once

#include <cmath>
#include <stdexcept>

#include <ceres/autodiff_cost_function.h>
#include <Eigen/Core>
#include <Eigen/Geometry>

#include "factors/pose_manifold.h"

namespace auvdock {

inline constexpr int kDepthResidualSize = 1;

class DepthFactor {
 public:
  // Throws std::invalid_argument for non-finite input, sigma_m <= 0 or a zero down direction.
  DepthFactor(double depth_m, double sigma_m, double origin_depth_m, const Eigen::Vector3d& down_D,
              const Eigen::Vector3d& p_B_S)
      : depth_m_(depth_m), sigma_m_(sigma_m), origin_depth_m_(origin_depth_m), p_B_S_(p_B_S) {
    if (!std::isfinite(depth_m_) || !std::isfinite(origin_depth_m_) || !p_B_S_.allFinite() ||
        !down_D.allFinite() || !(down_D.norm() > 0.0)) {
      throw std::invalid_argument("DepthFactor: non-finite measurement or constant");
    }
    if (!(sigma_m_ > 0.0) || !std::isfinite(sigma_m_)) {
      throw std::invalid_argument("DepthFactor: sigma_m must be > 0");
    }
    down_D_ = down_D.normalized();
  }

  template <typename T>
  bool operator()(const T* pose_D_B, T* residual) const {
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> p_D_B(pose_D_B);
    const Eigen::Map<const Eigen::Quaternion<T>> q_D_B(pose_D_B + 3);
    const Eigen::Matrix<T, 3, 1> p_D_S = p_D_B + q_D_B * p_B_S_.cast<T>();
    residual[0] = (T(origin_depth_m_) + down_D_.cast<T>().dot(p_D_S) - T(depth_m_)) / T(sigma_m_);
    return true;
  }

  static ceres::CostFunction* Create(double depth_m, double sigma_m, double origin_depth_m,
                                     const Eigen::Vector3d& down_D, const Eigen::Vector3d& p_B_S) {
    return new ceres::AutoDiffCostFunction<DepthFactor, kDepthResidualSize, kPoseSize>(
        new DepthFactor(depth_m, sigma_m, origin_depth_m, down_D, p_B_S));
  }

  double depth_m() const { return depth_m_; }
  double sigma_m() const { return sigma_m_; }

 private:
  double depth_m_;
  double sigma_m_;
  double origin_depth_m_;
  Eigen::Vector3d down_D_;
  Eigen::Vector3d p_B_S_;
};

}  // namespace auvdock
