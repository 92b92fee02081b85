// A time-ordered buffer of IMU samples that preintegrates any interval [t0, t1] between states.
//
// Each sample is held (zero-order hold) from its own time to the next sample's, as the
// simulator and most IMU drivers define a sample; the interval's first piece uses the last
// sample at or before t0, the last piece the last sample at or before t1 (nothing after t1 is
// used, which keeps the estimator causal). A hole longer than max_gap_s anywhere in [t0, t1]
// (including before the first or after the last sample) means the interval is not covered.
#pragma once

#include <cstdint>
#include <deque>
#include <optional>
#include <string>

#include "auvdock/imu/imu_preintegration.h"
#include "auvdock/io/calibration.h"
#include "auvdock/io/measurements.h"

namespace auvdock {

class ImuBuffer {
 public:
  // noise_scale multiplies every noise density and random walk of the calibration (so the
  // covariances by its square): real IMUs are noisier than their datasheets (EstimatorOptions::
  // imu_noise_scale).
  ImuBuffer(const ImuCalibration& calibration, double max_gap_s, double noise_scale = 1.0);

  // Appends a sample; returns an empty string, or why it was skipped (not finite, beyond the
  // calibration's gyroscope or accelerometer range on an axis, not after the previous sample).
  std::string Add(const ImuSample& sample);

  // Preintegration over [t0_ns, t1_ns] at the linearisation bias; nothing when the interval is
  // empty or not covered.
  std::optional<ImuPreintegration> Preintegrate(int64_t t0_ns, int64_t t1_ns,
                                                const ImuBias& bias) const;

  // The gyro sample held at t_ns (the last one at or before it; rad/s, in B, bias not removed):
  // the body rate a factor at t_ns needs (factors/dvl_factor.h). Nothing when no sample lies
  // within max_gap_s before t_ns.
  std::optional<Eigen::Vector3d> GyroAt(int64_t t_ns) const;

  // The mean accelerometer sample (specific force, m/s^2, in B, bias not removed) over the
  // samples with t0_ns <= t <= t1_ns; nothing when fewer than min_samples lie there.
  std::optional<Eigen::Vector3d> MeanAccel(int64_t t0_ns, int64_t t1_ns, int min_samples) const;
  // Forgets samples no longer needed for intervals starting at or after t_ns.
  void DropBefore(int64_t t_ns);

  bool empty() const { return samples_.empty(); }
  int64_t newest_t_ns() const { return samples_.empty() ? INT64_MIN : samples_.back().t_ns; }

 private:
  ImuNoiseDensities noise_;
  int64_t max_gap_ns_;
  double gyroscope_range_;      // rad/s, per axis
  double accelerometer_range_;  // m/s^2, per axis
  std::deque<ImuSample> samples_;
};

}  // namespace auvdock
