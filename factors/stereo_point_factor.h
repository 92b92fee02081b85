// Point residual of a dock light triangulated by the stereo pair against its known dock
// position: the stereo camera's term of the estimator (seed 000 eqs. 11-23 and seed 004's
// forward-down pair, recast from a per-frame SVD alignment into one residual per light).
//
// Parameter block (layout in factors/pose_manifold.h): pose_D_B [7] = p_D_B (m), q_D_B (x y z w).
// Constants: the light's dock position p_D_L (m) and the extrinsic T_B_S of the stereo frame
// S = the stereo-left camera frame (OpenCV axes: x right, y down, z optical axis).
//
//   p_S_pred = (T_D_B T_B_S)^-1 p_D_L = R_B_S^T (R_D_B^T (p_D_L - p_D_B) - p_B_S)    m
//   e = p_S_pred - p_S                                                                m
//   r = sqrt(w) sqrt_info_S e,   sqrt_info_S^T sqrt_info_S = Sigma_S^-1
// Sigma_S (3 x 3, m^2) is the first-order covariance of the triangulated point from pixel noise
// (TriangulatedPoint::covariance): strongly anisotropic, the depth along the viewing ray being the
// weak direction (sigma ~ z^2 / (f b)). The error is expressed in S, where Sigma_S lives, so the
// covariance is used as given (no rotation into D) and factored once here. w
// (information_weight, default 1) is the stage weight of include/auvdock/estimator/
// stage_weighting.h: it multiplies the information, so it scales the residual by sqrt(w).
// UnweightedError and SquaredMahalanobis ignore w: gating tests the measurement against its own
// noise model. The residual is linear in p_D_B and smooth in q_D_B everywhere, so unlike the
// mono reprojection there is no infeasible region.
//
// Why the point and not the pixels: it keeps the stereo front-end's output (triangulated lights)
// as the measurement, as in the source paper; the two pixel reprojections carry the same
// information to first order, which Sigma_S encodes.
//
// Source: seed 000 (Zhu et al., Control and Decision 2025, section 3.3: linear triangulation,
// eqs. 11-16, and rigid alignment of the triangulated lights to the dock model, eqs. 17-23, whose
// least-squares cost this residual weights by Sigma_S^-1 instead of uniformly).
#pragma once

#include <cmath>
#include <memory>
#include <stdexcept>

#include <ceres/autodiff_cost_function.h>
#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Geometry>

#include "auvdock/geometry/pose3.h"
#include "factors/analytic_pose_cost_function.h"
#include "factors/pose_manifold.h"

namespace auvdock {

inline constexpr int kStereoPointResidualSize = 3;

class StereoPointFactor {
 public:
  // p_S: triangulated light in S (m); covariance_S: its 3 x 3 covariance in S (m^2); T_B_S: the
  // stereo-left camera to body extrinsic; p_D_L: the light in D (m); information_weight > 0:
  // stage weight. Throws std::invalid_argument for non-finite input, a covariance that is not
  // symmetric positive definite or a non-positive weight.
  StereoPointFactor(const Eigen::Vector3d& p_S, const Eigen::Matrix3d& covariance_S,
                    const Pose3& T_B_S, const Eigen::Vector3d& p_D_L,
                    double information_weight = 1.0)
      : p_S_(p_S),
        covariance_S_(covariance_S),
        T_B_S_(T_B_S),
        p_D_L_(p_D_L),
        information_weight_(information_weight) {
    if (!p_S_.allFinite() || !p_D_L_.allFinite() || !T_B_S_.p.allFinite() ||
        !T_B_S_.q.coeffs().allFinite() || !(T_B_S_.q.norm() > 0.0)) {
      throw std::invalid_argument("StereoPointFactor: non-finite measurement or constant");
    }
    if (!(information_weight_ > 0.0) || !std::isfinite(information_weight_)) {
      throw std::invalid_argument("StereoPointFactor: information_weight must be > 0");
    }
    if (!covariance_S_.allFinite() || !(covariance_S_ - covariance_S_.transpose())
                                           .isZero(1e-9 * covariance_S_.cwiseAbs().maxCoeff())) {
      throw std::invalid_argument("StereoPointFactor: covariance is not finite and symmetric");
    }
    // Sigma = L L^T  =>  Sigma^-1 = L^-T L^-1, so sqrt_info = L^-1.
    const Eigen::LLT<Eigen::Matrix3d> llt(covariance_S_);
    if (llt.info() != Eigen::Success) {
      throw std::invalid_argument("StereoPointFactor: covariance is not positive definite");
    }
    sqrt_info_ = llt.matrixL().solve(Eigen::Matrix3d::Identity());
    weighted_sqrt_info_ = std::sqrt(information_weight_) * sqrt_info_;
    T_B_S_.q.normalize();
  }

  template <typename T>
  bool operator()(const T* pose_D_B, T* residuals) const {
    Eigen::Map<Eigen::Matrix<T, 3, 1>> r(residuals);
    r = weighted_sqrt_info_.cast<T>() * Error(pose_D_B);
    return true;
  }

