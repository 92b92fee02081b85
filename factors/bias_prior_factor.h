// Prior on one IMU bias block (factors/pose_manifold.h): b = (b_g in rad/s, b_a in m/s^2), in the
// body (IMU) frame B. For the first state of a window: the bias is only weakly observable over a
// short docking run, and without a prior its random walk alone leaves it free.
//
//   e = b - b0                                          rad/s, m/s^2
//   r = sqrt_info e,   sqrt_info^T sqrt_info = Sigma^-1   (Sigma 6 x 6, factored once)
// Typical Sigma: the turn-on bias uncertainty of the IMU's datasheet, block diagonal.
// Source: the standard Gaussian prior of a least-squares estimator (no paper-specific form).
#pragma once

#include <stdexcept>

#include <ceres/autodiff_cost_function.h>
#include <Eigen/Cholesky>
#include <Eigen/Core>

#include "factors/pose_manifold.h"

namespace auvdock {

inline constexpr int kBiasPriorResidualSize = 6;

class BiasPriorFactor {
 public:
  using Vector6 = Eigen::Matrix<double, 6, 1>;
  using Matrix6 = Eigen::Matrix<double, 6, 6>;

  // bias_prior = (b_g, b_a). Throws std::invalid_argument for a non-finite mean or a covariance
  // that is not symmetric positive definite.
  BiasPriorFactor(const Vector6& bias_prior, const Matrix6& covariance)
      : bias_prior_(bias_prior), covariance_(covariance) {
    if (!bias_prior_.allFinite()) {
      throw std::invalid_argument("BiasPriorFactor: the prior bias is not finite");
    }
    if (!covariance_.allFinite() ||
        !(covariance_ - covariance_.transpose()).isZero(1e-9 * covariance_.cwiseAbs().maxCoeff())) {
      throw std::invalid_argument("BiasPriorFactor: covariance is not finite and symmetric");
    }
    // Sigma = L L^T  =>  Sigma^-1 = L^-T L^-1, so sqrt_info = L^-1.
    const Eigen::LLT<Matrix6> llt(covariance_);
    if (llt.info() != Eigen::Success) {
      throw std::invalid_argument("BiasPriorFactor: covariance is not positive definite");
    }
    sqrt_info_ = llt.matrixL().solve(Matrix6::Identity());
  }

  template <typename T>
  bool operator()(const T* bias, T* residuals) const {
    Eigen::Map<Eigen::Matrix<T, 6, 1>> r(residuals);
    r = sqrt_info_.cast<T>() * Error(bias);
    return true;
  }

  // The unweighted error b - b0 (rad/s, m/s^2).
  Vector6 UnweightedError(const double* bias) const { return Error(bias); }

  // e^T Sigma^-1 e (chi-square, 6 degrees of freedom).
  double SquaredMahalanobis(const double* bias) const {
    return (sqrt_info_ * Error(bias)).squaredNorm();
  }

  static ceres::CostFunction* Create(const Vector6& bias_prior, const Matrix6& covariance) {
    return new ceres::AutoDiffCostFunction<BiasPriorFactor, kBiasPriorResidualSize, kBiasSize>(
        new BiasPriorFactor(bias_prior, covariance));
  }

  const Vector6& bias_prior() const { return bias_prior_; }
  const Matrix6& covariance() const { return covariance_; }
  const Matrix6& sqrt_information() const { return sqrt_info_; }

 private:
  template <typename T>
  Eigen::Matrix<T, 6, 1> Error(const T* bias) const {
    return Eigen::Map<const Eigen::Matrix<T, 6, 1>>(bias) - bias_prior_.cast<T>();
  }

  Vector6 bias_prior_;
  Matrix6 covariance_;
  Matrix6 sqrt_info_;
};

}  // namespace auvdock
