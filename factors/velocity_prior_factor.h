// Prior on one body velocity v_D_B (the velocity block of factors/pose_manifold.h, expressed in
// the dock frame D, m/s): for the first state of a window, a reset or a vehicle known to be at
// rest.
//
//   e = v - v0                                         m/s
//   r = sqrt_info e,   sqrt_info^T sqrt_info = Sigma^-1  (Sigma 3 x 3, (m/s)^2, factored once)
// Source: the standard Gaussian prior of a least-squares estimator (no paper-specific form).
#pragma once

#include <stdexcept>

#include <ceres/autodiff_cost_function.h>
#include <Eigen/Cholesky>
#include <Eigen/Core>

#include "factors/pose_manifold.h"

namespace auvdock {

inline constexpr int kVelocityPriorResidualSize = 3;

class VelocityPriorFactor {
 public:
  // Throws std::invalid_argument for a non-finite mean or a covariance that is not symmetric
  // positive definite.
  VelocityPriorFactor(const Eigen::Vector3d& v_D_B_prior, const Eigen::Matrix3d& covariance)
      : v_D_B_prior_(v_D_B_prior), covariance_(covariance) {
    if (!v_D_B_prior_.allFinite()) {
      throw std::invalid_argument("VelocityPriorFactor: the prior velocity is not finite");
    }
    if (!covariance_.allFinite() ||
        !(covariance_ - covariance_.transpose()).isZero(1e-9 * covariance_.cwiseAbs().maxCoeff())) {
      throw std::invalid_argument("VelocityPriorFactor: covariance is not finite and symmetric");
    }
    // Sigma = L L^T  =>  Sigma^-1 = L^-T L^-1, so sqrt_info = L^-1.
    const Eigen::LLT<Eigen::Matrix3d> llt(covariance_);
    if (llt.info() != Eigen::Success) {
      throw std::invalid_argument("VelocityPriorFactor: covariance is not positive definite");
    }
    sqrt_info_ = llt.matrixL().solve(Eigen::Matrix3d::Identity());
  }

  template <typename T>
  bool operator()(const T* velocity_D_B, T* residuals) const {
    Eigen::Map<Eigen::Matrix<T, 3, 1>> r(residuals);
    r = sqrt_info_.cast<T>() * Error(velocity_D_B);
    return true;
  }

  // The unweighted error v - v0 (m/s).
  Eigen::Vector3d UnweightedError(const double* velocity_D_B) const { return Error(velocity_D_B); }

  // e^T Sigma^-1 e (chi-square, 3 degrees of freedom).
  double SquaredMahalanobis(const double* velocity_D_B) const {
    return (sqrt_info_ * Error(velocity_D_B)).squaredNorm();
  }

  static ceres::CostFunction* Create(const Eigen::Vector3d& v_D_B_prior,
                                     const Eigen::Matrix3d& covariance) {
    return new ceres::AutoDiffCostFunction<VelocityPriorFactor, kVelocityPriorResidualSize,
                                           kVelocitySize>(
        new VelocityPriorFactor(v_D_B_prior, covariance));
  }

  const Eigen::Vector3d& v_D_B_prior() const { return v_D_B_prior_; }
  const Eigen::Matrix3d& covariance() const { return covariance_; }
  const Eigen::Matrix3d& sqrt_information() const { return sqrt_info_; }

 private:
  template <typename T>
  Eigen::Matrix<T, 3, 1> Error(const T* velocity_D_B) const {
    return Eigen::Map<const Eigen::Matrix<T, 3, 1>>(velocity_D_B) - v_D_B_prior_.cast<T>();
  }

  Eigen::Vector3d v_D_B_prior_;
  Eigen::Matrix3d covariance_;
  Eigen::Matrix3d sqrt_info_;
};

}  // namespace auvdock
