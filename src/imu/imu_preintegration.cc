#include "auvdock/imu/imu_preintegration.h"

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

#include "auvdock/geometry/so3.h"
#include "auvdock/io/calibration.h"

namespace auvdock {

namespace {

void CheckDensity(double value, const char* name) {
  if (!std::isfinite(value) || value < 0.0) {
    std::ostringstream message;
    message << "ImuPreintegration: " << name << " must be finite and >= 0, got " << value;
    throw std::invalid_argument(message.str());
  }
}

void CheckFiniteVector(const Eigen::Vector3d& v, const char* name) {
  if (!v.allFinite()) {
    std::ostringstream message;
    message << "ImuPreintegration: " << name << " is not finite: (" << v.x() << ", " << v.y()
            << ", " << v.z() << ")";
    throw std::invalid_argument(message.str());
  }
}

void CheckNoise(const ImuNoiseDensities& noise) {
  CheckDensity(noise.gyroscope_noise_density, "gyroscope_noise_density");
  CheckDensity(noise.gyroscope_random_walk, "gyroscope_random_walk");
  CheckDensity(noise.accelerometer_noise_density, "accelerometer_noise_density");
  CheckDensity(noise.accelerometer_random_walk, "accelerometer_random_walk");
}

void CheckBias(const ImuBias& bias) {
  CheckFiniteVector(bias.gyro, "linearization gyro bias");
  CheckFiniteVector(bias.accel, "linearization accel bias");
}

}  // namespace

ImuNoiseDensities ImuNoiseDensities::FromCalibration(const ImuCalibration& calibration) {
  ImuNoiseDensities noise;
  noise.gyroscope_noise_density = calibration.gyroscope_noise_density;
  noise.gyroscope_random_walk = calibration.gyroscope_random_walk;
  noise.accelerometer_noise_density = calibration.accelerometer_noise_density;
  noise.accelerometer_random_walk = calibration.accelerometer_random_walk;
  return noise;
}

Eigen::Matrix3d RightJacobianSO3(const Eigen::Vector3d& phi) {
  const double theta_sq = phi.squaredNorm();
  const Eigen::Matrix3d W = Hat(phi);
  if (theta_sq < 1e-10) {
    // Series to second order; the next terms are O(theta^3), below 1e-15 here.
    return Eigen::Matrix3d::Identity() - 0.5 * W + (1.0 / 6.0) * W * W;
  }
  const double theta = std::sqrt(theta_sq);
  return Eigen::Matrix3d::Identity() - (1.0 - std::cos(theta)) / theta_sq * W +
         (theta - std::sin(theta)) / (theta_sq * theta) * W * W;
}

Eigen::Matrix3d InverseRightJacobianSO3(const Eigen::Vector3d& phi) {
  const double theta_sq = phi.squaredNorm();
  const Eigen::Matrix3d W = Hat(phi);
  if (theta_sq < 1e-10) {
    // Series: the [phi]x^2 coefficient is 1/12 + theta^2/720 + O(theta^4).
    return Eigen::Matrix3d::Identity() + 0.5 * W + (1.0 / 12.0) * W * W;
  }
  const double theta = std::sqrt(theta_sq);
  const double coefficient =
      1.0 / theta_sq - (1.0 + std::cos(theta)) / (2.0 * theta * std::sin(theta));
  return Eigen::Matrix3d::Identity() + 0.5 * W + coefficient * W * W;
}

ImuPreintegration::ImuPreintegration(const ImuNoiseDensities& noise,
                                     const ImuBias& linearization_bias)
    : noise_(noise), linearization_bias_(linearization_bias) {
  CheckNoise(noise_);
  CheckBias(linearization_bias_);
}

void ImuPreintegration::Reset(const ImuBias& linearization_bias) {
  CheckBias(linearization_bias);
  *this = ImuPreintegration(noise_, linearization_bias);
}

void ImuPreintegration::Integrate(const Eigen::Vector3d& gyro_B, const Eigen::Vector3d& accel_B,
                                  double dt_s) {
  if (!std::isfinite(dt_s) || dt_s <= 0.0) {
    std::ostringstream message;
    message << "ImuPreintegration::Integrate: dt must be finite and > 0 s, got " << dt_s;
    throw std::invalid_argument(message.str());
  }
  CheckFiniteVector(gyro_B, "gyro sample");
  CheckFiniteVector(accel_B, "accel sample");

  const double dt = dt_s;
  const double dt2_half = 0.5 * dt * dt;
  const Eigen::Vector3d w = gyro_B - linearization_bias_.gyro;
  const Eigen::Vector3d a = accel_B - linearization_bias_.accel;
  const Eigen::Vector3d phi = w * dt;
  const Eigen::Matrix3d dR_inc = ExpSO3(phi);
  const Eigen::Matrix3d Jr = RightJacobianSO3(phi);
  // Everything below uses dR_k, the rotation before this sample (Forster eq. 24-26, 59-63).
  const Eigen::Matrix3d dR = delta_q_.toRotationMatrix();
  const Eigen::Matrix3d dR_a_hat = dR * Hat(a);

  // Covariance: x_{k+1} = A x_k + B_g eta_g + B_a eta_a, x = (dtheta, dv, dp) (eq. 62).
  Eigen::Matrix<double, 9, 9> A = Eigen::Matrix<double, 9, 9>::Identity();
  A.block<3, 3>(0, 0) = dR_inc.transpose();
  A.block<3, 3>(3, 0) = -dR_a_hat * dt;
  A.block<3, 3>(6, 0) = -dR_a_hat * dt2_half;
  A.block<3, 3>(6, 3) = Eigen::Matrix3d::Identity() * dt;
  // Discrete white noise of a held sample has variance sigma_c^2 / dt; its effect enters with
  // factor dt (rotation, velocity) or dt^2 / 2 (position).
  const double var_g = noise_.gyroscope_noise_density * noise_.gyroscope_noise_density / dt;
  const double var_a = noise_.accelerometer_noise_density * noise_.accelerometer_noise_density / dt;
  Eigen::Matrix<double, 9, 3> B_g = Eigen::Matrix<double, 9, 3>::Zero();
  B_g.block<3, 3>(0, 0) = Jr * dt;
  Eigen::Matrix<double, 9, 3> B_a = Eigen::Matrix<double, 9, 3>::Zero();
  B_a.block<3, 3>(3, 0) = dR * dt;
  B_a.block<3, 3>(6, 0) = dR * dt2_half;
  covariance_ = A * covariance_ * A.transpose() + var_g * B_g * B_g.transpose() +
                var_a * B_a * B_a.transpose();
  // The discrete model makes the piece's dv and dp noise one and the same (rank 3 of 6): a
  // single piece would give a singular covariance (a frame held past the IMU's last sample).
  // Continuous white noise over the piece gives Cov(dp) = sigma_c^2 dt^3 / 3, Cov(dv, dp) =
  // sigma_c^2 dt^2 / 2, Cov(dv) = sigma_c^2 dt: the discrete model has all but sigma_c^2 dt^3 / 12
  // of Cov(dp) (isotropic, whatever dR).
  covariance_.block<3, 3>(6, 6).diagonal().array() +=
      noise_.accelerometer_noise_density * noise_.accelerometer_noise_density * dt * dt * dt / 12.0;
  // Keep it exactly symmetric so the factor's LLT sees the same matrix on both triangles.
  covariance_ = 0.5 * (covariance_ + covariance_.transpose()).eval();

  // Bias Jacobians (appendix B), position and velocity first: they use the old J_theta_bg.
  J_p_ba_ += J_v_ba_ * dt - dR * dt2_half;
  J_p_bg_ += J_v_bg_ * dt - dR_a_hat * J_theta_bg_ * dt2_half;
  J_v_ba_ -= dR * dt;
  J_v_bg_ -= dR_a_hat * J_theta_bg_ * dt;
  J_theta_bg_ = dR_inc.transpose() * J_theta_bg_ - Jr * dt;

  // The deltas (eq. 24-26).
  delta_p_ += delta_v_ * dt + dR * a * dt2_half;
  delta_v_ += dR * a * dt;
  delta_q_ = (delta_q_ * ExpQuaternion(phi)).normalized();

  sum_dt_ += dt;
  ++num_samples_;
}

NavState ImuPreintegration::Predict(const NavState& state_i, const ImuBias& bias,
                                    const Eigen::Vector3d& gravity_D,
                                    const Eigen::Vector3d& earth_rate_D) const {
  const CorrectedImuDeltas<double> d = Correct<double>(bias.gyro, bias.accel);
  const Eigen::Quaterniond dq = delta_q_ * ExpQuaternion(d.rotation_correction);
  const double t = sum_dt_;
  const Eigen::Vector3d& w = earth_rate_D;
  const Eigen::Vector3d dv_D = state_i.q_D_B * d.delta_v;
  const Eigen::Vector3d dp_D = state_i.q_D_B * d.delta_p;
  NavState state_j;
  state_j.q_D_B = (ExpQuaternion(Eigen::Vector3d(-w * t)) * state_i.q_D_B * dq).normalized();
  state_j.p_D = state_i.p_D + state_i.v_D * t + 0.5 * gravity_D * t * t + dp_D -
                w.cross(dv_D) * (t * t / 6.0) - w.cross(state_i.v_D) * (t * t);
  state_j.v_D = state_i.v_D + gravity_D * t + dv_D - w.cross(Eigen::Vector3d(t * dv_D - dp_D)) -
                2.0 * w.cross(Eigen::Vector3d(state_j.p_D - state_i.p_D));
  return state_j;
}

}  // namespace auvdock
