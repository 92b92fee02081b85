// Candidate light positions: maxima of the scale-normalised Laplacian-of-Gaussian response of
// the luma over space and scale (Lindeberg 1998, "Feature detection with automatic scale
// selection", IJCV 30(2)).
//
// Math: for scales sigma_k (pixels, geometric from min_sigma_px to max_sigma_px),
//   R_k(x) = -sigma_k^2 (Laplacian of (G_sigma_k * I))(x),
// which for a Gaussian blob of amplitude A and size s peaks at sigma = s with R = A / 2, for
// any s: the response compares blobs of every size on one scale (gray levels). A candidate is a
// point where R_k is at least min_response and not below any of its 26 neighbours in (x, y, k)
// (at the largest scale, only with keep_largest_scale).
// Candidates closer than nms_radius_sigmas x the smaller of the two sigmas (at least
// nms_min_radius_px) to a stronger one are dropped (one candidate per light: a light's halo
// makes weaker maxima around it); the smaller sigma, so that a large bright structure (a white
// funnel at a coarse scale) does not hide the small lights around it.
//
// Large scales are computed on a Gaussian pyramid (cv::pyrDown: each level blurs by ~1.1 px of
// its own resolution): the residual blur sqrt(sigma^2 - sigma_pyr^2) is applied at the coarsest
// level that still leaves it at least 1 pixel of that level. Spatial maxima are found on each
// scale's own level (level pixel j is full-resolution pixel 2^level j: pyrDown's kernel is
// centred on the even pixels) and compared with the neighbouring scales sampled bilinearly at the
// same point; a coarse candidate's position is good to its level's pixel, and the core centroid
// (light_core_centroid.h) refines it.
//
// Units: pixels (0, 0 is the centre of the top-left pixel) and gray levels.
#pragma once

#include <vector>

#include <opencv2/core.hpp>

namespace auvdock {

struct BlobCandidateOptions {
  double min_sigma_px = 1.5;
  double max_sigma_px = 13.5;
  int num_scales = 7;
  double min_response = 8.0;         // gray levels (half a matched blob's peak contrast)
  double nms_radius_sigmas = 1.5;
  double nms_min_radius_px = 5.0;
  int max_candidates = 200;          // strongest first
  // A maximum at the largest scale is not an extremum over scale (the response may still grow
  // beyond it): a structure larger than any light the scales cover. Off: such maxima are dropped,
  // and max_sigma_px only bounds the scale of the second-largest.
  bool keep_largest_scale = false;
};

struct BlobCandidate {
  int x = 0, y = 0;        // pixel of the maximum
  double sigma_px = 0.0;   // scale of the maximum
  double response = 0.0;   // R at the maximum, gray levels
};

// Candidates in a CV_32FC1 or CV_8UC1 luma image, strongest first. Throws std::invalid_argument
// for another type, an empty image or options out of range.
std::vector<BlobCandidate> FindBlobCandidates(const cv::Mat& luma,
                                              const BlobCandidateOptions& options);

}  // namespace auvdock
