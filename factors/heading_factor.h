// Heading of an AHRS or compass S against the body's attitude: the one rotation that gravity
// leaves unobserved, which far from the dock only the motion (DVL against acoustic fixes) shows.
//
// Parameter block (layout in factors/pose_manifold.h): pose_D_B [7] = p_D_B (m), q_D_B (x y z w).
// Constants: the measured heading h (rad; geometry/heading.h: clockwise from the reference seen
// from above), its 1-sigma sigma_rad, the sensor's rotation R_B_S and the dock's heading
// reference (down direction, horizontal reference axis, the dock's own heading).
//
//   a_D = R_D_B R_B_S e_x                       the sensor's x axis in D
//   r = wrap(heading(a_D) - h) / sigma_rad      wrap to (-pi, pi]: any branch of h
// which is the simulator's model (sim/heading_simulator.h). Undefined where a_D is vertical (a
// vehicle pitched 90 degrees); the position does not enter.
// Jacobians: automatic differentiation (atan2 of smooth functions of q_D_B).
#pragma once

#include <cmath>
#include <stdexcept>

#include <ceres/autodiff_cost_function.h>
#include <Eigen/Core>
#include <Eigen/Geometry>

#include "auvdock/geometry/heading.h"
#include "factors/pose_manifold.h"

namespace auvdock {

inline constexpr int kHeadingResidualSize = 1;

class HeadingFactor {
 public:
  // Throws std::invalid_argument for a non-finite heading or sigma_rad <= 0.
  HeadingFactor(double heading_rad, double sigma_rad, const Eigen::Quaterniond& q_B_S,
                const HeadingReference& reference)
      : heading_rad_(heading_rad), sigma_rad_(sigma_rad), reference_(reference) {
    if (!std::isfinite(heading_rad_) || !q_B_S.coeffs().allFinite()) {
      throw std::invalid_argument("HeadingFactor: non-finite measurement or rotation");
    }
    if (!(sigma_rad_ > 0.0) || !std::isfinite(sigma_rad_)) {
      throw std::invalid_argument("HeadingFactor: sigma_rad must be > 0");
    }
    x_B_ = q_B_S.normalized() * Eigen::Vector3d::UnitX();
  }

  template <typename T>
  bool operator()(const T* pose_D_B, T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q_D_B(pose_D_B + 3);
    const Eigen::Matrix<T, 3, 1> a_D = q_D_B * x_B_.cast<T>();
    residual[0] = WrapAngle(reference_.HeadingOf(a_D) - T(heading_rad_)) / T(sigma_rad_);
    return true;
  }

  static ceres::CostFunction* Create(double heading_rad, double sigma_rad,
                                     const Eigen::Quaterniond& q_B_S,
                                     const HeadingReference& reference) {
    return new ceres::AutoDiffCostFunction<HeadingFactor, kHeadingResidualSize, kPoseSize>(
        new HeadingFactor(heading_rad, sigma_rad, q_B_S, reference));
  }

 private:
  double heading_rad_;
  double sigma_rad_;
  HeadingReference reference_;
  Eigen::Vector3d x_B_;
};

}  // namespace auvdock
