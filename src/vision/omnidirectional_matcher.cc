#include "auvdock/vision/omnidirectional_matcher.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include <Eigen/Geometry>
#include <opencv2/imgproc.hpp>

#include "auvdock/vision/hungarian.h"

namespace auvdock {

namespace {

using Points = std::vector<Eigen::Vector2d>;

constexpr double kPi = 3.14159265358979323846;

// Centroid-relative vectors (eqs. 5-6) scaled to unit RMS length. False if all points coincide.
bool CentreAndScale(const Points& points, Points* out) {
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
  for (const auto& p : points) centroid += p;
  centroid /= static_cast<double>(points.size());
  double sum2 = 0.0;
  for (const auto& p : points) sum2 += (p - centroid).squaredNorm();
  const double rms = std::sqrt(sum2 / static_cast<double>(points.size()));
  if (!(rms > 1e-12)) return false;
  out->clear();
  for (const auto& p : points) out->push_back((p - centroid) / rms);
  return true;
}

// Angles (rad, in [0, 90 deg)) of the sides of the minimum-area enclosing rectangle and of every
// other rectangle flush with a hull edge whose area is within (1 + tolerance) of the minimum.
// The minimum-area rectangle has a side on a hull edge (Freeman & Shapira 1975), so the hull
// edges are the candidates (the rotating-calipers set). The near-minimal ones are kept because
// the minimum is often not unique: for the default T the hull is a triangle and the rectangles
// on its three edges have the same area (twice the triangle's), so cv::minAreaRect's single
// answer would be decided by rounding and perspective.
std::vector<double> RectangleAngles(const Points& points, double tolerance) {
  std::vector<cv::Point2f> cv_points;
  for (const auto& p : points) {
    cv_points.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()));
  }
  std::vector<cv::Point2f> hull;
  cv::convexHull(cv_points, hull);
  struct Candidate {
    double angle;
    double area;
  };
  std::vector<Candidate> candidates;
  double min_area = std::numeric_limits<double>::infinity();
  for (size_t e = 0; e < hull.size(); ++e) {
    const cv::Point2f edge = hull[(e + 1) % hull.size()] - hull[e];
    if (edge.dot(edge) <= 0.0f) continue;
    const double angle = std::atan2(static_cast<double>(edge.y), static_cast<double>(edge.x));
    const Eigen::Rotation2Dd to_edge(-angle);
    Eigen::Vector2d low = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
    Eigen::Vector2d high = -low;
    for (const auto& p : points) {
      const Eigen::Vector2d q = to_edge * p;
      low = low.cwiseMin(q);
      high = high.cwiseMax(q);
    }
    const double area = (high - low).prod();
    candidates.push_back({angle, area});
    min_area = std::min(min_area, area);
  }
  std::vector<double> angles;
  for (const Candidate& c : candidates) {
    if (c.area > (1.0 + tolerance) * min_area + 1e-12) continue;
    double angle = std::fmod(c.angle, 0.5 * kPi);
    if (angle < 0.0) angle += 0.5 * kPi;
    bool duplicate = false;
    for (double kept : angles) {
      const double difference = std::abs(kept - angle);
      duplicate = duplicate || std::min(difference, 0.5 * kPi - difference) < 0.5 * kPi / 180.0;
    }
    if (!duplicate) angles.push_back(angle);
  }
  return angles;
}

Points Rotate(const Points& points, double angle) {
  const Eigen::Rotation2Dd rotation(angle);
  Points out;
  out.reserve(points.size());
  for (const auto& p : points) out.push_back(rotation * p);
  return out;
}

struct Hypothesis {
  double rotation = 0.0;  // rotation (rad) applied to the centred image set
  std::vector<int> detection_of_light;
  double mean_cost = 0.0;
};

// Eqs. 8-9: Euclidean cost matrix (rows: design, columns: image) and Hungarian assignment.
Hypothesis Match(const Points& design, const Points& image, double rotation) {
  const Points rotated = Rotate(image, rotation);
  Eigen::MatrixXd cost(design.size(), rotated.size());
  for (size_t i = 0; i < design.size(); ++i) {
    for (size_t j = 0; j < rotated.size(); ++j) cost(i, j) = (design[i] - rotated[j]).norm();
  }
  Hypothesis h;
  h.rotation = rotation;
  h.detection_of_light = SolveAssignment(cost);
  double total = 0.0;
  for (size_t i = 0; i < design.size(); ++i) total += cost(i, h.detection_of_light[i]);
  h.mean_cost = total / static_cast<double>(design.size());
  return h;
}

