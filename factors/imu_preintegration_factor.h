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
// With the Earth's rotation (w = w_ie_D, constant in the Earth-fixed D; zero: none, as above):
// the gyro measures the body's rate against inertial space, and D itself turns at w, so
// R_j = Exp(-w dt) R_i dR exactly, and in D the velocity feels the Coriolis acceleration
// -2 w x v and the turning of D under the specific force. To first order in w (its square
// over a second is 5e-9), with a = R_i^T w (in B_i) and the interval's mean specific force
// (dv / dt) for the position's share:
//   e_theta = Log(dR(b_i)^T R_i^T Exp(w dt) R_j)
//   e_v     = R_i^T (v_j - v_i - g dt + 2 w x (p_j - p_i)) - dv(b_i) + a x (dt dv(b_i) - dp(b_i))
//   e_p     = R_i^T (p_j - p_i - v_i dt - 1/2 g dt^2 + w x v_i dt^2) - dp(b_i)
//             + a x dv(b_i) dt^2 / 6
// (over 0.1 s the position's terms are 1e-6 m; over 1 s, 1e-4 m).
// Residual r = sqrt_info e, with sqrt_info^T sqrt_info = Sigma^-1 and Sigma (15 x 15) the
// block-diagonal of the preintegration covariance of (dtheta, dv, dp) and the bias random walk
// over the interval, sigma_bw^2 dt I3 for each bias (continuous density sigma_bw). Sigma is
// factored once here, never in Evaluate.
//
// Jacobians (analytic; Forster's appendix, adapted to the pose manifold's left perturbation in D,
// x <- (p + dp, Exp(dtheta) R)). With E = dR(b_i)^T R_i^T R_j, Jr^-1 = Jr^-1(e_theta),
// w_v = v_j - v_i - g dt, w_p = p_j - p_i - v_i dt - 1/2 g dt^2 and phi = J_theta_bg db_g:
//   d e_theta / d dtheta_i = -Jr^-1 R_j^T      d e_theta / d dtheta_j = Jr^-1 R_j^T
//   d e_theta / d b_g,i    = -Jr^-1 E^T Jr(phi) J_theta_bg
//   d e_v / d dtheta_i     = R_i^T [w_v]x      d e_v / d v_i = -R_i^T    d e_v / d v_j = R_i^T
//   d e_p / d dtheta_i     = R_i^T [w_p]x      d e_p / d p_i = -R_i^T    d e_p / d p_j = R_i^T
//   d e_p / d v_i          = -R_i^T dt
//   d (e_v, e_p) / d b_i   = -(J_v_bg, J_v_ba; J_p_bg, J_p_ba)
//   d e_b / d b_i = -I,  d e_b / d b_j = I.
// With the Earth's rotation (W = [w]x, O = Exp(w dt), c_v = dt dv - dp, c_p = dv dt^2 / 6, and
// w_v, w_p including the Coriolis terms): d e_theta / d dtheta_i = -Jr^-1 R_j^T O^T;
// d e_v / d dtheta_i += -[c_v]x R_i^T W, d e_v / d p_i = -2 R_i^T W, d e_v / d p_j = 2 R_i^T W;
// d e_p / d dtheta_i += -[c_p]x R_i^T W, d e_p / d v_i += R_i^T W dt^2;
// d e_v / d b_i += [a]x (dt J_v_b - J_p_b), d e_p / d b_i += [a]x J_v_b dt^2 / 6.
// Ceres asks for derivatives with respect to the 7 ambient numbers of a pose block; they are the
// tangent Jacobian times MinusJacobian(x) (6 x 7, the pose manifold's "lift"). That is the exact
// derivative of the residual written with the normalized quaternion q/|q| (which is what Evaluate
// computes), so J_ambient * PlusJacobian = J_tangent holds exactly: a true manifold, no padded
// Jacobian. CreateAutoDiff gives the same residual differentiated by ceres::Jet; the tests check
// the analytic Jacobians against it and against GradientChecker. The analytic form is ~4x faster
// (benchmarks/imu_preintegration_benchmark.cc) and the IMU factor was a quarter of the window
// update's time with autodiff.
#pragma once

#include <stdexcept>
#include <string>

#include <ceres/autodiff_cost_function.h>
#include <ceres/sized_cost_function.h>
#include <ceres/jet.h>
#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Geometry>

#include "auvdock/geometry/so3.h"
#include "auvdock/imu/imu_preintegration.h"
#include "factors/pose_manifold.h"
#include "factors/tangent_jacobians.h"

