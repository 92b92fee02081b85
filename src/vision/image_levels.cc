#include "auvdock/vision/image_levels.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

namespace auvdock {

double EstimatePixelNoise(const cv::Mat& luma) {
  std::vector<float> diffs;
  diffs.reserve(static_cast<size_t>(luma.rows / 4 + 1) * luma.cols);
  for (int y = 0; y < luma.rows; y += 4) {
    const float* row = luma.ptr<float>(y);
    for (int x = 1; x < luma.cols; ++x) diffs.push_back(std::abs(row[x] - row[x - 1]));
  }
  if (diffs.empty()) return 1.0;
  std::nth_element(diffs.begin(), diffs.begin() + diffs.size() / 2, diffs.end());
  return std::max(0.5, diffs[diffs.size() / 2] / (0.6745 * std::sqrt(2.0)));
}

namespace {

// The median spread max - min of the colour channels over the pixels whose luma lies within one
// level of `level` (0 for a grey image).
double MedianChannelSpread(const cv::Mat& bgr, const cv::Mat& luma, int level) {
  if (bgr.empty() || bgr.type() != CV_8UC3) return 0.0;
  std::vector<int> spreads;
  for (int y = 0; y < luma.rows; ++y) {
    const cv::Vec3b* colour = bgr.ptr<cv::Vec3b>(y);
    for (int x = 0; x < luma.cols; ++x) {
      const float value =
          luma.type() == CV_8UC1 ? luma.ptr<uchar>(y)[x] : luma.ptr<float>(y)[x];
      if (std::abs(value - level) > 1.5f) continue;
      const cv::Vec3b& p = colour[x];
      spreads.push_back(std::max({p[0], p[1], p[2]}) - std::min({p[0], p[1], p[2]}));
    }
  }
  if (spreads.empty()) return 0.0;
  std::nth_element(spreads.begin(), spreads.begin() + spreads.size() / 2, spreads.end());
  return spreads[spreads.size() / 2];
}

}  // namespace

std::optional<double> EstimateClipLevel(const cv::Mat& luma, const cv::Mat& bgr,
                                        const ClipLevelOptions& options) {
  std::array<long, 256> h{};
  if (luma.type() == CV_8UC1) {
    for (int y = 0; y < luma.rows; ++y) {
      const uchar* row = luma.ptr<uchar>(y);
      for (int x = 0; x < luma.cols; ++x) ++h[row[x]];
    }
  } else {
    for (int y = 0; y < luma.rows; ++y) {
      const float* row = luma.ptr<float>(y);
      for (int x = 0; x < luma.cols; ++x) {
        ++h[static_cast<size_t>(std::clamp(static_cast<int>(row[x] + 0.5f), 0, 255))];
      }
    }
  }
  std::array<long, 257> at_or_above{};  // at_or_above[k]: pixels at level k or brighter
  for (int k = 255; k >= 0; --k) at_or_above[k] = at_or_above[k + 1] + h[k];
  auto brighter_than = [&](int level) { return level >= 255 ? 0L : at_or_above[level + 1]; };
  const int low = std::max(options.min_level, 9);
  for (int level = 254; level >= low; --level) {
    if (brighter_than(level + 1) >= 4 * static_cast<long>(luma.total()) / 100) break;
    const long top = h[level - 1] + h[level] + h[level + 1];
    double below = 0.0;
    for (int k = level - 8; k <= level - 4; ++k) below += h[k];
    below /= 5.0;
    if (top >= options.min_pixels && top >= options.spike_ratio * 3.0 * below &&
        4 * brighter_than(level + 1) < top &&
        100 * brighter_than(level + options.overshoot_levels) < top) {
      // The plateau's own level: the fullest of the three (a plateau at 255 has nothing above).
      if (level == 254 && h[255] >= h[254] && h[255] >= h[253]) return 255.0;  // full range
      const int peak = h[level + 1] > h[level] && h[level + 1] >= h[level - 1]
                           ? level + 1
                           : (h[level - 1] > h[level] ? level - 1 : level);
      // Clipped pixels are white: every channel reached the clip. A flat coloured surface piles
      // its pixels up too, but is no clip (and nothing below the image's top is).
      if (MedianChannelSpread(bgr, luma, peak) > options.max_channel_spread * peak) {
        return std::nullopt;
      }
      return static_cast<double>(peak);
    }
  }
  return std::nullopt;
}

}  // namespace auvdock
