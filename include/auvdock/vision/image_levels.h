// What an image's own pixels say about its levels, so that the detector needs no camera-specific
// constants: its noise, and where it clips.
//
// Pixel noise: the median absolute difference of horizontal neighbours on every 4th row,
//   sigma = MAD / (0.6745 sqrt(2))
// (two independent pixels' difference has sigma sqrt(2) sigma_n; the median of |N(0, s)| is
// 0.6745 s), at least 0.5 gray levels. Edges and lights are a small fraction of the pixels and
// do not move the median.
//
// Clip level: an overexposed image piles its brightest pixels up at one level, whatever that
// level is (255 for a full-range camera; 235 for limited-range video; lower after a gain or a
// tone curve applied past the clip). Its signature in the luma histogram h, with JPEG spreading a
// plateau over a few levels: a level L whose three levels T = h[L-1] + h[L] + h[L+1] hold
//   T >= min_pixels,
//   T >= spike_ratio * 3 * (mean of h[L-8 .. L-4])   (a pile-up, not a smooth top),
// with fewer than T / 4 pixels above L + 1 (JPEG's overshoot around a clipped plateau) and fewer
// than T / 100 above L + overshoot_levels (nothing is brighter than a clip, beyond JPEG's ringing:
// a uniform lit surface with a light brighter than it is no clip); the clip level is the fullest
// of the three, and the plateau must be white (the median max - min of the colour channels over
// the pixels at L at most max_channel_spread L: clipping flattens every channel; a flat coloured
// surface, as renderers draw them, piles up too but keeps its colour). L is searched from 254 down to min_level while fewer than 4 % of the pixels are
// brighter (a clip is the top of the image).
// A smooth unclipped maximum (a light's bell-shaped top, a lit surface) has fewer pixels at its
// top than a few levels below it, and gives no clip level.
// Units: gray levels.
#pragma once

#include <optional>

#include <opencv2/core.hpp>

namespace auvdock {

// luma: CV_32FC1.
double EstimatePixelNoise(const cv::Mat& luma);

struct ClipLevelOptions {
  int min_pixels = 32;
  double spike_ratio = 3.0;
  int min_level = 64;
  int overshoot_levels = 8;
  double max_channel_spread = 0.1;
};

// luma: CV_8UC1, or CV_32FC1 with values in [0, 255]; bgr: the CV_8UC3 image it comes from (empty or CV_8UC1:
// no colour test). nullopt when the image shows no clipping.
std::optional<double> EstimateClipLevel(const cv::Mat& luma, const cv::Mat& bgr = cv::Mat(),
                                        const ClipLevelOptions& options = {});

}  // namespace auvdock
