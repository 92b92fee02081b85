// Identification of a few lights by a precise prediction alone: what identifies the one or two
// lights a camera sees at the end of a landing, where no per-frame pose is possible (fewer than
// the 3-4 lights a pose needs) but the estimator knows the pose to millimetres from the frames
// before and the IMU.
//
// Each detection j is compared with the lights L the prediction puts in the image (PredictLights:
// projection p_L, expected radius), at distance d_jL = |u_j - p_L| (pixels, raw image). Its gate
//   g_j = gate_px + radius_fraction * r_j        (r_j: the detection's own radius, px)
// grows with the blob's size: a large glow's centroid is less certain, and at the range where
// a light fills a large part of the image the other lights are far away. Detection j is
// labelled L when
//   d_jL <= g_j,                                  (the prediction explains it)
//   d_jM > d_jL + g_j for every other light M,    (no other light could be it)
//   d_kL > d_jL + g_j for every other detection k (no other detection could be L),
//   d_jM >= isolation_radii * r_j for every other light M (no other light inside or at the rim
//                                  of the blob: a glow that merges with a neighbour's has its
//                                  centroid pulled towards it).
// Otherwise it stays unlabelled: the rule never guesses between two candidates. Wrong labels
// that slip through meet the estimator's chi-square gate on the residual.
//
// Units: pixels; the prediction's frame conventions are PredictLights' (guided_light_search.h).
#pragma once

#include <vector>

#include "auvdock/vision/guided_light_search.h"
#include "auvdock/vision/light_detection.h"

namespace auvdock {

struct PredictionAssociationOptions {
  double gate_px = 4.0;
  double radius_fraction = 0.5;
  double isolation_radii = 2.0;
};

// Per detection: the light id it is labelled with, or -1.
std::vector<int> AssociateByPrediction(const std::vector<LightDetection>& detections,
                                       const std::vector<PredictedLight>& predicted,
                                       const PredictionAssociationOptions& options = {});

}  // namespace auvdock
