// A state-free innovation of the pressure depth, for estimating its effective noise online
// (adaptive_noise_scale.h), as the DVL's rate-of-change test is for the DVL.
//
// Three consecutive samples z0, z1, z2 at t0 < t1 < t2 give the second divided difference
//   d = c0 z0 + c1 z1 + c2 z2,   c0 = 2 / (h1 (h1 + h2)),  c2 = 2 / (h2 (h1 + h2)),  c1 = -c0 - c2
// (h1 = t1 - t0, h2 = t2 - t1): the sensor's vertical acceleration at about t1 plus the noise.
// With white noise of sigma lambda^(1/2) sigma_m per sample,
//   Var d = lambda sigma_m^2 (c0^2 + c1^2 + c2^2) + accel_sigma^2,
// where accel_sigma covers the vehicle's own vertical acceleration (a docking AUV: a few
// cm/s^2; against sigma_m = 2 cm at 10 Hz, sqrt(sum c^2) sigma_m ~ 5 m/s^2, so it hardly counts).
// The statistic d^2 / Var d is chi-square with 1 dof when lambda is right, whatever the state's
// estimate. Samples more than max_span_s apart (a gap) restart the triple; a sample not later
// than the previous one is ignored. Units: m, s.
#pragma once

#include <cstdint>
#include <optional>

#include "auvdock/io/measurements.h"

namespace auvdock {

struct DepthSecondDifferenceOptions {
  double accel_sigma_mps2 = 0.1;
  double max_span_s = 1.0;
};

class DepthSecondDifference {
 public:
  explicit DepthSecondDifference(const DepthSecondDifferenceOptions& options = {})
      : options_(options) {}

  // The statistic of the triple ending with `sample` (nullopt until there are three samples
  // within max_span_s), for the configured sigma_m and the variance factor lambda in use; the
  // sample then becomes the newest of the triple.
  std::optional<double> Add(const DepthMeasurement& sample, double sigma_m, double lambda);

  void Reset() { count_ = 0; }

 private:
  DepthSecondDifferenceOptions options_;
  int64_t t_[2] = {0, 0};  // the two previous samples, older first
  double z_[2] = {0.0, 0.0};
  int count_ = 0;          // how many of them are held (0-2)
};

}  // namespace auvdock
