#include "auvdock/sim/imu_simulator.h"

#include <cmath>
#include <sstream>

#include "auvdock/geometry/so3.h"

#include "auvdock/sim/random_stream.h"

namespace auvdock {

ImuSimulator::ImuSimulator(const ImuCalibration& calibration, const Eigen::Vector3d& gravity_D,
                           const Eigen::Vector3d& initial_gyro_bias,
                           const Eigen::Vector3d& initial_accel_bias, bool noise_enabled,
                           std::mt19937_64 rng, const ImuErrorConfig& errors)
    : calibration_(calibration), errors_(errors), gravity_D_(gravity_D),
      gyro_bias_(initial_gyro_bias), accel_bias_(initial_accel_bias),
      noise_enabled_(noise_enabled), rng_(std::move(rng)) {
  const Eigen::Matrix3d R_m_T = ExpSO3(errors_.misalignment_rad).transpose();
  gyro_model_ = (Eigen::Matrix3d::Identity() + errors_.gyro_scale_factor.asDiagonal().toDenseMatrix()) * R_m_T;
  accel_model_ = (Eigen::Matrix3d::Identity() + errors_.accel_scale_factor.asDiagonal().toDenseMatrix()) * R_m_T;
}

ImuSample ImuSimulator::Ideal(int64_t t_ns, const KinematicState& s,
                              const Eigen::Vector3d& gravity_D) {
  ImuSample sample;
  sample.t_ns = t_ns;
  sample.gyro = s.omega_B;
  sample.accel = s.T_D_B.q.conjugate() * (s.a_D - gravity_D);
  return sample;
}

ImuSample ImuSimulator::Sample(int64_t t_ns, const KinematicState& s,
                               std::optional<FaultRecord>* fault) {
  ImuSample sample = Ideal(t_ns, s, gravity_D_);
  if (!noise_enabled_) return sample;
  if (first_ && fault != nullptr && errors_.any()) {
    std::ostringstream detail;
    const auto triple = [&](const Eigen::Vector3d& v) {
      detail << v.x() << ";" << v.y() << ";" << v.z();
    };
    detail << "noise_scale=" << errors_.noise_scale << ";gyro_scale=";
    triple(errors_.gyro_scale_factor);
    detail << ";accel_scale=";
    triple(errors_.accel_scale_factor);
    detail << ";misalignment_rad=";
    triple(errors_.misalignment_rad);
    *fault = FaultRecord{t_ns, calibration_.name, "model_error", detail.str()};
  }
  sample.gyro = gyro_model_ * sample.gyro;
  sample.accel = accel_model_ * sample.accel;
  const double dt = 1.0 / calibration_.rate_hz;
  const double k = errors_.noise_scale;
  if (!first_) {
    gyro_bias_ += k * calibration_.gyroscope_random_walk * std::sqrt(dt) * StandardNormal3(rng_);
    accel_bias_ +=
        k * calibration_.accelerometer_random_walk * std::sqrt(dt) * StandardNormal3(rng_);
  }
  first_ = false;
  sample.gyro += gyro_bias_ + k * calibration_.gyroscope_noise_density / std::sqrt(dt) *
                                  StandardNormal3(rng_);
  sample.accel += accel_bias_ + k * calibration_.accelerometer_noise_density / std::sqrt(dt) *
                                    StandardNormal3(rng_);
  return sample;
}

}  // namespace auvdock