namespace auvdock {

inline constexpr int kImuResidualSize = 15;

class ImuPreintegrationFactor final
    : public ceres::SizedCostFunction<15, kPoseSize, kVelocitySize, kBiasSize, kPoseSize,
                                      kVelocitySize, kBiasSize>,
      public TangentJacobians {
 public:
  using Vector15 = Eigen::Matrix<double, kImuResidualSize, 1>;
  using Matrix15 = Eigen::Matrix<double, kImuResidualSize, kImuResidualSize>;

  // Throws std::invalid_argument if the preintegration is empty or its covariance (with the bias
  // walk) is not positive definite, e.g. zero noise densities.
  // earth_rate_D: the Earth's rotation in D (geometry/dock_model.h EarthRate_D; zero: none).
  ImuPreintegrationFactor(const ImuPreintegration& preintegration, const Eigen::Vector3d& gravity_D,
                          const Eigen::Vector3d& earth_rate_D = Eigen::Vector3d::Zero())
      : preintegration_(preintegration), gravity_D_(gravity_D), earth_rate_D_(earth_rate_D) {
    const double dt = preintegration_.sum_dt();
    if (preintegration_.num_samples() == 0 || !(dt > 0.0)) {
      throw std::invalid_argument("ImuPreintegrationFactor: the preintegration has no samples");
    }
    if (!gravity_D_.allFinite() || !earth_rate_D_.allFinite()) {
      throw std::invalid_argument(
          "ImuPreintegrationFactor: gravity_D or earth_rate_D is not finite");
    }
    earth_turn_q_ = QuaternionExp<double>(Eigen::Vector3d(earth_rate_D_ * dt));
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
          "ImuPreintegrationFactor: covariance is not positive definite (zero noise densities?) "
          "over " + std::to_string(dt) + " s, " + std::to_string(preintegration_.num_samples()) +
          " samples");
    }
    sqrt_info_ = llt.matrixL().solve(Matrix15::Identity());
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

