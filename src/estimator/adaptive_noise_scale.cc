#include "auvdock/estimator/adaptive_noise_scale.h"

#include <cmath>

namespace auvdock {

double ChiSquareCdf(int dof, double x) {
  if (!(x > 0.0) || dof < 1) return 0.0;
  const double half = 0.5 * x;
  int k = (dof % 2 == 1) ? 1 : 2;
  double p = (k == 1) ? std::erf(std::sqrt(half)) : 1.0 - std::exp(-half);
  for (; k + 2 <= dof; k += 2) {
    p -= std::exp(0.5 * k * std::log(half) - half - std::lgamma(0.5 * k + 1.0));
  }
  return std::clamp(p, 0.0, 1.0);
}

void AdaptiveNoiseScale::UpdateCensored(double statistic, int dof, double cutoff) {
  if (!options_.enabled || dof < 1 || !(statistic >= 0.0)) return;
  if (!(cutoff > 0.0)) {  // no cutoff (a sensor without a gate): every statistic counts
    Update(statistic, static_cast<double>(dof));
    return;
  }
  if (statistic > cutoff) {
    ++censored_;
    return;
  }
  const double kept = ChiSquareCdf(dof, cutoff);
  const double truncated_mean_ratio = kept > 0.0 ? ChiSquareCdf(dof + 2, cutoff) / kept : 1.0;
  Update(statistic / truncated_mean_ratio, static_cast<double>(dof));
}

}  // namespace auvdock
