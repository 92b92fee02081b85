// One short-baseline (SBL) slant range (seed 001) as a factor on the body pose: the distance
// from the dock's beacon to one transducer of the hull's array. Ranges, not a solved position:
// a ping with only two or three replies still constrains the pose, and each range's noise is
// the sensor's own (a position solved from a ~1 m array is poorly conditioned across it).
//
// Parameter block (layout in factors/pose_manifold.h): pose_D_B [7] = p_D_B (m), q_D_B (x y z w).
// Constants: the measured range rho (m), its 1-sigma sigma_m (range-dependent, carried by the
// measurement), the transducer's position p_B_T (m, in B) and the beacon's p_D_F (m, in D:
// dock.yaml beacon_p_D).
//
//   p_D_T = p_D_B + R_D_B p_B_T
//   r = (|p_D_T - p_D_F| - rho) / sigma_m                  (1 residual)
// which is the simulator's model (sim/sbl_simulator.h). The range is smooth wherever the
// transducer is not at the beacon (d|x|/dx = x / |x|); a transducer within 1 mm of the beacon
// gives residual -rho / sigma with a zero Jacobian (a vehicle sitting on the beacon: no
// direction to correct). A range measured at t after the state's time attaches through the
// IMU's motion (factors/time_shifted_factor.h). Jacobians: automatic differentiation.
#pragma once

#include <cmath>
#include <stdexcept>

#include <ceres/autodiff_cost_function.h>
#include <Eigen/Core>
#include <Eigen/Geometry>

#include "factors/pose_manifold.h"

namespace auvdock {

inline constexpr int kSblRangeResidualSize = 1;

class SblRangeFactor {
 public:
  // Throws std::invalid_argument for non-finite input, a negative range or sigma_m <= 0.
  SblRangeFactor(double range_m, double sigma_m, const Eigen::Vector3d& p_B_T,
                 const Eigen::Vector3d& p_D_F)
      : range_m_(range_m), sigma_m_(sigma_m), p_B_T_(p_B_T), p_D_F_(p_D_F) {
    if (!std::isfinite(range_m_) || range_m_ < 0.0 || !p_B_T_.allFinite() ||
        !p_D_F_.allFinite()) {
      throw std::invalid_argument("SblRangeFactor: non-finite input or negative range");
    }
    if (!(sigma_m_ > 0.0) || !std::isfinite(sigma_m_)) {
      throw std::invalid_argument("SblRangeFactor: sigma_m must be > 0");
    }
  }

  template <typename T>
  bool operator()(const T* pose_D_B, T* residual) const {
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> p_D_B(pose_D_B);
    const Eigen::Map<const Eigen::Quaternion<T>> q_D_B(pose_D_B + 3);
    const Eigen::Matrix<T, 3, 1> d = p_D_B + q_D_B * p_B_T_.cast<T>() - p_D_F_.cast<T>();
    const T squared = d.squaredNorm();
    // sqrt at 0 has no derivative: there the range is 0 with a zero Jacobian.
    const T distance = squared > T(1e-6) ? sqrt(squared) : T(0.0) * squared;
    residual[0] = (distance - T(range_m_)) / T(sigma_m_);
    return true;
  }

  static ceres::CostFunction* Create(double range_m, double sigma_m, const Eigen::Vector3d& p_B_T,
                                     const Eigen::Vector3d& p_D_F) {
    return new ceres::AutoDiffCostFunction<SblRangeFactor, kSblRangeResidualSize, kPoseSize>(
        new SblRangeFactor(range_m, sigma_m, p_B_T, p_D_F));
  }

 private:
  double range_m_;
  double sigma_m_;
  Eigen::Vector3d p_B_T_;
  Eigen::Vector3d p_D_F_;
};

}  // namespace auvdock
