// On-manifold IMU preintegration between two estimator states i and j (Forster, Carlone, Dellaert,
// Scaramuzza, "On-Manifold Preintegration for Real-Time Visual-Inertial Odometry", IEEE T-RO
// 2017; equation numbers below refer to that paper and its appendix).
//
// Frames and units: body B = IMU frame (x forward, y right, z down); navigation frame = dock
// frame D (z down), gravity g_D a vector (nominally (0, 0, +9.81) m/s^2). A sample is the body
// rate w_B (rad/s) and the specific force f_B = R_D_B^T (a_D - g_D) (m/s^2), both with biases
// b_g, b_a (in B) added. Time in seconds (dt_s) at this interface; durations are short (< 1 min),
// so double seconds lose nothing.
//
// Discretisation: Euler, each sample held constant over its dt (sample-and-hold, as in Forster
// eq. 24-26 and GTSAM's ManifoldPreintegration). With a = f - b_a_hat, w = w_B - b_g_hat:
//   dp_{k+1} = dp_k + dv_k dt + 1/2 dR_k a dt^2
//   dv_{k+1} = dv_k + dR_k a dt
//   dR_{k+1} = dR_k Exp(w dt)
// dR is exact for a rate held over the step, but dv and dp also hold the attitude at dR_k within
// it, and a real rate is not held. So for smooth motion all deltas are first-order in dt; the
// attitude error (1/2 dt |dw/dt| per second) times |f| ~ g dominates: on the test trajectory
// 1 kHz over 2 s leaves 2.7e-4 rad, 3.7e-3 m/s, 2.7e-3 m, and 200 Hz five times that. It is the
// scheme GTSAM's regression values come from; they are matched to 5e-9 (their printed digits).
//
// Prediction (eq. 33 with the bias correction of eq. 44), dt_ij = sum of dt:
//   R_j = R_i dR(b),   v_j = v_i + g dt_ij + R_i dv(b),   p_j = p_i + v_i dt_ij + 1/2 g dt_ij^2
//   + R_i dp(b), where dR(b) = dR Exp(J_theta_bg db_g), dv(b) = dv + J_v_bg db_g + J_v_ba db_a,
//   dp(b) = dp + J_p_bg db_g + J_p_ba db_a and db = b - b_hat (the linearisation bias).
//
// Covariance of the preintegration error (dtheta, dv, dp) with dR_meas = dR_true Exp(dtheta),
// dv_meas = dv_true + dv, dp_meas = dp_true + dp (eq. 62-63), propagated per sample with the
// discrete noise sigma_d^2 = sigma_c^2 / dt of the continuous densities. The bias random walk is
// not part of it: within one interval the bias is held at b_hat; the factor adds the walk
// (sigma_bw^2 dt_ij) on its own bias residual.
#pragma once

#include <cmath>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "auvdock/imu/nav_state.h"

namespace auvdock {

struct ImuCalibration;

// IMU biases in B: gyro (rad/s) and accelerometer (m/s^2). Stored in a parameter block as
// [b_g, b_a] (factors/pose_manifold.h).
struct ImuBias {
  Eigen::Vector3d gyro = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel = Eigen::Vector3d::Zero();
};

// Continuous-time noise densities (Kalibr / EuRoC names and units, as in ImuCalibration).
struct ImuNoiseDensities {
  double gyroscope_noise_density = 3.4e-4;      // rad/s/sqrt(Hz)
  double gyroscope_random_walk = 3.9e-5;        // rad/s^2/sqrt(Hz)
  double accelerometer_noise_density = 4.0e-3;  // m/s^2/sqrt(Hz)
  double accelerometer_random_walk = 6.0e-3;    // m/s^3/sqrt(Hz)

  static ImuNoiseDensities FromCalibration(const ImuCalibration& calibration);
};

// Bias-corrected deltas for a (possibly Jet-typed) bias. The rotation is returned as the
// first-order correction phi with dR(b) = dR_hat Exp(phi), so that this header needs no templated
// exponential; the factor applies QuaternionExp from factors/pose_manifold.h.
template <typename T>
struct CorrectedImuDeltas {
  Eigen::Matrix<T, 3, 1> rotation_correction;  // phi (rad), applied on the right of delta_q()
  Eigen::Matrix<T, 3, 1> delta_v;              // m/s, in B_i
  Eigen::Matrix<T, 3, 1> delta_p;              // m, in B_i
};

class ImuPreintegration {
 public:
  // Noise densities must be finite and >= 0 (zero gives a deterministic, singular covariance;
  // the factor then refuses it). Throws std::invalid_argument otherwise.
  ImuPreintegration(const ImuNoiseDensities& noise, const ImuBias& linearization_bias);

  // Adds one sample held over dt_s (> 0, seconds): w_B (rad/s) and specific force f_B (m/s^2),
  // both raw (the linearisation bias is removed here). Throws std::invalid_argument on dt_s <= 0
  // or a non-finite value; the state is unchanged then.
  void Integrate(const Eigen::Vector3d& gyro_B, const Eigen::Vector3d& accel_B, double dt_s);

