// The preintegrated-IMU residual between two estimator states i and j (Forster, Carlone, Dellaert,
// Scaramuzza, "On-Manifold Preintegration for Real-Time Visual-Inertial Odometry", IEEE T-RO
// 2017, eq. 45 plus the bias random walk of the "combined" form).
//
// Parameter blocks (layouts in factors/pose_manifold.h, all in the dock frame D, z down):
//   pose_i [7] = p_D_Bi, q_D_Bi (x y z w)   velocity_i [3] = v_D_Bi   bias_i [6] = b_g, b_a
//   pose_j [7], velocity_j [3], bias_j [6]  likewise at t_j.
// Unweighted error e (15), with dt = t_j - t_i, g = g_D (m/s^2) and the preintegrated deltas
// corrected to bias_i to first order (ImuPreintegration::Correct):
//   e_theta = Log(dR(b_i)^T R_i^T R_j)                                     rad
//   e_v     = R_i^T (v_j - v_i - g dt) - dv(b_i)                           m/s
//   e_p     = R_i^T (p_j - p_i - v_i dt - 1/2 g dt^2) - dp(b_i)            m
//   e_bg    = b_g,j - b_g,i                                                rad/s
//   e_ba    = b_a,j - b_a,i                                                m/s^2
// Residual r = sqrt_info e, with sqrt_info^T sqrt_info = Sigma^-1 and Sigma (15 x 15) the
// block-diagonal of the preintegration covariance of (dtheta, dv, dp) and the bias random walk
// over the interval, sigma_bw^2 dt I3 for each bias (continuous density sigma_bw). Sigma is
// factored once here, never in Evaluate.
//
// e_theta and the pose's manifold: the rotation error is a right (body-frame) rotation vector, the
// pose manifold perturbs on the left in D; the chain rule through PlusJacobian joins the two, so
// nothing else is needed here (the GradientChecker test checks exactly that combination).
#pragma once

#include <stdexcept>

#include <ceres/autodiff_cost_function.h>
#include <ceres/jet.h>
#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Geometry>

#include "auvdock/imu/imu_preintegration.h"
#include "factors/pose_manifold.h"

namespace auvdock {

inline constexpr int kImuResidualSize = 15;

class ImuPreintegrationFactor {
 public:
  using Vector15 = Eigen::Matrix<double, kImuResidualSize, 1>;
  using Matrix15 = Eigen::Matrix<double, kImuResidualSize, kImuResidualSize>;

  // Throws std::invalid_argument if the preintegration is empty or its covariance (with the bias
  // walk) is not positive definite, e.g. zero noise densities.
  ImuPreintegrationFactor(const ImuPreintegration& preintegration, const Eigen::Vector3d& gravity_D)
      : preintegration_(preintegration), gravity_D_(gravity_D) {
    const double dt = preintegration_.sum_dt();
    if (preintegration_.num_samples() == 0 || !(dt > 0.0)) {
      throw std::invalid_argument("ImuPreintegrationFactor: the preintegration has no samples");
    }
    if (!gravity_D_.allFinite()) {
      throw std::invalid_argument("ImuPreintegrationFactor: gravity_D is not finite");
    }
    const ImuNoiseDensities& noise = preintegration_.noise();
    covariance_.setZero();
    covariance_.topLeftCorner<9, 9>() = preintegration_.covariance();
    covariance_.block<3, 3>(9, 9).diagonal().setConstant(noise.gyroscope_random_walk *
                                                         noise.gyroscope_random_walk * dt);
    covariance_.block<3, 3>(12, 12).diagonal().setConstant(noise.accelerometer_random_walk *
                                                           noise.accelerometer_random_walk * dt);
    // Sigma = L L^T  =>  Sigma^-1 = L^-T L^-1, so sqrt_info = L^-1.
    const Eigen::LLT<Matrix15> llt(covariance_);
    if (llt.info() != Eigen::Success) {
      throw std::invalid_argument(
          "ImuPreintegrationFactor: covariance is not positive definite (zero noise densities?)");
    }
    sqrt_info_ = llt.matrixL().solve(Matrix15::Identity());
  }

  template <typename T>
  bool operator()(const T* pose_i, const T* velocity_i, const T* bias_i, const T* pose_j,
                  const T* velocity_j, const T* bias_j, T* residuals) const {
    Whiten(sqrt_info_, Error(pose_i, velocity_i, bias_i, pose_j, velocity_j, bias_j), residuals);
    return true;
  }

  // The unweighted error e (rad, m/s, m, rad/s, m/s^2) for gating and evaluation.
  Vector15 UnweightedError(const double* pose_i, const double* velocity_i, const double* bias_i,
                           const double* pose_j, const double* velocity_j,
                           const double* bias_j) const {
    return Error(pose_i, velocity_i, bias_i, pose_j, velocity_j, bias_j);
  }

