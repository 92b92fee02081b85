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
// Used for each camera system's centroid noise (post-solve residuals) and for the depth, DVL
// and SBL noise (state-free innovations: second_difference.h, dvl_rate_test.h): one mechanism.
//
// A state-free innovation test sees the sensor's outliers too (a pressure spike, a DVL lock on
// a fish, an SBL multipath reply): UpdateCensored leaves out a statistic above the test's cutoff
// c instead of clipping it to c (clipped, 2 % SBL multipath gave a factor of 1.3-2.5 on ranges
// exactly as configured), and divides each kept statistic by the mean of the truncated
// distribution, E[chi2_m | chi2_m < c] / m = P_{m+2}(c) / P_m(c) (P_k: the chi-square CDF with
// k dof), so that the true factor stays the fixed point. From a factor far too small most
// statistics are above c and the factor climbs a few time constants, not one.
//
// Units: none (a ratio of variances). Not thread-safe; one per sensor.
#pragma once

#include <algorithm>
#include <cstdint>

namespace auvdock {

struct AdaptiveNoiseOptions {
  bool enabled = true;
  double time_constant = 200.0;  // measurements (degrees of freedom, weighted)
  double min_factor = 0.25;      // sigma at least half the configured one
  double max_factor = 25.0;      // ... and at most five times
  double min_redundancy = 20.0;  // degrees of freedom seen before the factor moves from 1
};

// For a factor estimated from state-free innovations (differences of consecutive samples):
// never below the configured noise, since such a difference is blind to an error that is
// correlated between the samples; it can only show a sensor noisier than configured.
inline constexpr AdaptiveNoiseOptions kStateFreeNoiseOptions{true, 200.0, 1.0};

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

  // One statistic that is chi-square with `dof` degrees of freedom when the factor in use is
  // right (whitened by it), left out when above `cutoff`, see above; cutoff <= 0: none, every
  // statistic counts as it is.
  void UpdateCensored(double statistic, int dof, double cutoff);

  double factor() const { return factor_; }
  int64_t censored() const { return censored_; }
  double redundancy_seen() const { return seen_; }

 private:
  AdaptiveNoiseOptions options_;
  double factor_ = 1.0;
  double sum_q_ = 1.0;  // EMA of q / redundancy, started at the configured noise
  double seen_ = 0.0;
  int64_t censored_ = 0;
};

// P(chi2_dof < x), for dof >= 1: the recurrence
//   P_{k+2}(x) = P_k(x) - (x/2)^(k/2) e^(-x/2) / Gamma(k/2 + 1)
// from P_1(x) = erf(sqrt(x/2)) and P_2(x) = 1 - e^(-x/2).
double ChiSquareCdf(int dof, double x);

}  // namespace auvdock
