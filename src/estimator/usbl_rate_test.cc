#include "auvdock/estimator/usbl_rate_test.h"

#include <cmath>
#include <cstdio>
#include <limits>

namespace auvdock {

UsblRateVerdict UsblRateTest::Check(const AcousticFix& fix) {
  UsblRateVerdict verdict;
  verdict.excess = std::numeric_limits<double>::quiet_NaN();
  if (!options_.enabled) return verdict;
  candidate_.reset();
  if (reference_ && (fix.t_ns <= reference_->fix.t_ns ||
                     1e-9 * static_cast<double>(fix.t_ns - reference_->fix.t_ns) >
                         options_.max_reference_age_s)) {
    reference_.reset();
  }
  if (!reference_) {
    candidate_ = Reference{fix, false};
    return verdict;  // no opinion
  }
  const double dt = 1e-9 * static_cast<double>(fix.t_ns - reference_->fix.t_ns);
  const double sigma = std::hypot(fix.sigma_m, reference_->fix.sigma_m);
  verdict.excess = ((fix.p_D - reference_->fix.p_D).norm() - options_.max_speed_mps * dt) / sigma;
  if (verdict.excess <= options_.gate_sigmas) {
    candidate_ = Reference{fix, true};
    return verdict;
  }
  if (!reference_->confirmed) {
    candidate_ = Reference{fix, false};  // the reference may have been the outlier
    return verdict;
  }
  char reason[160];
  std::snprintf(reason, sizeof(reason),
                "rate test: %.2f m from the last good fix %.2f s before (at most %.2f m/s)",
                (fix.p_D - reference_->fix.p_D).norm(), dt, options_.max_speed_mps);
  verdict.pass = false;
  verdict.reason = reason;
  return verdict;
}

void UsblRateTest::Confirm(int64_t t_ns) {
  if (candidate_ && candidate_->fix.t_ns == t_ns) {
    reference_ = candidate_;
    candidate_.reset();
  }
}

}  // namespace auvdock