  // The whitened squared error e^T Sigma^-1 e (chi-square with 15 degrees of freedom).
  double SquaredMahalanobis(const double* pose_i, const double* velocity_i, const double* bias_i,
                            const double* pose_j, const double* velocity_j,
                            const double* bias_j) const {
    return (sqrt_info_ * UnweightedError(pose_i, velocity_i, bias_i, pose_j, velocity_j, bias_j))
        .squaredNorm();
  }

  static ceres::CostFunction* Create(const ImuPreintegration& preintegration,
                                     const Eigen::Vector3d& gravity_D) {
    return new ceres::AutoDiffCostFunction<ImuPreintegrationFactor, kImuResidualSize, kPoseSize,
                                           kVelocitySize, kBiasSize, kPoseSize, kVelocitySize,
                                           kBiasSize>(
        new ImuPreintegrationFactor(preintegration, gravity_D));
  }

  const ImuPreintegration& preintegration() const { return preintegration_; }
  const Eigen::Vector3d& gravity_D() const { return gravity_D_; }
  const Matrix15& covariance() const { return covariance_; }
  const Matrix15& sqrt_information() const { return sqrt_info_; }

 private:
  template <typename T>
  Eigen::Matrix<T, kImuResidualSize, 1> Error(const T* pose_i, const T* velocity_i, const T* bias_i,
                                              const T* pose_j, const T* velocity_j,
                                              const T* bias_j) const {
    using Vector3T = Eigen::Matrix<T, 3, 1>;
    const Eigen::Map<const Vector3T> p_i(pose_i);
    const Eigen::Map<const Eigen::Quaternion<T>> q_i(pose_i + 3);
    const Eigen::Map<const Vector3T> v_i(velocity_i);
    const Eigen::Map<const Vector3T> bg_i(bias_i);
    const Eigen::Map<const Vector3T> ba_i(bias_i + 3);
    const Eigen::Map<const Vector3T> p_j(pose_j);
    const Eigen::Map<const Eigen::Quaternion<T>> q_j(pose_j + 3);
    const Eigen::Map<const Vector3T> v_j(velocity_j);
    const Eigen::Map<const Vector3T> bg_j(bias_j);
    const Eigen::Map<const Vector3T> ba_j(bias_j + 3);

    // Constants stay double so that they enter the Jets as cheap mixed products.
    const double dt = preintegration_.sum_dt();
    const Eigen::Vector3d g_dt = gravity_D_ * dt;
    const Eigen::Vector3d half_g_dt2 = 0.5 * gravity_D_ * dt * dt;
    const CorrectedImuDeltas<T> d = preintegration_.Correct<T>(Vector3T(bg_i), Vector3T(ba_i));
    const Eigen::Quaternion<T> dq =
        preintegration_.delta_q().cast<T>() * QuaternionExp<T>(d.rotation_correction);
    const Eigen::Quaternion<T> q_i_inv = q_i.conjugate();

    Eigen::Matrix<T, kImuResidualSize, 1> e;
    e.template segment<3>(0) = QuaternionLog<T>(dq.conjugate() * (q_i_inv * q_j));
    e.template segment<3>(3) = q_i_inv * Vector3T(v_j - v_i - g_dt) - d.delta_v;
    e.template segment<3>(6) = q_i_inv * Vector3T(p_j - p_i - v_i * dt - half_g_dt2) - d.delta_p;
    e.template segment<3>(9) = bg_j - bg_i;
    e.template segment<3>(12) = ba_j - ba_i;
    return e;
  }

  // r = sqrt_info e; sqrt_info is lower triangular (the inverse of the Cholesky factor).
  template <typename T>
  static void Whiten(const Matrix15& sqrt_info, const Eigen::Matrix<T, kImuResidualSize, 1>& e,
                     T* residuals) {
    Eigen::Map<Eigen::Matrix<T, kImuResidualSize, 1>> r(residuals);
    r = sqrt_info.triangularView<Eigen::Lower>() * e;
  }
  // The same for Jets, as one double product over the value and derivative parts. Done Jet by
  // Jet it is 120 Jet multiply-adds with temporaries, which took ~2/3 of an Evaluate with
  // Jacobians in benchmarks/imu_preintegration_benchmark.cc.
  template <int N>
  static void Whiten(const Matrix15& sqrt_info,
                     const Eigen::Matrix<ceres::Jet<double, N>, kImuResidualSize, 1>& e,
                     ceres::Jet<double, N>* residuals) {
    Eigen::Matrix<double, kImuResidualSize, N + 1> parts;
    for (int k = 0; k < kImuResidualSize; ++k) {
      parts(k, 0) = e[k].a;
      parts.row(k).template tail<N>() = e[k].v.transpose();
    }
    const Eigen::Matrix<double, kImuResidualSize, N + 1> whitened =
        sqrt_info.triangularView<Eigen::Lower>() * parts;
    for (int k = 0; k < kImuResidualSize; ++k) {
      residuals[k].a = whitened(k, 0);
      residuals[k].v = whitened.row(k).template tail<N>().transpose();
    }
  }

  ImuPreintegration preintegration_;
  Eigen::Vector3d gravity_D_;
  Matrix15 covariance_;
  Matrix15 sqrt_info_;
};

}  // namespace auvdock
