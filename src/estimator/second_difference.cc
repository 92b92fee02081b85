#include "auvdock/estimator/second_difference.h"

#include <cmath>

namespace auvdock {

std::optional<double> SecondDifference::Add(int64_t t_ns, double value, double sigma,
                                            double lambda) {
  if (!std::isfinite(value) || !std::isfinite(sigma) || !(sigma > 0.0)) return std::nullopt;
  if (count_ > 0 && t_ns <= t_[count_ - 1]) return std::nullopt;
  if (count_ > 0 && 1e-9 * static_cast<double>(t_ns - t_[count_ - 1]) > options_.max_span_s) {
    Reset();
  }
  std::optional<double> statistic;
  if (count_ == 2 && 1e-9 * static_cast<double>(t_ns - t_[0]) <= options_.max_span_s) {
    const double h1 = 1e-9 * static_cast<double>(t_[1] - t_[0]);
    const double h2 = 1e-9 * static_cast<double>(t_ns - t_[1]);
    const double c0 = 2.0 / (h1 * (h1 + h2));
    const double c2 = 2.0 / (h2 * (h1 + h2));
    const double c1 = -c0 - c2;
    const double d = c0 * z_[0] + c1 * z_[1] + c2 * value;
    const double variance =
        lambda * (c0 * c0 * s_[0] * s_[0] + c1 * c1 * s_[1] * s_[1] + c2 * c2 * sigma * sigma) +
        options_.accel_sigma * options_.accel_sigma;
    if (variance > 0.0 && std::isfinite(d)) statistic = d * d / variance;
  }
  // Shift the triple.
  if (count_ == 2) {
    t_[0] = t_[1];
    z_[0] = z_[1];
    s_[0] = s_[1];
    --count_;
  }
  t_[count_] = t_ns;
  z_[count_] = value;
  s_[count_] = sigma;
  ++count_;
  return options_.outlier_cutoff > 0.0 ? Screen(statistic) : statistic;
}

std::optional<double> SecondDifference::Screen(std::optional<double> statistic) {
  if (!statistic) return std::nullopt;
  if (*statistic > options_.outlier_cutoff) {
    held_.reset();
    drop_next_ = true;
    return std::nullopt;
  }
  if (drop_next_) {
    drop_next_ = false;
    return std::nullopt;
  }
  const std::optional<double> released = held_;
  held_ = statistic;
  return released;
}

}  // namespace auvdock
