#include "auvdock/vision/saturated_disc.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

#include <Eigen/Dense>
#include <opencv2/imgproc.hpp>

namespace auvdock {
namespace {

constexpr double kPi = 3.14159265358979323846;

// 255 where every channel is at or above level.
cv::Mat SaturatedMask(const cv::Mat& image, int level) {
  cv::Mat mask;
  if (image.channels() == 1) {
    cv::compare(image, level, mask, cv::CMP_GE);
  } else {
    cv::inRange(image, cv::Scalar(level, level, level), cv::Scalar(255, 255, 255), mask);
  }
  return mask;
}

struct Circle {
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  double radius = 0.0;
};

// The circle through three points; nothing when they are (nearly) collinear.
std::optional<Circle> CircleThrough(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                                    const Eigen::Vector2d& c) {
  const Eigen::Vector2d ab = b - a, ac = c - a;
  const double d = 2.0 * (ab.x() * ac.y() - ab.y() * ac.x());
  if (std::fabs(d) < 1e-9 * ab.squaredNorm() * ac.squaredNorm() || std::fabs(d) < 1e-12) {
    return std::nullopt;
  }
  const Eigen::Vector2d o((ac.y() * ab.squaredNorm() - ab.y() * ac.squaredNorm()) / d,
                          (ab.x() * ac.squaredNorm() - ac.x() * ab.squaredNorm()) / d);
  return Circle{a + o, o.norm()};
}

// How far from the circle an outline pixel may lie and still support it (the acceptance).
double Tolerance(const Circle& circle, const SaturatedDiscOptions& options) {
  return std::max(1.0, options.arc_tolerance_fraction * circle.radius);
}

bool OnCircle(const Eigen::Vector2d& p, const Circle& circle, double tolerance) {
  return std::fabs((p - circle.centre).norm() - circle.radius) <= tolerance;
}

size_t CountInliers(const std::vector<Eigen::Vector2d>& outline, const Circle& circle,
                    double tolerance) {
  return static_cast<size_t>(std::count_if(outline.begin(), outline.end(), [&](const auto& p) {
    return OnCircle(p, circle, tolerance);
  }));
}

std::vector<Eigen::Vector2d> Inliers(const std::vector<Eigen::Vector2d>& outline,
                                     const Circle& circle, double tolerance) {
  std::vector<Eigen::Vector2d> inliers;
  for (const Eigen::Vector2d& p : outline) {
    if (OnCircle(p, circle, tolerance)) inliers.push_back(p);
  }
  return inliers;
}

// Gauss-Newton on r_i = |p_i - c| - R over (c, R).
Circle RefineCircle(const std::vector<Eigen::Vector2d>& points, Circle circle) {
  for (int iteration = 0; iteration < 10; ++iteration) {
    Eigen::Matrix3d JtJ = Eigen::Matrix3d::Zero();
    Eigen::Vector3d Jtr = Eigen::Vector3d::Zero();
    for (const Eigen::Vector2d& p : points) {
      const Eigen::Vector2d d = p - circle.centre;
      const double n = d.norm();
      if (n < 1e-9) continue;
      const Eigen::Vector3d J(-d.x() / n, -d.y() / n, -1.0);
      JtJ += J * J.transpose();
      Jtr += J * (n - circle.radius);
    }
    const Eigen::Vector3d step = JtJ.ldlt().solve(-Jtr);
    if (!step.allFinite()) break;
    circle.centre += step.head<2>();
    circle.radius += step.z();
    if (step.norm() < 1e-6) break;
  }
  return circle;
}

// The circle that the most outline pixels lie on (see the header), of radius at most
// max_radius.
std::optional<Circle> ConsensusCircle(const std::vector<Eigen::Vector2d>& outline,
                                      const SaturatedDiscOptions& options, double max_radius) {
  const size_t n = outline.size();
  if (n < 12) return std::nullopt;
  std::optional<Circle> best;
  size_t best_support = 0;
  const size_t stride = std::max<size_t>(1, n / 48);
  for (size_t i = 0; i < n; i += stride) {
    for (const size_t gap : {n / 3, n / 4, n / 6}) {
      const auto circle =
          CircleThrough(outline[i], outline[(i + gap) % n], outline[(i + 2 * gap) % n]);
      if (!circle || circle->radius > max_radius) continue;
      const size_t support = CountInliers(outline, *circle, options.fit_tolerance_px);
      if (support > best_support) {
        best_support = support;
        best = circle;
      }
    }
  }
  if (!best) return std::nullopt;
  Circle circle = *best;
  for (int pass = 0; pass < 2; ++pass) {
    const std::vector<Eigen::Vector2d> inliers =
        Inliers(outline, circle, options.fit_tolerance_px);
    if (inliers.size() < 3) return std::nullopt;
    circle = RefineCircle(inliers, circle);
  }
  if (!(circle.radius > 0.0) || !circle.centre.allFinite()) return std::nullopt;
  return circle;
}

// The region `label` of labels (its bounding box `box`) measured as a disc; offset maps the
// labels' pixels to the image's.
std::optional<LightDetection> MeasureDisc(const cv::Mat& labels, int label, const cv::Rect& box,
                                          const Eigen::Vector2d& offset,
                                          const SaturatedDiscOptions& options) {
  // Cut by the labelled window (the image border or the search limit): not a whole disc.
  if (box.x == 0 || box.y == 0 || box.x + box.width == labels.cols ||
      box.y + box.height == labels.rows) {
    return std::nullopt;
  }
  cv::Mat mask;
  cv::compare(labels(box), label, mask, cv::CMP_EQ);
  const double area = cv::countNonZero(mask);
  if (std::sqrt(area / kPi) < options.min_radius_px) return std::nullopt;
  // A zero frame so that the region's pixels on the box's edge are outline too.
  cv::Mat framed;
  cv::copyMakeBorder(mask, framed, 1, 1, 1, 1, cv::BORDER_CONSTANT, cv::Scalar(0));
  std::vector<std::vector<cv::Point>> contours;
  cv::findContours(framed, contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE);
  if (contours.empty()) return std::nullopt;
  const auto longest =
      std::max_element(contours.begin(), contours.end(),
                       [](const auto& a, const auto& b) { return a.size() < b.size(); });
  std::vector<Eigen::Vector2d> outline;
  outline.reserve(longest->size());
  for (const cv::Point& p : *longest) outline.emplace_back(p.x - 1, p.y - 1);
  const auto circle = ConsensusCircle(outline, options, std::max(box.width, box.height));
  if (!circle) return std::nullopt;
  const double support =
      static_cast<double>(CountInliers(outline, *circle, Tolerance(*circle, options)));
  if (support < options.min_arc_fraction * 2.0 * kPi * circle->radius) return std::nullopt;
  // Fill and overreach: the region's pixels within and beyond the disc of radius R + 1/2.
  const double radius = circle->radius + 0.5;
  double inside = 0.0, outside = 0.0;
  for (int y = 0; y < mask.rows; ++y) {
    const unsigned char* row = mask.ptr<unsigned char>(y);
    for (int x = 0; x < mask.cols; ++x) {
      if (!row[x]) continue;
      ((Eigen::Vector2d(x, y) - circle->centre).norm() <= radius ? inside : outside) += 1.0;
    }
  }
  const double disc_area = kPi * radius * radius;
  if (inside < options.min_fill * disc_area || outside > options.max_outside_fraction * disc_area) {
    return std::nullopt;
  }
  LightDetection d;
  d.uv = circle->centre + Eigen::Vector2d(box.x, box.y) + offset;
  d.radius_px = radius;
  d.peak = 255.0;
  d.score = 1.0;
  const double s = options.centroid_sigma_fraction * radius + options.centroid_sigma_floor_px;
  d.covariance = s * s * Eigen::Matrix2d::Identity();
  return d;
}

bool UsableImage(const cv::Mat& image) {
  return !image.empty() && (image.type() == CV_8UC3 || image.type() == CV_8UC1);
}

}  // namespace

std::optional<LightDetection> FindSaturatedDisc(const cv::Mat& image,
                                                const Eigen::Vector2d& seed_uv,
                                                const SaturatedDiscOptions& options) {
  if (!UsableImage(image)) return std::nullopt;
  const int half = static_cast<int>(std::ceil(options.window_radius_px));
  const int cu = static_cast<int>(std::lround(seed_uv.x()));
  const int cv_ = static_cast<int>(std::lround(seed_uv.y()));
  const cv::Rect window = cv::Rect(cu - half, cv_ - half, 2 * half + 1, 2 * half + 1) &
                          cv::Rect(0, 0, image.cols, image.rows);
  if (window.area() == 0) return std::nullopt;
  const cv::Mat mask = SaturatedMask(image(window), options.saturation_level);
  cv::Mat labels;
  if (cv::connectedComponents(mask, labels, 8, CV_32S) < 2) return std::nullopt;
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
  cv::Mat region;
  cv::compare(labels, label, region, cv::CMP_EQ);
  const cv::Rect box = cv::boundingRect(region);
  return MeasureDisc(labels, label, box, Eigen::Vector2d(window.x, window.y), options);
}

std::vector<LightDetection> FindSaturatedDiscs(const cv::Mat& image,
                                               const SaturatedDiscOptions& options) {
  std::vector<LightDetection> discs;
  if (!UsableImage(image)) return discs;
  // Most frames have no saturated region of a disc's size: the mask's count and its regions'
  // outlines (one external contour per 8-connected region) say so before any labelling.
  const cv::Mat mask = SaturatedMask(image, options.saturation_level);
  const double min_area = kPi * options.min_radius_px * options.min_radius_px;
  if (cv::countNonZero(mask) < min_area) return discs;
  std::vector<std::vector<cv::Point>> outlines;
  cv::findContours(mask.clone(), outlines, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_SIMPLE);
  std::vector<std::pair<cv::Point, cv::Rect>> regions;  // a pixel of each large region, its box
  for (const std::vector<cv::Point>& outline : outlines) {
    if (cv::contourArea(outline) < 0.5 * min_area) continue;
    regions.emplace_back(outline.front(), cv::boundingRect(outline));
  }
  if (regions.empty()) return discs;
  cv::Mat labels;
  cv::connectedComponents(mask, labels, 8, CV_32S);
  for (const auto& [pixel, box] : regions) {
    const auto disc =
        MeasureDisc(labels, labels.at<int>(pixel), box, Eigen::Vector2d::Zero(), options);
    if (disc) discs.push_back(*disc);
  }
  return discs;
}

}  // namespace auvdock
