// Reprojection residual of a known dock light seen by one camera as a pixel of its raw
// (distorted) image: the mono camera's term of the estimator (seed 000 eq. 10 and seed 004's
// down-looking camera, recast from a per-frame PnP into one residual per light).
//
// Parameter block (layout in factors/pose_manifold.h): pose_D_B [7] = p_D_B (m), q_D_B (x y z w).
// Constants: the light's dock position p_D_L (m), the camera extrinsic T_B_C (camera C in OpenCV
// axes: x right, y down, z optical axis; B: x forward, y right, z down) and the intrinsics
// (fx, fy, cx, cy in pixels; radtan k1, k2, p1, p2, k3 as in PinholeRadtanCamera).
//
//   p_C = T_C_B T_B_D p_D_L = R_C_B R_D_B^T (p_D_L - p_D_B) + p_C_B,   T_C_B = T_B_C^-1
//   (x, y) = (X / Z, Y / Z),  (x_d, y_d) = DistortNormalized(x, y)
//   pi(p_C) = (fx x_d + cx, fy y_d + cy)                                      pixels
//   e = pi(p_C) - uv                                                          pixels
//   r = sqrt(w) sqrt_info e,   sqrt_info^T sqrt_info = Sigma_uv^-1
// Sigma_uv (2 x 2, px^2) is the centroid noise of the detected light; it is factored once here.
// w (information_weight, default 1) is the stage weight of include/auvdock/estimator/
// stage_weighting.h: it multiplies the information, so it scales the residual by sqrt(w).
// UnweightedError and SquaredMahalanobis ignore w: gating tests the measurement against its own
// noise model, whatever share of the cost the fusion policy gives it.
//
// A light behind the camera (Z <= kMinDepth): operator() returns false. The projection has no
// meaning there, and any finite stand-in (clamping Z, a constant penalty) is either a false
// minimum (a light straight behind projects onto the principal point when Z is clamped) or a
// residual whose Jacobian does not describe the cost. Ceres treats false during the iterations
// as an infeasible step: the trust region shrinks and the pose never crosses the camera plane.
// Evaluating false at the initial point makes Solve() fail, so the caller must not add a factor
// whose light is behind the camera at the current estimate: check DepthInCamera() (or
// SquaredMahalanobis(), which is +infinity there) first. The distortion polynomial is only valid
// near the image; lights far outside the field of view should likewise not be added.
//
// Source: seed 000 (Zhu et al., Control and Decision 2025, section 3.2, eq. 10: mono PnP by
// minimising this reprojection error); the camera model of PinholeRadtanCamera (OpenCV's).
#pragma once

#include <array>
#include <cmath>
#include <memory>
#include <limits>
#include <stdexcept>

#include <ceres/autodiff_cost_function.h>
#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Geometry>

#include "auvdock/camera/pinhole_radtan_camera.h"
#include "auvdock/geometry/pose3.h"
#include "factors/analytic_pose_cost_function.h"
#include "factors/pose_manifold.h"

namespace auvdock {

inline constexpr int kMonoResidualSize = 2;

class MonoReprojectionFactor {
 public:
  // Smallest depth Z (m) in the camera frame at which the residual is evaluated.
  static constexpr double kMinDepth = 1e-3;

  // uv: measured raw pixel; covariance: its 2 x 2 covariance (px^2); camera: intrinsics and
  // distortion (width/height unused); T_B_C: camera-to-body extrinsic; p_D_L: the light in D (m);
  // information_weight > 0: stage weight (see the header comment). Throws std::invalid_argument
  // for non-finite input, a covariance that is not symmetric positive definite, non-positive
  // focal lengths or a non-positive weight.
  MonoReprojectionFactor(const Eigen::Vector2d& uv, const Eigen::Matrix2d& covariance,
                         const PinholeRadtanCamera& camera, const Pose3& T_B_C,
                         const Eigen::Vector3d& p_D_L, double information_weight = 1.0)
      : uv_(uv),
        covariance_(covariance),
        fx_(camera.fx()),
        fy_(camera.fy()),
        cx_(camera.cx()),
        cy_(camera.cy()),
        distortion_(camera.distortion()),
        T_B_C_(T_B_C),
        p_D_L_(p_D_L),
        information_weight_(information_weight) {
    if (!uv_.allFinite() || !p_D_L_.allFinite() || !T_B_C_.p.allFinite() ||
        !T_B_C_.q.coeffs().allFinite() || !(T_B_C_.q.norm() > 0.0)) {
      throw std::invalid_argument("MonoReprojectionFactor: non-finite measurement or constant");
    }
    if (!(fx_ > 0.0) || !(fy_ > 0.0) || !std::isfinite(fx_) || !std::isfinite(fy_) ||
        !std::isfinite(cx_) || !std::isfinite(cy_)) {
      throw std::invalid_argument("MonoReprojectionFactor: invalid intrinsics");
    }
    for (const double d : distortion_) {
      if (!std::isfinite(d)) {
        throw std::invalid_argument("MonoReprojectionFactor: non-finite distortion coefficient");
      }
    }
    if (!(information_weight_ > 0.0) || !std::isfinite(information_weight_)) {
      throw std::invalid_argument("MonoReprojectionFactor: information_weight must be > 0");
    }
    if (!covariance_.allFinite() ||
        !(covariance_ - covariance_.transpose()).isZero(1e-9 * covariance_.cwiseAbs().maxCoeff())) {
      throw std::invalid_argument("MonoReprojectionFactor: covariance is not finite and symmetric");
    }
    // Sigma = L L^T  =>  Sigma^-1 = L^-T L^-1, so sqrt_info = L^-1.
    const Eigen::LLT<Eigen::Matrix2d> llt(covariance_);
    if (llt.info() != Eigen::Success) {
      throw std::invalid_argument("MonoReprojectionFactor: covariance is not positive definite");
    }
    sqrt_info_ = llt.matrixL().solve(Eigen::Matrix2d::Identity());
    weighted_sqrt_info_ = std::sqrt(information_weight_) * sqrt_info_;
    T_B_C_.q.normalize();
    q_C_B_ = T_B_C_.q.conjugate();
    p_C_B_ = -(q_C_B_ * T_B_C_.p);
  }

