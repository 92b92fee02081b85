#include "auvdock/estimator/imu_buffer.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <stdexcept>

namespace auvdock {

ImuBuffer::ImuBuffer(const ImuCalibration& calibration, double max_gap_s, double noise_scale)
    : noise_(ImuNoiseDensities::FromCalibration(calibration)),
      max_gap_ns_(static_cast<int64_t>(max_gap_s * 1e9)),
      gyroscope_range_(calibration.gyroscope_range),
      accelerometer_range_(calibration.accelerometer_range) {
  if (!(max_gap_s > 0.0)) throw std::invalid_argument("ImuBuffer: max_gap_s must be positive");
  if (!(noise_scale > 0.0) || !std::isfinite(noise_scale)) {
    throw std::invalid_argument("ImuBuffer: noise_scale must be positive");
  }
  noise_.gyroscope_noise_density *= noise_scale;
  noise_.gyroscope_random_walk *= noise_scale;
  noise_.accelerometer_noise_density *= noise_scale;
  noise_.accelerometer_random_walk *= noise_scale;
}

std::string ImuBuffer::Add(const ImuSample& sample) {
  if (!sample.gyro.allFinite() || !sample.accel.allFinite()) return "not finite";
  if (sample.gyro.cwiseAbs().maxCoeff() > gyroscope_range_) {
    return "beyond the gyroscope's range (" + std::to_string(gyroscope_range_) + " rad/s)";
  }
  if (sample.accel.cwiseAbs().maxCoeff() > accelerometer_range_) {
    return "beyond the accelerometer's range (" + std::to_string(accelerometer_range_) + " m/s^2)";
  }
  if (!samples_.empty() && sample.t_ns <= samples_.back().t_ns) return "out of order or repeated";
  samples_.push_back(sample);
  return "";
}

void ImuBuffer::DropBefore(int64_t t_ns) {
  // Keep the last sample at or before t_ns: it is held over the start of the next interval.
  while (samples_.size() >= 2 && samples_[1].t_ns <= t_ns) samples_.pop_front();
}

std::optional<Eigen::Vector3d> ImuBuffer::GyroAt(int64_t t_ns) const {
  auto it = std::upper_bound(samples_.begin(), samples_.end(), t_ns,
                             [](int64_t t, const ImuSample& s) { return t < s.t_ns; });
  if (it == samples_.begin()) return std::nullopt;
  const ImuSample& held = *std::prev(it);
  if (t_ns - held.t_ns > max_gap_ns_) return std::nullopt;
  return held.gyro;
}

std::optional<Eigen::Vector3d> ImuBuffer::MeanAccel(int64_t t0_ns, int64_t t1_ns,
                                                    int min_samples) const {
  auto it = std::lower_bound(samples_.begin(), samples_.end(), t0_ns,
                             [](const ImuSample& s, int64_t t) { return s.t_ns < t; });
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int n = 0;
  for (; it != samples_.end() && it->t_ns <= t1_ns; ++it, ++n) sum += it->accel;
  if (n < std::max(1, min_samples)) return std::nullopt;
  return sum / static_cast<double>(n);
}

std::optional<ImuPreintegration> ImuBuffer::Preintegrate(int64_t t0_ns, int64_t t1_ns,
                                                         const ImuBias& bias) const {
  if (samples_.empty() || t1_ns <= t0_ns) return std::nullopt;
  auto it = std::upper_bound(samples_.begin(), samples_.end(), t0_ns,
                             [](int64_t t, const ImuSample& s) { return t < s.t_ns; });
  const ImuSample* held;
  if (it == samples_.begin()) {
    if (it->t_ns - t0_ns > max_gap_ns_) return std::nullopt;
    held = &*it;  // the first sample stands in for the short piece before it
  } else {
    held = &*std::prev(it);
    if (t0_ns - held->t_ns > max_gap_ns_) return std::nullopt;
  }
  ImuPreintegration pim(noise_, bias);
  int64_t t = t0_ns;
  for (; it != samples_.end() && it->t_ns <= t1_ns; ++it) {
    if (it->t_ns > t) {
      if (it->t_ns - t > max_gap_ns_) return std::nullopt;
      pim.Integrate(held->gyro, held->accel, 1e-9 * static_cast<double>(it->t_ns - t));
      t = it->t_ns;
    }
    held = &*it;
  }
  if (t1_ns - held->t_ns > max_gap_ns_) return std::nullopt;  // the IMU stopped before t1
  if (t1_ns > t) pim.Integrate(held->gyro, held->accel, 1e-9 * static_cast<double>(t1_ns - t));
  return pim;
}

}  // namespace auvdock