  // Clears all samples and starts again about a new linearisation bias (re-preintegration after
  // the bias estimate moved too far for the first-order correction).
  void Reset(const ImuBias& linearization_bias);

  double sum_dt() const { return sum_dt_; }
  int num_samples() const { return num_samples_; }
  const Eigen::Quaterniond& delta_q() const { return delta_q_; }  // dR = R_Bi_Bj
  const Eigen::Vector3d& delta_v() const { return delta_v_; }     // m/s, in B_i
  const Eigen::Vector3d& delta_p() const { return delta_p_; }     // m, in B_i
  const Eigen::Matrix3d& J_theta_bg() const { return J_theta_bg_; }
  const Eigen::Matrix3d& J_v_bg() const { return J_v_bg_; }
  const Eigen::Matrix3d& J_v_ba() const { return J_v_ba_; }
  const Eigen::Matrix3d& J_p_bg() const { return J_p_bg_; }
  const Eigen::Matrix3d& J_p_ba() const { return J_p_ba_; }
  // 9 x 9 covariance of (dtheta (rad), dv (m/s), dp (m)).
  const Eigen::Matrix<double, 9, 9>& covariance() const { return covariance_; }
  const ImuBias& linearization_bias() const { return linearization_bias_; }
  const ImuNoiseDensities& noise() const { return noise_; }

  // State j predicted from state i with the bias `bias` (first-order corrected deltas). With
  // the Earth's rotation earth_rate_D (zero: none), to first order in it, as the IMU factor
  // models it (factors/imu_preintegration_factor.h): R_j = Exp(-w dt) R_i dR(b),
  // p_j = p_i + v_i dt + 1/2 g dt^2 + R_i dp(b) - w x R_i dv(b) dt^2 / 6 - w x v_i dt^2,
  // v_j = v_i + g dt + R_i dv(b) - w x R_i (dt dv(b) - dp(b)) - 2 w x (p_j - p_i).
  NavState Predict(const NavState& state_i, const ImuBias& bias, const Eigen::Vector3d& gravity_D,
                   const Eigen::Vector3d& earth_rate_D = Eigen::Vector3d::Zero()) const;

  // The deltas corrected to the bias (b_g, b_a) to first order; T is double or a ceres::Jet.
  // The constant terms stay double (mixed double-Jet products, which ceres/jet.h enables for
  // Eigen): casting them to Jets would make every product carry a zero derivative part, several
  // times slower in the factor's autodiff.
  template <typename T>
  CorrectedImuDeltas<T> Correct(const Eigen::Matrix<T, 3, 1>& gyro_bias,
                                const Eigen::Matrix<T, 3, 1>& accel_bias) const {
    const Eigen::Matrix<T, 3, 1> dbg = gyro_bias - linearization_bias_.gyro;
    const Eigen::Matrix<T, 3, 1> dba = accel_bias - linearization_bias_.accel;
    CorrectedImuDeltas<T> out;
    out.rotation_correction = J_theta_bg_ * dbg;
    out.delta_v = J_v_bg_ * dbg + J_v_ba_ * dba + delta_v_;
    out.delta_p = J_p_bg_ * dbg + J_p_ba_ * dba + delta_p_;
    return out;
  }

 private:
  ImuNoiseDensities noise_;
  ImuBias linearization_bias_;

  double sum_dt_ = 0.0;
  int num_samples_ = 0;
  Eigen::Quaterniond delta_q_ = Eigen::Quaterniond::Identity();
  Eigen::Vector3d delta_v_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d delta_p_ = Eigen::Vector3d::Zero();
  Eigen::Matrix3d J_theta_bg_ = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d J_v_bg_ = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d J_v_ba_ = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d J_p_bg_ = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d J_p_ba_ = Eigen::Matrix3d::Zero();
  Eigen::Matrix<double, 9, 9> covariance_ = Eigen::Matrix<double, 9, 9>::Zero();
};

// Right Jacobian of SO(3), Jr(phi) = d Log(Exp(phi)^-1 Exp(phi + dphi)) / d dphi (Forster eq. 8):
//   Jr = I - (1 - cos|phi|)/|phi|^2 [phi]x + (|phi| - sin|phi|)/|phi|^3 [phi]x^2.
Eigen::Matrix3d RightJacobianSO3(const Eigen::Vector3d& phi);

// Its inverse, Jr^-1(phi) = d dphi / d Log(...) (Forster eq. 9):
//   Jr^-1 = I + 1/2 [phi]x + (1/|phi|^2 - (1 + cos|phi|)/(2 |phi| sin|phi|)) [phi]x^2,
// valid for |phi| < pi (the rotation errors of the factors are far from pi).
Eigen::Matrix3d InverseRightJacobianSO3(const Eigen::Vector3d& phi);

}  // namespace auvdock