  template <typename T>
  bool operator()(const T* pose_D_B, T* residuals) const {
    Eigen::Matrix<T, 2, 1> e;
    if (!Error(pose_D_B, &e)) return false;
    Eigen::Map<Eigen::Matrix<T, 2, 1>> r(residuals);
    r = weighted_sqrt_info_.cast<T>() * e;
    return true;
  }

  // The residual and its analytic Jacobian in the pose's tangent space (dp, dtheta; J may be
  // null), for AnalyticPoseCostFunction. With A = R_C_B R_D_B^T and v = p_D_L - p_D_B:
  //   dp_C/ddp = -A,   dp_C/ddtheta = A [v]x      (left perturbation R_D_B <- Exp(dtheta) R_D_B)
  //   d(x, y)/dp_C = [1/Z 0 -X/Z^2; 0 1/Z -Y/Z^2]
  //   d(x_d, y_d)/d(x, y): the radtan polynomial's derivative (DistortionJacobian)
  //   J = sqrt(w) sqrt_info diag(fx, fy) d(x_d, y_d)/d(x, y) d(x, y)/dp_C [-A, A [v]x]
  bool EvaluateTangent(const double* pose_D_B, double* residuals,
                       Eigen::Matrix<double, 2, kPoseTangentSize, Eigen::RowMajor>* J) const {
    const Eigen::Map<const Eigen::Vector3d> p_D_B(pose_D_B);
    const Eigen::Map<const Eigen::Quaterniond> q_D_B(pose_D_B + 3);
    const Eigen::Matrix3d A = q_C_B_.toRotationMatrix() * q_D_B.toRotationMatrix().transpose();
    const Eigen::Vector3d v = p_D_L_ - p_D_B;
    const Eigen::Vector3d p_C = A * v + p_C_B_;
    if (!(p_C.z() > kMinDepth)) return false;
    const double inv_z = 1.0 / p_C.z();
    const double x = p_C.x() * inv_z, y = p_C.y() * inv_z;
    double x_d, y_d;
    DistortNormalized(distortion_, x, y, &x_d, &y_d);
    const Eigen::Vector2d e(fx_ * x_d + cx_ - uv_(0), fy_ * y_d + cy_ - uv_(1));
    Eigen::Map<Eigen::Vector2d> r(residuals);
    r = weighted_sqrt_info_ * e;
    if (J == nullptr) return true;
    Eigen::Matrix<double, 2, 3> d_xy_d_pC;
    d_xy_d_pC << inv_z, 0.0, -x * inv_z, 0.0, inv_z, -y * inv_z;
    const Eigen::Matrix2d d_e_d_xy =
        Eigen::Vector2d(fx_, fy_).asDiagonal() * DistortionJacobian(x, y);
    const Eigen::Matrix<double, 2, 3> d_r_d_pC = weighted_sqrt_info_ * d_e_d_xy * d_xy_d_pC;
    Eigen::Matrix3d v_cross;
    v_cross << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
    J->leftCols<3>() = -d_r_d_pC * A;
    J->rightCols<3>() = d_r_d_pC * A * v_cross;
    return true;
  }

  // The unweighted error pi(p_C) - uv (pixels); false (error untouched) when the light is behind
  // the camera.
  bool UnweightedError(const double* pose_D_B, Eigen::Vector2d* error) const {
    return Error(pose_D_B, error);
  }

  // e^T Sigma_uv^-1 e (chi-square, 2 degrees of freedom), without the stage weight; +infinity
  // when the light is behind the camera.
  double SquaredMahalanobis(const double* pose_D_B) const {
    Eigen::Vector2d e;
    if (!Error(pose_D_B, &e)) return std::numeric_limits<double>::infinity();
    return (sqrt_info_ * e).squaredNorm();
  }

