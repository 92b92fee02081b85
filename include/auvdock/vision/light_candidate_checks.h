// Evidence that a blob candidate is one of the dock's lights, and the checks on it. What makes a
// light, whatever renders or films it: a compact peak that falls off in every direction (not an
// edge, a ridge or a corner of a large bright structure such as a white funnel, a lit deck or a
// wall), surrounded by a halo of the light's own colour (a white surface, a yellow-green wall or
// white marine snow are not blue), and bright enough to matter.
//
// Measured on rings around the core centre c at radius rho = max(halo_radius_sigmas sigma,
// min_halo_radius_px), sampled at 24 angles and grouped into 8 sectors of 45 degrees:
//   halo_excess  = mean colour excess (light_colour.h) on the ring, gray levels;
//   peak_drop    = core peak - the brightest sector's mean luma on the ring, gray levels (a light
//                  is brighter than its halo in every direction; an edge of a bright structure
//                  is not: one sector is as bright as the centre);
//   at_border    = the ring leaves the image (the halo, and the centroid with it, is cut).
// Units: pixels and gray levels.
#pragma once

#include <string>

#include <opencv2/core.hpp>

#include "auvdock/vision/blob_candidates.h"
#include "auvdock/vision/light_colour.h"
#include "auvdock/vision/light_core_centroid.h"

namespace auvdock {

struct LightCandidateCheckOptions {
  LightColour colour = LightColour::kBlue;
  double halo_radius_sigmas = 2.0;
  double min_halo_radius_px = 3.0;
  // Colour excess of the halo (the most coloured of rings from just outside the core to
  // halo_radius_sigmas sigma) against the image's median, gray levels; not applied for white
  // lights. Permissive: lights in our renders reach ~50-95, blue LEDs blooming in a pool
  // ~120-190, white and grey clutter stays below ~35; a footage's own value is learned from its
  // identified lights (halo_colour_learner.h).
  double min_halo_excess = 40.0;
  double min_peak_drop = 1.0;       // gray levels
  double max_core_radius_sigmas = 2.0;  // a core wider than this is a bright surface
};

struct LightCandidateEvidence {
  double halo_excess = 0.0;
  double peak_drop = 0.0;
  bool at_border = false;
};

// bgr: CV_8UC3 (or CV_8UC1: no colour, halo_excess = 0); luma: CV_32FC1 of the same size.
LightCandidateEvidence MeasureCandidateEvidence(const cv::Mat& bgr, const cv::Mat& luma,
                                                const LightCore& core, double sigma_px,
                                                double background_excess,
                                                const LightCandidateCheckOptions& options);

// The median colour excess of an image (every 4th pixel of every 4th row): the water's and the
// scene's cast, against which a halo's colour is measured. 0 for white or a grey image.
double MedianColourExcess(const cv::Mat& bgr, LightColour colour);

// Empty when the candidate passes; otherwise a short reason ("extended", "cut by the
// border" (the core itself reaches the image's edge: its centre is biased by an unknown amount
// and the light may be mostly outside), "not a peak", "wrong colour").
std::string CheckLightCandidate(const BlobCandidate& candidate, const LightCore& core,
                                const LightCandidateEvidence& evidence, bool has_colour,
                                const LightCandidateCheckOptions& options);

}  // namespace auvdock
