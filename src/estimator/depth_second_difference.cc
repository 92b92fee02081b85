#include "auvdock/estimator/depth_second_difference.h"

#include <cmath>

namespace auvdock {

std::optional<double> DepthSecondDifference::Add(const DepthMeasurement& sample, double sigma_m,
                                                 double lambda) {
  if (!std::isfinite(sample.depth_m)) return std::nullopt;
  if (count_ > 0 && sample.t_ns <= t_[count_ - 1]) return std::nullopt;
  if (count_ > 0 &&
      1e-9 * static_cast<double>(sample.t_ns - t_[count_ - 1]) > options_.max_span_s) {
    count_ = 0;
  }
  std::optional<double> statistic;
  if (count_ == 2 && 1e-9 * static_cast<double>(sample.t_ns - t_[0]) <= options_.max_span_s) {
    const double h1 = 1e-9 * static_cast<double>(t_[1] - t_[0]);
    const double h2 = 1e-9 * static_cast<double>(sample.t_ns - t_[1]);
    const double c0 = 2.0 / (h1 * (h1 + h2));
    const double c2 = 2.0 / (h2 * (h1 + h2));
    const double c1 = -c0 - c2;
    const double d = c0 * z_[0] + c1 * z_[1] + c2 * sample.depth_m;
    const double variance = lambda * sigma_m * sigma_m * (c0 * c0 + c1 * c1 + c2 * c2) +
                            options_.accel_sigma_mps2 * options_.accel_sigma_mps2;
    if (variance > 0.0 && std::isfinite(d)) statistic = d * d / variance;
  }
  // Shift the triple.
  if (count_ == 2) {
    t_[0] = t_[1];
    z_[0] = z_[1];
    t_[1] = sample.t_ns;
    z_[1] = sample.depth_m;
  } else {
    t_[count_] = sample.t_ns;
    z_[count_] = sample.depth_m;
    ++count_;
  }
  return statistic;
}

}  // namespace auvdock
