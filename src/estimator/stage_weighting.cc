#include "auvdock/estimator/stage_weighting.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace auvdock {

const char* StageWeightingModeName(StageWeightingMode mode) {
  switch (mode) {
    case StageWeightingMode::kInformation:
      return "information";
    case StageWeightingMode::kPaperLightCount:
      return "paper_light_count";
  }
  return "unknown";
}

bool ParseStageWeightingMode(const std::string& text, StageWeightingMode* mode) {
  for (const StageWeightingMode m :
       {StageWeightingMode::kInformation, StageWeightingMode::kPaperLightCount}) {
    if (text == StageWeightingModeName(m)) {
      *mode = m;
      return true;
    }
  }
  return false;
}

StageWeighting::StageWeighting(const StageWeightingOptions& options) : options_(options) {
  if (options_.mode != StageWeightingMode::kInformation &&
      options_.mode != StageWeightingMode::kPaperLightCount) {
    throw std::invalid_argument("StageWeighting: unknown mode");
  }
  if (!(options_.min_share >= 0.0 && options_.min_share <= 0.5)) {
    throw std::invalid_argument("StageWeighting: min_share must be in [0, 0.5]");
  }
}

StageWeights StageWeighting::Compute(int n_stereo, int n_mono) const {
  if (n_stereo < 0 || n_mono < 0) {
    throw std::invalid_argument("StageWeighting: negative light count");
  }
  StageWeights weights;  // 1 and 1
  // Only the both-visible stage has a split to make; a lone system (or none) keeps weight 1.
  if (options_.mode == StageWeightingMode::kInformation || n_stereo == 0 || n_mono == 0) {
    return weights;
  }
  const double n_s = n_stereo;
  const double n_m = n_mono;
  const double n = n_s + n_m;
  const double share_s = std::clamp(n_s / n, options_.min_share, 1.0 - options_.min_share);
  const double share_m = 1.0 - share_s;
  // Keep the per-light mean weight at 1: n_s w_s + n_m w_m = n_s + n_m.
  const double c = n / (n_s * share_s + n_m * share_m);
  weights.stereo = c * share_s;
  weights.mono = c * share_m;
  return weights;
}

}  // namespace auvdock
