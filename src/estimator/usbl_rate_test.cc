#include "auvdock/estimator/usbl_rate_test.h"

#include <cmath>
#include <cstdio>
#include <limits>

namespace auvdock {

UsblRateVerdict UsblRateTest::Check(const AcousticFix& fix) {
  return CheckValue(fix.t_ns, fix.p_D, fix.sigma_m, "fix");
}

UsblRateVerdict UsblRateTest::Check(const SblRange& range) {
  return CheckValue(range.t_ns, Eigen::Vector3d(range.range_m, 0.0, 0.0), range.sigma_m, "range");
}

UsblRateVerdict UsblRateTest::CheckValue(int64_t t_ns, const Eigen::Vector3d& value,
                                         double sigma, const char* what) {
  UsblRateVerdict verdict;
  verdict.excess = std::numeric_limits<double>::quiet_NaN();
  if (!options_.enabled) return verdict;
  candidate_.reset();
  if (reference_ && (t_ns <= reference_->t_ns ||
                     1e-9 * static_cast<double>(t_ns - reference_->t_ns) >
                         options_.max_reference_age_s)) {
    reference_.reset();
  }
  if (!reference_) {
    candidate_ = Reference{t_ns, value, sigma, false};
    return verdict;  // no opinion
  }
  const double dt = 1e-9 * static_cast<double>(t_ns - reference_->t_ns);
  const double change = (value - reference_->value).norm();
  const double speed_bound = speed_bound_mps();
  verdict.excess = (change - speed_bound * dt) / std::hypot(sigma, reference_->sigma);
  if (verdict.excess <= options_.gate_sigmas) {
    candidate_ = Reference{t_ns, value, sigma, true};
    return verdict;
  }
  if (!reference_->confirmed) {
    candidate_ = Reference{t_ns, value, sigma, false};  // the reference may have been the outlier
    return verdict;
  }
  char reason[160];
  std::snprintf(reason, sizeof(reason),
                "rate test: %.2f m from the last good %s %.2f s before (at most %.2f m/s)", change,
                what, dt, speed_bound);
  verdict.pass = false;
  verdict.reason = reason;
  return verdict;
}

void UsblRateTest::Confirm(int64_t t_ns) {
  if (candidate_ && candidate_->t_ns == t_ns) {
    reference_ = candidate_;
    candidate_.reset();
  }
}

}  // namespace auvdock
