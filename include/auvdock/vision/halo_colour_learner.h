// The colour a dock's lights show in *this* footage, learned from the lights that were
// identified: how strongly coloured a light's halo is depends on the LEDs, their range, the water
// and the camera's white balance (close blue LEDs blooming in a pool: halo excess ~120-190 gray
// levels; blue-green lights at 3-8 m in our renders: ~50-95), so no single threshold serves every
// scene. The detector starts from a permissive threshold (BlobLightDetectorOptions::checks
// .min_halo_excess) that keeps every light and lets clutter through; identification against the
// dock model (hypothesise-and-verify) still finds the lights among it. From then on the
// threshold is
//   max(initial, fraction x the `quantile` quantile of the halo excess of the last `window`
//   identified lights),
// once at least min_samples lights have been identified: just below the least coloured of the
// lights seen (the quantile follows the lights' own spread, which is wide at long range), well
// above the clutter's (in both footages below ~35 % of the lights' median).
// It only ever tightens relative to the initial value and follows slow changes (range, water).
//
// Units: gray levels (colour excess relative to the image's median, light_candidate_checks.h).
#pragma once

#include <deque>
#include <optional>
#include <vector>

#include "auvdock/vision/light_detection.h"

namespace auvdock {

struct HaloColourLearnerOptions {
  double quantile = 0.1;
  double fraction = 0.8;
  int min_samples = 8;
  int window = 64;
};

class HaloColourLearner {
 public:
  explicit HaloColourLearner(double initial_threshold, const HaloColourLearnerOptions& options = {});

  // Adds the identified detections (light_ids[i] >= 0) of one frame.
  void Observe(const std::vector<LightDetection>& detections, const std::vector<int>& light_ids);

  double threshold() const { return threshold_; }
  bool learned() const { return learned_; }
  // Median halo excess of the identified lights, once learned.
  std::optional<double> median_excess() const;

 private:
  double initial_;
  HaloColourLearnerOptions options_;
  double Quantile(double q) const;

  std::deque<double> samples_;
  double threshold_;
  bool learned_ = false;
};

}  // namespace auvdock
