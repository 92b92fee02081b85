#include "auvdock/vision/saturated_disc.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>
#include <opencv2/imgproc.hpp>

namespace auvdock {
namespace {

// 255 where every channel is at or above level.
cv::Mat SaturatedMask(const cv::Mat& image, int level) {
  cv::Mat mask;
  if (image.channels() == 1) {
    cv::compare(image, level, mask, cv::CMP_GE);
    return mask;
  }
  cv::Mat least;
  cv::Mat channels[3];
  cv::split(image, channels);
  cv::min(channels[0], channels[1], least);
  cv::min(least, channels[2], least);
  cv::compare(least, level, mask, cv::CMP_GE);
  return mask;
}

}  // namespace

std::optional<LightDetection> FindSaturatedDisc(const cv::Mat& image,
                                                const Eigen::Vector2d& seed_uv,
                                                const SaturatedDiscOptions& options) {
  if (image.empty() || (image.type() != CV_8UC3 && image.type() != CV_8UC1)) return std::nullopt;
  const int half = static_cast<int>(std::ceil(options.window_radius_px));
  const int cu = static_cast<int>(std::lround(seed_uv.x()));
  const int cv_ = static_cast<int>(std::lround(seed_uv.y()));
  const cv::Rect window = cv::Rect(cu - half, cv_ - half, 2 * half + 1, 2 * half + 1) &
                          cv::Rect(0, 0, image.cols, image.rows);
  if (window.area() == 0) return std::nullopt;
  const cv::Mat mask = SaturatedMask(image(window), options.saturation_level);
  cv::Mat labels;
  const int n = cv::connectedComponents(mask, labels, 8, CV_32S);
  if (n < 2) return std::nullopt;
  // The region at or nearest the seed, within the search radius.
  const Eigen::Vector2d seed = seed_uv - Eigen::Vector2d(window.x, window.y);
  const int r = static_cast<int>(std::ceil(options.search_radius_px));
  int label = 0;
  double nearest = options.search_radius_px;
  for (int y = std::max(0, static_cast<int>(seed.y()) - r);
       y <= std::min(labels.rows - 1, static_cast<int>(seed.y()) + r); ++y) {
    for (int x = std::max(0, static_cast<int>(seed.x()) - r);
         x <= std::min(labels.cols - 1, static_cast<int>(seed.x()) + r); ++x) {
      const int l = labels.at<int>(y, x);
      const double d = (Eigen::Vector2d(x, y) - seed).norm();
      if (l > 0 && d <= nearest) {
        nearest = d;
        label = l;
      }
    }
  }
  if (label == 0) return std::nullopt;
  double m0 = 0.0;
  Eigen::Vector2d m1 = Eigen::Vector2d::Zero();
  Eigen::Matrix2d m2 = Eigen::Matrix2d::Zero();
  for (int y = 0; y < labels.rows; ++y) {
    const int* row = labels.ptr<int>(y);
    for (int x = 0; x < labels.cols; ++x) {
      if (row[x] != label) continue;
      // Cut by the window (the image border or the search limit): the centroid is not the centre.
      if (x == 0 || y == 0 || x == labels.cols - 1 || y == labels.rows - 1) return std::nullopt;
      const Eigen::Vector2d p(x, y);
      m0 += 1.0;
      m1 += p;
      m2 += p * p.transpose();
    }
  }
  const Eigen::Vector2d centroid = m1 / m0;
  const Eigen::Matrix2d sigma = m2 / m0 - centroid * centroid.transpose();
  const Eigen::Vector2d axes = Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(sigma).eigenvalues();
  if (!(axes.minCoeff() > 0.0)) return std::nullopt;
  const double ellipse_area = 4.0 * M_PI * std::sqrt(axes.prod());
  const double radius = std::sqrt(m0 / M_PI);
  if (m0 < options.min_fill * ellipse_area || radius < options.min_radius_px ||
      std::sqrt(axes.maxCoeff() / axes.minCoeff()) > options.max_axis_ratio) {
    return std::nullopt;
  }
  LightDetection d;
  d.uv = centroid + Eigen::Vector2d(window.x, window.y);
  d.radius_px = radius;
  d.peak = 255.0;
  d.score = 1.0;
  const double s = options.centroid_sigma_fraction * radius + options.centroid_sigma_floor_px;
  d.covariance = s * s * Eigen::Matrix2d::Identity();
  return d;
}

}  // namespace auvdock
