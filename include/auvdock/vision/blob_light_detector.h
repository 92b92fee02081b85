// Guide-light detector for real water: scale-space blob candidates (blob_candidates.h), the
// sub-pixel centre of each candidate's core with its own covariance (light_core_centroid.h), and
// checks on what makes a light, whoever drew the image (light_candidate_checks.h): a compact peak
// brighter than its halo in every direction, a halo of the dock's light colour, enough contrast.
//
// Unlike LightDetector (light_detector.h, tuned to our renderer's look: it rejects the reflection
// the renderer draws below every light, the renderer's particle colour and dark housings), this
// detector knows nothing of how a particular renderer draws a scene: extended bright structures
// (a white funnel, a lit deck, walls) fail the peak and extent checks, differently coloured
// clutter the colour check. It was developed on real pool footage (a white funnel ringed by blue
// LEDs) and randomised renders.
//
// Pipeline per image: optional field deinterlacing (field_deinterlace.h) -> luma (BT.601) -> its
// noise and clip level (image_levels.h: an image clipping at L < 255 saturates at L - (255 -
// checks.saturation_level), and its contrasts are scaled by L / 255, the response thresholds
// min_response and score_response with them) -> candidates -> per candidate: core, evidence, checks -> detections
// closer than the larger core radius (at least min_separation_px) to a stronger one are the same
// light, and much weaker ones in a stronger light's halo are its glow (halo_extent_sigmas,
// max_response_in_halo) -> at most max_detections by score. Candidates at scales above
// close_light_min_sigma_px (a light within decimetres of the lens, or a large bright structure) are
// judged after all others and suppress none of them: one is kept only if no kept light lies within
// halo_extent_sigmas of its sigma (a light that close outshines the others and is far from them in
// the image; a white funnel's plateau has the dock's lights round it). Their halo colour is held to
// checks.min_halo_excess, never to a higher threshold learned from the footage's farther lights:
// a light that close whitens its own halo (on the randomised renders: 19 more lights closer than
// 1 m found, of 660 then missed). A detection whose halo ring
// leaves the image is flagged at_border and its covariance widened by (border_sigma_fraction
// sigma)^2 per axis: the cut biases the centroid by a fraction of the light's size.
//
// Score in [0, 1]: the geometric mean of response / score_response and halo_excess /
// (2 min_halo_excess) (1 for white lights), each clamped to [0, 1].
//
// Units: pixels (0, 0 is the centre of the top-left pixel), gray levels. Detect() is const and
// thread-safe.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "auvdock/vision/blob_candidates.h"
#include "auvdock/vision/light_candidate_checks.h"
#include "auvdock/vision/light_core_centroid.h"
#include "auvdock/vision/light_detection.h"

namespace auvdock {

struct BlobLightDetectorOptions {
  bool deinterlace = false;  // keep the even field, rebuild odd rows (combing)
  // Read the image's clip level (image_levels.h) and judge saturation and contrast by it; off: a
  // full-range camera is assumed (saturation at checks.saturation_level, contrasts as they are).
  bool adapt_to_clip_level = true;
  // Scale-normalised LoG response of at least 30 gray levels: a light of ~60 levels of contrast
  // at its own scale (lower thresholds let the pool footage's clutter through: at 10, precision
  // 0.12 on the pool clip). Scales 1.44 apart from 1.5 px (the optics' blur) to 248 px; maxima
  // at the largest are dropped (blob_candidates.h), so lights up to sigma ~170 px are found: a
  // light 0.4 m from the lens, its glow filling the image, peaks at ~120 px (at 120 px, the
  // largest scale until 2026-12, it was dropped as a structure larger than any light). Large bright
  // structures at those scales are told from lights by their shape (light_candidate_checks.h:
  // a large core must be round).
  BlobCandidateOptions candidates{/*min_sigma_px=*/1.5, /*max_sigma_px=*/248.0, /*num_scales=*/15,
                                  /*min_response=*/30.0};
  double score_response = 60.0;  // a response that scores full strength
  LightCoreOptions core;
  LightCandidateCheckOptions checks;
  double min_separation_px = 3.0;
  // A candidate within halo_extent_sigmas sigma of a kept light whose response is less than
  // max_response_in_halo of that light's lies in its glow: bloom, a fitting or rim the light
  // illuminates, a reflection. Two real lights that close in the image are about equally bright.
  double halo_extent_sigmas = 3.5;
  double max_response_in_halo = 0.5;
  double close_light_min_sigma_px = 30.0;
  double border_sigma_fraction = 0.5;
  int max_detections = 64;
};

// A candidate that was not kept, and why (for overlays and "why no light" reports).
struct RejectedLightCandidate {
  Eigen::Vector2d uv = Eigen::Vector2d::Zero();
  double sigma_px = 0.0;
  std::string reason;
  // At a close light's scale (above close_light_min_sigma_px), with a light's shape, and
  // rejected for its colour alone: a light within decimetres of the lens whitens its own glow,
  // and the prediction of a light tracked to there may overrule the colour (few_light_tracker.h).
  // Its core's centroid covariance then (zero otherwise).
  bool overrulable = false;
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Zero();
};

class BlobLightDetector {
 public:
  // Throws std::invalid_argument for options out of range.
  explicit BlobLightDetector(const BlobLightDetectorOptions& options = {});

  // Lights in an 8-bit BGR (CV_8UC3) or gray (CV_8UC1) image, by descending score; a gray image
  // has no colour and skips the colour check. rejected (optional) receives every candidate not
  // kept. Throws std::invalid_argument for an empty image or another type.
  // min_halo_excess, when given, replaces checks.min_halo_excess for this image (a threshold
  // learned from the footage: halo_colour_learner.h).
  std::vector<LightDetection> Detect(const cv::Mat& image,
                                     std::vector<RejectedLightCandidate>* rejected = nullptr,
                                     std::optional<double> min_halo_excess = std::nullopt) const;

  const BlobLightDetectorOptions& options() const { return options_; }

 private:
  BlobLightDetectorOptions options_;
};

}  // namespace auvdock