  // The residual and its analytic Jacobian in the pose's tangent space (dp, dtheta; J may be
  // null), for AnalyticPoseCostFunction. With A = R_S_B R_D_B^T and v = p_D_L - p_D_B,
  // p_S_pred = A v - R_S_B p_B_S and
  //   J = sqrt(w) sqrt_info [-A, A [v]x]   (left perturbation R_D_B <- Exp(dtheta) R_D_B).
  bool EvaluateTangent(const double* pose_D_B, double* residuals,
                       Eigen::Matrix<double, 3, kPoseTangentSize, Eigen::RowMajor>* J) const {
    const Eigen::Map<const Eigen::Vector3d> p_D_B(pose_D_B);
    const Eigen::Map<const Eigen::Quaterniond> q_D_B(pose_D_B + 3);
    const Eigen::Matrix3d R_S_B = T_B_S_.q.conjugate().toRotationMatrix();
    const Eigen::Matrix3d A = R_S_B * q_D_B.toRotationMatrix().transpose();
    const Eigen::Vector3d v = p_D_L_ - p_D_B;
    Eigen::Map<Eigen::Vector3d> r(residuals);
    r = weighted_sqrt_info_ * (A * v - R_S_B * T_B_S_.p - p_S_);
    if (J == nullptr) return true;
    Eigen::Matrix3d v_cross;
    v_cross << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
    const Eigen::Matrix3d WA = weighted_sqrt_info_ * A;
    J->leftCols<3>() = -WA;
    J->rightCols<3>() = WA * v_cross;
    return true;
  }

  // The unweighted error p_S_pred - p_S (m, in S).
  Eigen::Vector3d UnweightedError(const double* pose_D_B) const { return Error(pose_D_B); }

  // e^T Sigma_S^-1 e (chi-square, 3 degrees of freedom), without the stage weight.
  double SquaredMahalanobis(const double* pose_D_B) const {
    return (sqrt_info_ * Error(pose_D_B)).squaredNorm();
  }

  // The light predicted in S by the pose (m).
  Eigen::Vector3d PredictedPointInS(const double* pose_D_B) const {
    return PredictedPoint<double>(pose_D_B);
  }

  static ceres::CostFunction* Create(const Eigen::Vector3d& p_S,
                                     const Eigen::Matrix3d& covariance_S, const Pose3& T_B_S,
                                     const Eigen::Vector3d& p_D_L,
                                     double information_weight = 1.0) {
    return Create(
        std::make_unique<StereoPointFactor>(p_S, covariance_S, T_B_S, p_D_L, information_weight));
  }
  // Create gives the analytic Jacobian (EvaluateTangent); CreateAutoDiff differentiates the
  // templated operator() with ceres::Jet (the tests' reference).
  static ceres::CostFunction* Create(std::unique_ptr<StereoPointFactor> factor) {
    return new AnalyticPoseCostFunction<StereoPointFactor, kStereoPointResidualSize>(
        std::move(factor));
  }
  static ceres::CostFunction* CreateAutoDiff(std::unique_ptr<StereoPointFactor> factor) {
    return new ceres::AutoDiffCostFunction<StereoPointFactor, kStereoPointResidualSize, kPoseSize>(
        factor.release());
  }

  const Eigen::Vector3d& p_S() const { return p_S_; }
  const Eigen::Matrix3d& covariance_S() const { return covariance_S_; }
  // Without the stage weight.
  const Eigen::Matrix3d& sqrt_information() const { return sqrt_info_; }
  double information_weight() const { return information_weight_; }
  const Pose3& T_B_S() const { return T_B_S_; }
  const Eigen::Vector3d& p_D_L() const { return p_D_L_; }

 private:
  template <typename T>
  Eigen::Matrix<T, 3, 1> PredictedPoint(const T* pose_D_B) const {
    using Vector3T = Eigen::Matrix<T, 3, 1>;
    const Eigen::Map<const Vector3T> p_D_B(pose_D_B);
    const Eigen::Map<const Eigen::Quaternion<T>> q_D_B(pose_D_B + 3);
    const Vector3T p_B = q_D_B.conjugate() * Vector3T(p_D_L_.cast<T>() - p_D_B);
    return T_B_S_.q.conjugate().cast<T>() * Vector3T(p_B - T_B_S_.p.cast<T>());
  }

  template <typename T>
  Eigen::Matrix<T, 3, 1> Error(const T* pose_D_B) const {
    return PredictedPoint<T>(pose_D_B) - p_S_.cast<T>();
  }

  Eigen::Vector3d p_S_;
  Eigen::Matrix3d covariance_S_;
  Pose3 T_B_S_;
  Eigen::Vector3d p_D_L_;
  double information_weight_;
  Eigen::Matrix3d sqrt_info_;
  Eigen::Matrix3d weighted_sqrt_info_;
};

}  // namespace auvdock