// Every pairing of a design rectangle with an image rectangle, at the four quarter turns: the
// design in its rectangle frame matched to the image rotated into its own and turned by k 90 deg.
// Only the relative rotation matters (the costs are invariant to a common rotation), so pairings
// giving the same relative rotation (within 0.5 deg) are matched once. Sorted by mean cost.
std::vector<Hypothesis> MatchAll(const Points& design, const std::vector<double>& design_angles,
                                 const Points& image, const std::vector<double>& image_angles) {
  std::vector<Hypothesis> hypotheses;
  std::vector<double> done;
  for (double design_angle : design_angles) {
    for (double image_angle : image_angles) {
      for (int k = 0; k < 4; ++k) {
        // Image -> design rotation, in [0, 2 pi).
        double rotation = std::fmod(k * 0.5 * kPi + design_angle - image_angle, 2.0 * kPi);
        if (rotation < 0.0) rotation += 2.0 * kPi;
        bool duplicate = false;
        for (double other : done) {
          const double difference = std::abs(other - rotation);
          duplicate = duplicate || std::min(difference, 2.0 * kPi - difference) < kPi / 360.0;
        }
        if (duplicate) continue;
        done.push_back(rotation);
        hypotheses.push_back(Match(design, image, rotation));
      }
    }
  }
  std::sort(hypotheses.begin(), hypotheses.end(),
            [](const Hypothesis& a, const Hypothesis& b) { return a.mean_cost < b.mean_cost; });
  return hypotheses;
}

}  // namespace

MatchResult MatchOmnidirectional(const std::vector<LightDetection>& detections,
                                 const DockModel& dock,
                                 const OmnidirectionalMatcherOptions& options) {
  MatchResult result;
  result.status = MatchStatus::kFailed;
  const size_t n = dock.lights.size();
  if (n < 3) {
    result.reason = "the dock has fewer than 3 lights";
    return result;
  }
  if (detections.size() != n) {
    result.reason = std::to_string(detections.size()) + " detections for " + std::to_string(n) +
                    " lights: the omnidirectional matcher needs every light and nothing else";
    return result;
  }

  Points design_raw, image_raw, design, image;
  for (const DockLight& light : dock.lights) design_raw.push_back(light.p_D.head<2>());
  for (const LightDetection& detection : detections) image_raw.push_back(detection.uv);
  if (!CentreAndScale(design_raw, &design)) {
    result.reason = "the dock's lights coincide in (x, y)";
    return result;
  }
  if (!CentreAndScale(image_raw, &image)) {
    result.reason = "all detections coincide";
    return result;
  }
  const std::vector<double> design_angles =
      RectangleAngles(design, options.rectangle_area_tolerance);
  const std::vector<double> image_angles = RectangleAngles(image, options.rectangle_area_tolerance);
  if (design_angles.empty() || image_angles.empty()) {
    result.reason = "no enclosing rectangle (degenerate point set)";
    return result;
  }

  // A design that maps onto itself (other than by the identity) cannot be labelled by shape.
  for (const Hypothesis& self : MatchAll(design, design_angles, design, design_angles)) {
    if (self.mean_cost >= options.symmetry_tolerance) break;
    bool identity = true;
    for (size_t i = 0; i < n; ++i) {
      identity = identity && self.detection_of_light[i] == static_cast<int>(i);
    }
    if (!identity) {
      int degrees = static_cast<int>(std::lround(self.rotation * 180.0 / kPi)) % 360;
      if (degrees < 0) degrees += 360;
      std::ostringstream reason;
      reason << "the dock's layout maps onto itself under a " << degrees
             << " deg rotation: its lights cannot be told apart by shape";
      result.status = MatchStatus::kAmbiguous;
      result.reason = reason.str();
      return result;
    }
  }

  const std::vector<Hypothesis> hypotheses = MatchAll(design, design_angles, image, image_angles);
  const Hypothesis& best = hypotheses.front();
  result.cost = best.mean_cost;
  if (best.mean_cost > options.max_mean_cost) {
    std::ostringstream reason;
    reason.precision(3);
    reason << "best mean cost " << best.mean_cost << " exceeds " << options.max_mean_cost
           << ": the image does not look like the design";
    result.reason = reason.str();
    return result;
  }
  for (const Hypothesis& other : hypotheses) {
    if (other.mean_cost - best.mean_cost >= options.ambiguity_margin) break;
    if (other.detection_of_light != best.detection_of_light) {
      std::ostringstream reason;
      reason.precision(3);
      reason << "two rotations match about equally well (mean costs " << best.mean_cost << " and "
             << other.mean_cost << ") with different labels";
      result.status = MatchStatus::kAmbiguous;
      result.reason = reason.str();
      return result;
    }
  }

  for (size_t i = 0; i < n; ++i) {
    result.matches.push_back({best.detection_of_light[i], dock.lights[i].id});
  }
  std::sort(result.matches.begin(), result.matches.end(),
            [](const LightMatch& a, const LightMatch& b) { return a.detection < b.detection; });
  result.status = MatchStatus::kOk;
  return result;
}

}  // namespace auvdock