  // The light in the camera frame, p_C (m); its z is the depth checked against kMinDepth.
  Eigen::Vector3d PointInCamera(const double* pose_D_B) const {
    return LightInCamera<double>(pose_D_B);
  }
  double DepthInCamera(const double* pose_D_B) const { return PointInCamera(pose_D_B).z(); }

  static ceres::CostFunction* Create(const Eigen::Vector2d& uv, const Eigen::Matrix2d& covariance,
                                     const PinholeRadtanCamera& camera, const Pose3& T_B_C,
                                     const Eigen::Vector3d& p_D_L,
                                     double information_weight = 1.0) {
    return Create(std::make_unique<MonoReprojectionFactor>(uv, covariance, camera, T_B_C, p_D_L,
                                                           information_weight));
  }
  // The same for a factor already built (e.g. after checking DepthInCamera).
  // Create gives the analytic Jacobian (EvaluateTangent); CreateAutoDiff differentiates the
  // templated operator() with ceres::Jet (the tests' reference).
  static ceres::CostFunction* Create(std::unique_ptr<MonoReprojectionFactor> factor) {
    return new AnalyticPoseCostFunction<MonoReprojectionFactor, kMonoResidualSize>(
        std::move(factor));
  }
  static ceres::CostFunction* CreateAutoDiff(std::unique_ptr<MonoReprojectionFactor> factor) {
    return new ceres::AutoDiffCostFunction<MonoReprojectionFactor, kMonoResidualSize, kPoseSize>(
        factor.release());
  }

  const Eigen::Vector2d& uv() const { return uv_; }
  const Eigen::Matrix2d& covariance() const { return covariance_; }
  // Without the stage weight.
  const Eigen::Matrix2d& sqrt_information() const { return sqrt_info_; }
  double information_weight() const { return information_weight_; }
  const Pose3& T_B_C() const { return T_B_C_; }
  const Eigen::Vector3d& p_D_L() const { return p_D_L_; }

 private:
  template <typename T>
  Eigen::Matrix<T, 3, 1> LightInCamera(const T* pose_D_B) const {
    using Vector3T = Eigen::Matrix<T, 3, 1>;
    const Eigen::Map<const Vector3T> p_D_B(pose_D_B);
    const Eigen::Map<const Eigen::Quaternion<T>> q_D_B(pose_D_B + 3);
    const Vector3T p_B = q_D_B.conjugate() * Vector3T(p_D_L_.cast<T>() - p_D_B);
    return q_C_B_.cast<T>() * p_B + p_C_B_.cast<T>();
  }

  // d(x_d, y_d)/d(x, y) of DistortNormalized, with R' = k1 + 2 k2 r2 + 3 k3 r2^2:
  //   dx_d/dx = radial + 2 x^2 R' + 2 p1 y + 6 p2 x,   dx_d/dy = 2 x y R' + 2 p1 x + 2 p2 y
  //   dy_d/dx = 2 x y R' + 2 p1 x + 2 p2 y,             dy_d/dy = radial + 2 y^2 R' + 6 p1 y + 2 p2 x
  Eigen::Matrix2d DistortionJacobian(double x, double y) const {
    const double k1 = distortion_[0], k2 = distortion_[1], p1 = distortion_[2],
                 p2 = distortion_[3], k3 = distortion_[4];
    const double r2 = x * x + y * y;
    const double radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3));
    const double slope = k1 + r2 * (2.0 * k2 + 3.0 * k3 * r2);
    const double cross = 2.0 * x * y * slope + 2.0 * p1 * x + 2.0 * p2 * y;
    Eigen::Matrix2d D;
    D << radial + 2.0 * x * x * slope + 2.0 * p1 * y + 6.0 * p2 * x, cross,
        cross, radial + 2.0 * y * y * slope + 6.0 * p1 * y + 2.0 * p2 * x;
    return D;
  }

  template <typename T>
  bool Error(const T* pose_D_B, Eigen::Matrix<T, 2, 1>* e) const {
    const Eigen::Matrix<T, 3, 1> p_C = LightInCamera<T>(pose_D_B);
    if (!(p_C.z() > T(kMinDepth))) return false;
    const T x = p_C.x() / p_C.z();
    const T y = p_C.y() / p_C.z();
    T x_d, y_d;
    DistortNormalized(distortion_, x, y, &x_d, &y_d);
    (*e)(0) = T(fx_) * x_d + T(cx_) - T(uv_(0));
    (*e)(1) = T(fy_) * y_d + T(cy_) - T(uv_(1));
    return true;
  }

  Eigen::Vector2d uv_;
  Eigen::Matrix2d covariance_;
  double fx_, fy_, cx_, cy_;
  std::array<double, 5> distortion_;
  Pose3 T_B_C_;
  Eigen::Vector3d p_D_L_;
  double information_weight_;
  Eigen::Matrix2d sqrt_info_;
  Eigen::Matrix2d weighted_sqrt_info_;
  Eigen::Quaterniond q_C_B_;
  Eigen::Vector3d p_C_B_;
};

}  // namespace auvdock
