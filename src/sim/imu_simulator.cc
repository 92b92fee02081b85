#include "auvdock/sim/imu_simulator.h"

#include <cmath>

#include "auvdock/sim/random_stream.h"

namespace auvdock {

ImuSimulator::ImuSimulator(const ImuCalibration& calibration, const Eigen::Vector3d& gravity_D,
                           const Eigen::Vector3d& initial_gyro_bias,
                           const Eigen::Vector3d& initial_accel_bias, bool noise_enabled,
                           std::mt19937_64 rng)
    : calibration_(calibration), gravity_D_(gravity_D), gyro_bias_(initial_gyro_bias),
      accel_bias_(initial_accel_bias), noise_enabled_(noise_enabled), rng_(std::move(rng)) {}

ImuSample ImuSimulator::Ideal(int64_t t_ns, const KinematicState& s,
                              const Eigen::Vector3d& gravity_D) {
  ImuSample sample;
  sample.t_ns = t_ns;
  sample.gyro = s.omega_B;
  sample.accel = s.T_D_B.q.conjugate() * (s.a_D - gravity_D);
  return sample;
}

ImuSample ImuSimulator::Sample(int64_t t_ns, const KinematicState& s) {
  ImuSample sample = Ideal(t_ns, s, gravity_D_);
  if (!noise_enabled_) return sample;
  const double dt = 1.0 / calibration_.rate_hz;
  if (!first_) {
    gyro_bias_ += calibration_.gyroscope_random_walk * std::sqrt(dt) * StandardNormal3(rng_);
    accel_bias_ += calibration_.accelerometer_random_walk * std::sqrt(dt) * StandardNormal3(rng_);
  }
  first_ = false;
  sample.gyro += gyro_bias_ + calibration_.gyroscope_noise_density / std::sqrt(dt) *
                                  StandardNormal3(rng_);
  sample.accel += accel_bias_ + calibration_.accelerometer_noise_density / std::sqrt(dt) *
                                    StandardNormal3(rng_);
  return sample;
}

}  // namespace auvdock
