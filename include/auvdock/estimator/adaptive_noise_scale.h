// One sensor's effective noise, estimated online from its own residuals: a variance factor
// lambda (true variance / configured variance) that multiplies the configured covariance of
// that sensor's next measurements. Covariance matching (Mehra 1972; seed 001's adaptive Kalman
// filter as a bounded, slow adaptation): for a measurement of dimension m whitened by the
// covariance actually used, lambda_used R, its residual after the solve has
//   E[r^T (lambda_used R)^-1 r] = m - leverage,   leverage = tr(J P J^T)
// (J: the whitened residual's Jacobian on the state, P: the state's covariance after the solve,
// i.e. the share of the measurement the state itself absorbed). So
//   q = lambda_used r^T (lambda_used R)^-1 r       (the residual in configured units)
// has expectation lambda (m - leverage), and lambda is estimated as the ratio of exponential
// moving averages of q and of (m - leverage), with time constant `time_constant` measurements:
// slow, so that one bad frame does not move it, and never outside [min_factor, max_factor].
// Used for each camera system's centroid noise now, meant for every sensor (depth, DVL,
// acoustic): one mechanism.
//
// Units: none (a ratio of variances). Not thread-safe; one per sensor.
#pragma once

#include <algorithm>

namespace auvdock {

struct AdaptiveNoiseOptions {
  bool enabled = true;
  double time_constant = 200.0;  // measurements (degrees of freedom, weighted)
  double min_factor = 0.25;      // sigma at least half the configured one
  double max_factor = 25.0;      // ... and at most five times
  double min_redundancy = 20.0;  // degrees of freedom seen before the factor moves from 1
};

class AdaptiveNoiseScale {
 public:
  explicit AdaptiveNoiseScale(const AdaptiveNoiseOptions& options = {}) : options_(options) {}

  // One measurement (or several summed): whitened squared residual with the factor in use, and
  // its redundancy m - leverage (> 0).
  void Update(double whitened_squared_residual, double redundancy) {
    if (!options_.enabled || !(redundancy > 0.0) || !(whitened_squared_residual >= 0.0)) return;
    const double q = factor_ * whitened_squared_residual;
    const double alpha = std::min(1.0, redundancy / options_.time_constant);
    sum_q_ = (1.0 - alpha) * sum_q_ + alpha * q / redundancy;
    seen_ += redundancy;
    if (seen_ >= options_.min_redundancy) {
      factor_ = std::clamp(sum_q_, options_.min_factor, options_.max_factor);
    }
  }

  double factor() const { return factor_; }
  double redundancy_seen() const { return seen_; }

 private:
  AdaptiveNoiseOptions options_;
  double factor_ = 1.0;
  double sum_q_ = 1.0;  // EMA of q / redundancy, started at the configured noise
  double seen_ = 0.0;
};

}  // namespace auvdock
