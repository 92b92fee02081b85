// Simulated IMU (B is the IMU frame): exact body rate and specific force from the trajectory,
// plus white noise and bias random walk.
//
// Continuous-time model (Kalibr / EuRoC conventions, Forster et al. 2017 eq. 28):
//   w_m = w_B + b_g + n_g,            n_g ~ N(0, sigma_g^2 / dt)
//   a_m = R_B_D (a_D - g_D) + b_a + n_a,  n_a ~ N(0, sigma_a^2 / dt)
//   b_g(k+1) = b_g(k) + sigma_bg sqrt(dt) N(0, I),  likewise b_a.
// sigma_* are the densities of ImuCalibration (rad/s/sqrt(Hz), m/s^2/sqrt(Hz), ...). With
// noise disabled the samples are exact derivatives of the trajectory.
//
// Errors the estimator does not model (ImuErrorConfig, scenario key imu.errors; none by default):
// a real IMU's noise above its datasheet (the calibration keeps the datasheet's densities, the
// samples get noise_scale times them, and the random walks too), per-axis scale factors and a
// misalignment of the sensor's axes from B (a small rotation R_m = Exp(misalignment_rad)):
//   w_m = (I + diag(s_g)) R_m^T w_B + b_g + noise_scale n_g
//   a_m = (I + diag(s_a)) R_m^T f_B + b_a + noise_scale n_a
// They go to groundtruth/faults.csv once, at the first sample ("model_error").
#pragma once

#include <optional>
#include <random>

#include "auvdock/io/calibration.h"
#include "auvdock/io/measurements.h"
#include "auvdock/sim/docking_trajectory.h"

namespace auvdock {

struct ImuErrorConfig {
  double noise_scale = 1.0;  // true noise densities and random walks / the calibration's
  Eigen::Vector3d gyro_scale_factor = Eigen::Vector3d::Zero();   // per axis, fraction
  Eigen::Vector3d accel_scale_factor = Eigen::Vector3d::Zero();  // per axis, fraction
  Eigen::Vector3d misalignment_rad = Eigen::Vector3d::Zero();    // rotation vector of R_m
  bool any() const {
    return noise_scale != 1.0 || !gyro_scale_factor.isZero() || !accel_scale_factor.isZero() ||
           !misalignment_rad.isZero();
  }
};

class ImuSimulator {
 public:
  ImuSimulator(const ImuCalibration& calibration, const Eigen::Vector3d& gravity_D,
               const Eigen::Vector3d& initial_gyro_bias, const Eigen::Vector3d& initial_accel_bias,
               bool noise_enabled, std::mt19937_64 rng, const ImuErrorConfig& errors = {});

  // The sample at time t (s) of the state s; advances the bias random walk by one period
  // first (except for the very first sample). *fault: the errors' record at the first sample
  // when there are any (else untouched).
  ImuSample Sample(int64_t t_ns, const KinematicState& s,
                   std::optional<FaultRecord>* fault = nullptr);

  const Eigen::Vector3d& gyro_bias() const { return gyro_bias_; }
  const Eigen::Vector3d& accel_bias() const { return accel_bias_; }

  // Noise-free measurement model (also used by tests).
  static ImuSample Ideal(int64_t t_ns, const KinematicState& s, const Eigen::Vector3d& gravity_D);

 private:
  ImuCalibration calibration_;
  ImuErrorConfig errors_;
  Eigen::Matrix3d gyro_model_, accel_model_;  // (I + diag(s)) R_m^T
  Eigen::Vector3d gravity_D_;
  Eigen::Vector3d gyro_bias_, accel_bias_;
  bool noise_enabled_;
  bool first_ = true;
  std::mt19937_64 rng_;
};

}  // namespace auvdock