  // The analytic factor (production).
  static ceres::CostFunction* Create(
      const ImuPreintegration& preintegration, const Eigen::Vector3d& gravity_D,
      const Eigen::Vector3d& earth_rate_D = Eigen::Vector3d::Zero()) {
    return new ImuPreintegrationFactor(preintegration, gravity_D, earth_rate_D);
  }
  // The same residual with automatic derivatives: the reference for tests and benchmarks.
  static ceres::CostFunction* CreateAutoDiff(
      const ImuPreintegration& preintegration, const Eigen::Vector3d& gravity_D,
      const Eigen::Vector3d& earth_rate_D = Eigen::Vector3d::Zero());

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    return EvaluateImpl(parameters, residuals, jacobians, /*tangent=*/false);
  }
  // The pose blocks' Jacobians in their tangent space (15 x 6), not lifted (tangent_jacobians.h).
  bool EvaluateInTangentSpace(double const* const* parameters, double* residuals,
                              double** jacobians) const override {
    return EvaluateImpl(parameters, residuals, jacobians, /*tangent=*/true);
  }

  const ImuPreintegration& preintegration() const { return preintegration_; }
  const Eigen::Vector3d& gravity_D() const { return gravity_D_; }
  const Eigen::Vector3d& earth_rate_D() const { return earth_rate_D_; }
  const Matrix15& covariance() const { return covariance_; }

 private:
  bool EvaluateImpl(double const* const* parameters, double* residuals, double** jacobians,
                    bool tangent) const {
    using Eigen::Matrix3d;
    using Eigen::Vector3d;
    const Eigen::Map<const Vector3d> p_i(parameters[0]);
    const Eigen::Quaterniond q_i =
        Eigen::Map<const Eigen::Quaterniond>(parameters[0] + 3).normalized();
    const Eigen::Map<const Vector3d> v_i(parameters[1]);
    const Eigen::Map<const Vector3d> bg_i(parameters[2]);
    const Eigen::Map<const Vector3d> ba_i(parameters[2] + 3);
    const Eigen::Map<const Vector3d> p_j(parameters[3]);
    const Eigen::Quaterniond q_j =
        Eigen::Map<const Eigen::Quaterniond>(parameters[3] + 3).normalized();
    const Eigen::Map<const Vector3d> v_j(parameters[4]);
    const Eigen::Map<const Vector3d> bg_j(parameters[5]);
    const Eigen::Map<const Vector3d> ba_j(parameters[5] + 3);

    const double dt = preintegration_.sum_dt();
    const CorrectedImuDeltas<double> d = preintegration_.Correct<double>(bg_i, ba_i);
    const Eigen::Quaterniond dq =
        preintegration_.delta_q() * QuaternionExp<double>(d.rotation_correction);
    const Eigen::Quaterniond error_q = dq.conjugate() * (q_i.conjugate() * (earth_turn_q_ * q_j));
    const Matrix3d R_i_T = q_i.toRotationMatrix().transpose();
    const Vector3d& w = earth_rate_D_;
    const Vector3d w_v = v_j - v_i - gravity_D_ * dt + 2.0 * w.cross(p_j - p_i);
    const Vector3d w_p = p_j - p_i - v_i * dt - 0.5 * gravity_D_ * dt * dt + w.cross(v_i) * dt * dt;
    const Vector3d a = R_i_T * w;  // the Earth's rate in B_i
    const Vector3d c_v = dt * d.delta_v - d.delta_p;
    const Vector3d c_p = d.delta_v * (dt * dt / 6.0);

    Vector15 e;
    e.segment<3>(0) = QuaternionLog<double>(error_q);
    e.segment<3>(3) = R_i_T * w_v - d.delta_v + a.cross(c_v);
    e.segment<3>(6) = R_i_T * w_p - d.delta_p + a.cross(c_p);
    e.segment<3>(9) = bg_j - bg_i;
    e.segment<3>(12) = ba_j - ba_i;
    const auto L = sqrt_info_.triangularView<Eigen::Lower>();
    Eigen::Map<Vector15> r(residuals);
    r = L * e;
    if (jacobians == nullptr) return true;

    const Matrix3d Jr_inv = InverseRightJacobianSO3(e.segment<3>(0));
    const Matrix3d R_j_T = q_j.toRotationMatrix().transpose();
    const Matrix3d I = Matrix3d::Identity();
    using Matrix15x6 = Eigen::Matrix<double, kImuResidualSize, 6>;
    using Matrix15x3 = Eigen::Matrix<double, kImuResidualSize, 3>;
    // Pose blocks: tangent (dp, dtheta) Jacobian, whitened, then lifted to the 7 ambient numbers
    // (or left in the tangent space).
    auto write_pose = [&](const Matrix15x6& J_tangent, const double* pose, double* out) {
      if (tangent) {
        Eigen::Map<Eigen::Matrix<double, kImuResidualSize, kPoseTangentSize, Eigen::RowMajor>>
            J_out(out);
        J_out = L * J_tangent;
        return;
      }
      Eigen::Matrix<double, kPoseTangentSize, kPoseSize, Eigen::RowMajor> lift;
      PoseManifold().MinusJacobian(pose, lift.data());
      Eigen::Map<Eigen::Matrix<double, kImuResidualSize, kPoseSize, Eigen::RowMajor>> J_out(out);
      J_out = (L * J_tangent) * lift;
    };
    const Matrix3d W = Hat(w);
    if (jacobians[0] != nullptr) {
      Matrix15x6 J = Matrix15x6::Zero();
      J.block<3, 3>(0, 3) = -Jr_inv * R_j_T * earth_turn_q_.toRotationMatrix().transpose();
      J.block<3, 3>(3, 0) = -2.0 * R_i_T * W;
      J.block<3, 3>(3, 3) = R_i_T * Hat(w_v) - Hat(c_v) * R_i_T * W;
      J.block<3, 3>(6, 0) = -R_i_T;
      J.block<3, 3>(6, 3) = R_i_T * Hat(w_p) - Hat(c_p) * R_i_T * W;
      write_pose(J, parameters[0], jacobians[0]);
    }
    if (jacobians[1] != nullptr) {
      Matrix15x3 J = Matrix15x3::Zero();
      J.block<3, 3>(3, 0) = -R_i_T;
      J.block<3, 3>(6, 0) = -R_i_T * dt + R_i_T * W * (dt * dt);
      Eigen::Map<Eigen::Matrix<double, kImuResidualSize, 3, Eigen::RowMajor>> J_out(jacobians[1]);
      J_out = L * J;
    }
    if (jacobians[2] != nullptr) {
      Matrix15x6 J = Matrix15x6::Zero();
      const Matrix3d E = error_q.toRotationMatrix();
      J.block<3, 3>(0, 0) = -Jr_inv * E.transpose() * RightJacobianSO3(d.rotation_correction) *
                            preintegration_.J_theta_bg();
      const Matrix3d A = Hat(a);
      J.block<3, 3>(3, 0) = -preintegration_.J_v_bg() +
                            A * (dt * preintegration_.J_v_bg() - preintegration_.J_p_bg());
      J.block<3, 3>(3, 3) = -preintegration_.J_v_ba() +
                            A * (dt * preintegration_.J_v_ba() - preintegration_.J_p_ba());
      J.block<3, 3>(6, 0) =
          -preintegration_.J_p_bg() + A * preintegration_.J_v_bg() * (dt * dt / 6.0);
      J.block<3, 3>(6, 3) =
          -preintegration_.J_p_ba() + A * preintegration_.J_v_ba() * (dt * dt / 6.0);
      J.block<3, 3>(9, 0) = -I;
      J.block<3, 3>(12, 3) = -I;
      Eigen::Map<Eigen::Matrix<double, kImuResidualSize, 6, Eigen::RowMajor>> J_out(jacobians[2]);
      J_out = L * J;
    }
    if (jacobians[3] != nullptr) {
      Matrix15x6 J = Matrix15x6::Zero();
      J.block<3, 3>(0, 3) = Jr_inv * R_j_T;
      J.block<3, 3>(3, 0) = 2.0 * R_i_T * W;
      J.block<3, 3>(6, 0) = R_i_T;
      write_pose(J, parameters[3], jacobians[3]);
    }
    if (jacobians[4] != nullptr) {
      Matrix15x3 J = Matrix15x3::Zero();
      J.block<3, 3>(3, 0) = R_i_T;
      Eigen::Map<Eigen::Matrix<double, kImuResidualSize, 3, Eigen::RowMajor>> J_out(jacobians[4]);
      J_out = L * J;
    }
    if (jacobians[5] != nullptr) {
      Matrix15x6 J = Matrix15x6::Zero();
      J.block<3, 3>(9, 0) = I;
      J.block<3, 3>(12, 3) = I;
      Eigen::Map<Eigen::Matrix<double, kImuResidualSize, 6, Eigen::RowMajor>> J_out(jacobians[5]);
      J_out = L * J;
    }
    return true;
  }

 public:
  const Matrix15& sqrt_information() const { return sqrt_info_; }

 private:
  struct AutoDiffResidual;

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
    const Vector3T w = earth_rate_D_.cast<T>();
    const Vector3T a = q_i_inv * w;
    const Vector3T c_v = d.delta_v * T(dt) - d.delta_p;
    const Vector3T c_p = d.delta_v * T(dt * dt / 6.0);
    const Eigen::Quaternion<T> turned_q_j = earth_turn_q_.cast<T>() * q_j;

    Eigen::Matrix<T, kImuResidualSize, 1> e;
    e.template segment<3>(0) = QuaternionLog<T>(dq.conjugate() * (q_i_inv * turned_q_j));
    e.template segment<3>(3) =
        q_i_inv * Vector3T(v_j - v_i - g_dt + T(2.0) * w.cross(Vector3T(p_j - p_i))) - d.delta_v +
        a.cross(c_v);
    e.template segment<3>(6) = q_i_inv * Vector3T(p_j - p_i - v_i * dt - half_g_dt2 +
                                                  w.cross(Vector3T(v_i)) * T(dt * dt)) -
                               d.delta_p + a.cross(c_p);
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
  Eigen::Vector3d earth_rate_D_;
  Eigen::Quaterniond earth_turn_q_ = Eigen::Quaterniond::Identity();  // Exp(w dt)
  Matrix15 covariance_;
  Matrix15 sqrt_info_;
};

// The residual as a functor of templated blocks, for ceres::AutoDiffCostFunction.
struct ImuPreintegrationFactor::AutoDiffResidual {
  template <typename T>
  bool operator()(const T* pose_i, const T* velocity_i, const T* bias_i, const T* pose_j,
                  const T* velocity_j, const T* bias_j, T* residuals) const {
    Whiten(factor.sqrt_info_,
           factor.Error(pose_i, velocity_i, bias_i, pose_j, velocity_j, bias_j), residuals);
    return true;
  }
  ImuPreintegrationFactor factor;
};

inline ceres::CostFunction* ImuPreintegrationFactor::CreateAutoDiff(
    const ImuPreintegration& preintegration, const Eigen::Vector3d& gravity_D,
    const Eigen::Vector3d& earth_rate_D) {
  return new ceres::AutoDiffCostFunction<AutoDiffResidual, kImuResidualSize, kPoseSize,
                                         kVelocitySize, kBiasSize, kPoseSize, kVelocitySize,
                                         kBiasSize>(
      new AutoDiffResidual{ImuPreintegrationFactor(preintegration, gravity_D, earth_rate_D)});
}

}  // namespace auvdock
