// Prior on one body pose T_D_B: a Gaussian in the tangent space of PoseManifold
// (factors/pose_manifold.h), for the first state of a window, a reset or a known start.
//
// Parameter block: pose_D_B [7] = p_D_B (m), q_D_B (x y z w), in the dock frame D (z down).
// Mean T_D_B0 = (p0, q0); covariance Sigma (6 x 6) of the tangent vector (dp_D in m, dtheta_D in
// rad, a rotation vector in D applied on the left), i.e. exactly the convention in which the
// estimator reports a pose covariance, so a reported covariance can be fed back as a prior.
//
//   e = Minus(T_D_B, T_D_B0) = [ p - p0 ;  Log(q q0^-1) ]        m, rad
//   r = sqrt_info e,   sqrt_info^T sqrt_info = Sigma^-1          (factored once here)
// Log takes the shorter of q and -q (angle in [0, pi]), so the sign of the stored quaternion
// does not matter; the price is a jump where the error angle crosses pi (q q0^-1 changes side),
// so a prior is only meaningful well inside that (any sensible covariance is). At T_D_B = T_D_B0
// the Jacobian with respect to the tangent step is sqrt_info itself (MinusJacobian * PlusJacobian =
// I). Source: the standard Gaussian prior of a least-squares estimator (no paper-specific form).
#pragma once

#include <cmath>
#include <stdexcept>

#include <ceres/autodiff_cost_function.h>
#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Geometry>

#include "auvdock/geometry/pose3.h"
#include "factors/pose_manifold.h"

namespace auvdock {

inline constexpr int kPosePriorResidualSize = 6;

class PosePriorFactor {
 public:
  using Vector6 = Eigen::Matrix<double, 6, 1>;
  using Matrix6 = Eigen::Matrix<double, 6, 6>;

  // Throws std::invalid_argument for a non-finite mean or a covariance that is not symmetric
  // positive definite.
  PosePriorFactor(const Pose3& T_D_B_prior, const Matrix6& covariance)
      : T_D_B_prior_(T_D_B_prior), covariance_(covariance) {
    if (!T_D_B_prior_.p.allFinite() || !T_D_B_prior_.q.coeffs().allFinite() ||
        !(T_D_B_prior_.q.norm() > 0.0)) {
      throw std::invalid_argument("PosePriorFactor: the prior pose is not finite");
    }
    if (!covariance_.allFinite() ||
        !(covariance_ - covariance_.transpose()).isZero(1e-9 * covariance_.cwiseAbs().maxCoeff())) {
      throw std::invalid_argument("PosePriorFactor: covariance is not finite and symmetric");
    }
    // Sigma = L L^T  =>  Sigma^-1 = L^-T L^-1, so sqrt_info = L^-1.
    const Eigen::LLT<Matrix6> llt(covariance_);
    if (llt.info() != Eigen::Success) {
      throw std::invalid_argument("PosePriorFactor: covariance is not positive definite");
    }
    sqrt_info_ = llt.matrixL().solve(Matrix6::Identity());
    T_D_B_prior_.q.normalize();
  }

  template <typename T>
  bool operator()(const T* pose_D_B, T* residuals) const {
    Eigen::Map<Eigen::Matrix<T, 6, 1>> r(residuals);
    r = sqrt_info_.cast<T>() * Error(pose_D_B);
    return true;
  }

  // The unweighted tangent error [p - p0; Log(q q0^-1)] (m, rad).
  Vector6 UnweightedError(const double* pose_D_B) const { return Error(pose_D_B); }

  // e^T Sigma^-1 e (chi-square, 6 degrees of freedom).
  double SquaredMahalanobis(const double* pose_D_B) const {
    return (sqrt_info_ * Error(pose_D_B)).squaredNorm();
  }

  static ceres::CostFunction* Create(const Pose3& T_D_B_prior, const Matrix6& covariance) {
    return new ceres::AutoDiffCostFunction<PosePriorFactor, kPosePriorResidualSize, kPoseSize>(
        new PosePriorFactor(T_D_B_prior, covariance));
  }

  const Pose3& T_D_B_prior() const { return T_D_B_prior_; }
  const Matrix6& covariance() const { return covariance_; }
  const Matrix6& sqrt_information() const { return sqrt_info_; }

 private:
  template <typename T>
  Eigen::Matrix<T, 6, 1> Error(const T* pose_D_B) const {
    using Vector3T = Eigen::Matrix<T, 3, 1>;
    const Eigen::Map<const Vector3T> p(pose_D_B);
    const Eigen::Map<const Eigen::Quaternion<T>> q(pose_D_B + 3);
    Eigen::Matrix<T, 6, 1> e;
    e.template head<3>() = p - T_D_B_prior_.p.cast<T>();
    e.template tail<3>() = QuaternionLog<T>(q * T_D_B_prior_.q.conjugate().cast<T>());
    return e;
  }

  Pose3 T_D_B_prior_;
  Matrix6 covariance_;
  Matrix6 sqrt_info_;
};

}  // namespace auvdock
