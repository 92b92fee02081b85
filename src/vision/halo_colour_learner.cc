#include "auvdock/vision/halo_colour_learner.h"

#include <algorithm>

namespace auvdock {

HaloColourLearner::HaloColourLearner(double initial_threshold,
                                     const HaloColourLearnerOptions& options)
    : initial_(initial_threshold), options_(options), threshold_(initial_threshold) {}

void HaloColourLearner::Observe(const std::vector<LightDetection>& detections,
                                const std::vector<int>& light_ids) {
  for (size_t i = 0; i < detections.size() && i < light_ids.size(); ++i) {
    if (light_ids[i] < 0) continue;
    samples_.push_back(detections[i].colour_excess);
    if (static_cast<int>(samples_.size()) > options_.window) samples_.pop_front();
  }
  if (static_cast<int>(samples_.size()) < options_.min_samples) return;
  learned_ = true;
  threshold_ = std::max(initial_, options_.fraction * Quantile(options_.quantile));
}

double HaloColourLearner::Quantile(double q) const {
  std::vector<double> sorted(samples_.begin(), samples_.end());
  const size_t k = std::min(sorted.size() - 1, static_cast<size_t>(q * sorted.size()));
  std::nth_element(sorted.begin(), sorted.begin() + k, sorted.end());
  return sorted[k];
}

std::optional<double> HaloColourLearner::median_excess() const {
  if (samples_.empty()) return std::nullopt;
  std::vector<double> sorted(samples_.begin(), samples_.end());
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  return sorted[sorted.size() / 2];
}

}  // namespace auvdock
