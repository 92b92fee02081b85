#include "auvdock/vision/guided_light_search.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/Eigenvalues>

namespace auvdock {
namespace {

Eigen::Matrix3d Skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

Eigen::Matrix<double, 2, 3> ProjectionJacobian(const PinholeRadtanCamera& camera,
                                               const Eigen::Vector3d& p_C) {
  Eigen::Matrix<double, 2, 3> J = Eigen::Matrix<double, 2, 3>::Zero();
  const double h = 1e-6 * std::max(1.0, p_C.norm());
  for (int k = 0; k < 3; ++k) {
    Eigen::Vector3d plus = p_C, minus = p_C;
    plus[k] += h;
    minus[k] -= h;
    const auto a = camera.Project(plus);
    const auto b = camera.Project(minus);
    if (!a || !b) return Eigen::Matrix<double, 2, 3>::Zero();
    J.col(k) = (*a - *b) / (2.0 * h);
  }
  return J;
}

}  // namespace

Eigen::Matrix<double, 2, 6> ProjectionPoseJacobian(const PinholeRadtanCamera& camera,
                                                   const Pose3& T_C_D, const Eigen::Vector3d& p_D) {
  const Eigen::Vector3d Rp = T_C_D.q * p_D;
  Eigen::Matrix<double, 3, 6> dp;
  dp.leftCols<3>() = -Skew(Rp);
  dp.rightCols<3>() = Eigen::Matrix3d::Identity();
  return ProjectionJacobian(camera, Rp + T_C_D.p) * dp;
}

std::vector<PredictedLight> PredictLights(const DockModel& dock, const PinholeRadtanCamera& camera,
                                          const Pose3& T_C_D,
                                          const Eigen::Matrix<double, 6, 6>& covariance_local,
                                          const std::vector<int>& skip_ids, double margin_px,
                                          double min_depth_m) {
  std::vector<PredictedLight> out;
  const Eigen::Matrix3d R = T_C_D.R();
  for (const DockLight& light : dock.lights) {
    if (std::find(skip_ids.begin(), skip_ids.end(), light.id) != skip_ids.end()) continue;
    const Eigen::Vector3d Rp = R * light.p_D;
    const Eigen::Vector3d p_C = Rp + T_C_D.p;
    if (!(p_C.z() > min_depth_m)) continue;
    const auto uv = camera.Project(p_C, min_depth_m);
    if (!uv || !camera.InImage(*uv, margin_px)) continue;
    const Eigen::Matrix<double, 2, 6> J = ProjectionPoseJacobian(camera, T_C_D, light.p_D);
    PredictedLight p;
    p.light_id = light.id;
    p.uv = *uv;
    p.covariance = J * covariance_local * J.transpose();
    p.radius_px = camera.fx() * light.radius_m / p_C.z();
    p.depth_m = p_C.z();
    out.push_back(p);
  }
  return out;
}

double ObservedSizeRatio(const DockModel& dock, const PinholeRadtanCamera& camera,
                         const Pose3& T_C_D, const std::vector<LightDetection>& detections,
                         const std::vector<int>& light_ids) {
  const std::vector<PredictedLight> predicted =
      PredictLights(dock, camera, T_C_D, Eigen::Matrix<double, 6, 6>::Zero(), {});
  std::vector<double> ratios;
  for (size_t i = 0; i < detections.size() && i < light_ids.size(); ++i) {
    for (const PredictedLight& p : predicted) {
      if (p.light_id == light_ids[i] && p.radius_px > 0.0) {
        ratios.push_back(detections[i].radius_px / p.radius_px);
      }
    }
  }
  if (ratios.empty()) return 1.0;
  std::nth_element(ratios.begin(), ratios.begin() + ratios.size() / 2, ratios.end());
  return ratios[ratios.size() / 2];
}

GuidedLightSearch::GuidedLightSearch(const BlobLightDetectorOptions& full_image_options,
                                     const GuidedLightSearchOptions& options)
    : detector_options_(full_image_options), options_(options) {
  if (!(options.gate_sigmas >= 0.0) || !(options.gate_floor_px > 0.0) ||
      !(options.max_gate_px >= options.gate_floor_px) || !(options.min_response > 0.0) ||
      !(options.halo_excess_fraction >= 0.0 && options.halo_excess_fraction <= 1.0) ||
      !(options.window_sigmas >= 2.0) || options.num_scales < 3 || !(options.max_scale_ratio >= 2.0) ||
      !(options.min_separation_px >= 0.0)) {
    throw std::invalid_argument("GuidedLightSearchOptions out of range");
  }
  BlobLightDetector check(full_image_options);  // throws for the first pass's options
  (void)check;
}

std::vector<GuidedDetection> GuidedLightSearch::Search(
    const cv::Mat& image, const std::vector<PredictedLight>& predictions,
    const std::vector<LightDetection>& existing, double min_halo_excess) const {
  if (image.empty() || (image.type() != CV_8UC3 && image.type() != CV_8UC1)) {
    throw std::invalid_argument("GuidedLightSearch: expected a non-empty CV_8UC3 or CV_8UC1 image");
  }
  const double min_sigma_limit = detector_options_.candidates.min_sigma_px;
  std::vector<GuidedDetection> found;
  for (const PredictedLight& prediction : predictions) {
    const double spread = std::sqrt(std::max(
        0.0, Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(prediction.covariance,
                                                            Eigen::EigenvaluesOnly)
                 .eigenvalues()
                 .maxCoeff()));
    const double gate = options_.gate_sigmas * spread + options_.gate_floor_px;
    if (!std::isfinite(gate) || gate > options_.max_gate_px) continue;
    const bool judged = std::any_of(existing.begin(), existing.end(), [&](const LightDetection& e) {
      const double distance = (e.uv - prediction.uv).norm();
      if (distance > gate) return false;
      return std::none_of(predictions.begin(), predictions.end(), [&](const PredictedLight& other) {
        return (e.uv - other.uv).norm() < distance;
      });
    });
    if (judged) continue;
    // A disc of radius r blurred by the optics (~min_sigma) has a blob scale of about
    // sqrt(min_sigma^2 + r^2 / 2); a light's halo and bloom make it larger, never smaller.
    const double expected_sigma = std::sqrt(min_sigma_limit * min_sigma_limit +
                                            0.5 * prediction.radius_px * prediction.radius_px);
    BlobLightDetectorOptions relaxed = detector_options_;
    relaxed.candidates.min_sigma_px = std::max(min_sigma_limit, 0.5 * expected_sigma);
    relaxed.candidates.max_sigma_px =
        std::max(2.0 * relaxed.candidates.min_sigma_px, options_.max_scale_ratio * expected_sigma);
    relaxed.candidates.num_scales = options_.num_scales;
    relaxed.candidates.min_response = options_.min_response;
    // A predicted light beside a much brighter one is not that light's glow: the prediction
    // says a light is there.
    relaxed.max_response_in_halo = 0.0;
    const double half = gate + options_.window_sigmas * relaxed.candidates.max_sigma_px;
    int x0 = static_cast<int>(std::floor(prediction.uv.x() - half));
    int y0 = static_cast<int>(std::floor(prediction.uv.y() - half));
    int x1 = static_cast<int>(std::ceil(prediction.uv.x() + half)) + 1;
    int y1 = static_cast<int>(std::ceil(prediction.uv.y() + half)) + 1;
    x0 = std::max(0, x0);
    y0 = std::max(0, y0 - (y0 & 1));  // an even first row keeps the fields of interlaced video
    x1 = std::min(image.cols, x1);
    y1 = std::min(image.rows, y1);
    if (x1 - x0 < 16 || y1 - y0 < 16) continue;
    const cv::Mat window = image(cv::Rect(x0, y0, x1 - x0, y1 - y0));
    const BlobLightDetector detector(relaxed);
    const Eigen::Vector2d offset(x0, y0);
    const GuidedDetection* best = nullptr;
    GuidedDetection candidate;
    for (LightDetection d :
         detector.Detect(window, nullptr, options_.halo_excess_fraction * min_halo_excess)) {
      d.uv += offset;
      const double distance = (d.uv - prediction.uv).norm();
      if (distance > gate || (best && distance >= best->distance_px)) continue;
      const bool seen = std::any_of(existing.begin(), existing.end(), [&](const LightDetection& e) {
        return (e.uv - d.uv).norm() <
               std::max({options_.min_separation_px, e.radius_px, d.radius_px});
      });
      if (seen) continue;
      candidate = {prediction.light_id, d, distance};
      best = &candidate;
    }
    if (!best && options_.saturated_discs) {
      // Too close and bright for a blob: the saturated disc there, if it holds this light only.
      SaturatedDiscOptions disc_options;
      disc_options.search_radius_px = gate;
      const std::optional<LightDetection> disc = FindSaturatedDisc(image, prediction.uv, disc_options);
      if (disc) {
        const double distance = (disc->uv - prediction.uv).norm();
        const double disc_sigma = std::sqrt(0.5 * disc->covariance.trace());
        const bool alone = std::none_of(
            predictions.begin(), predictions.end(), [&](const PredictedLight& other) {
              return other.light_id != prediction.light_id &&
                     (other.uv - disc->uv).norm() < disc->radius_px;
            });
        const bool seen =
            std::any_of(existing.begin(), existing.end(), [&](const LightDetection& e) {
              return (e.uv - disc->uv).norm() < std::max(e.radius_px, disc->radius_px);
            });
        if (alone && !seen && distance <= gate + 3.0 * disc_sigma) {
          candidate = {prediction.light_id, *disc, distance};
          best = &candidate;
        }
      }
    }
    if (!best) continue;
    // One light per detection: a candidate another light's prediction already took goes to the
    // nearer prediction.
    auto same = std::find_if(found.begin(), found.end(), [&](const GuidedDetection& g) {
      return (g.detection.uv - candidate.detection.uv).norm() <
             std::max(options_.min_separation_px, candidate.detection.radius_px);
    });
    if (same == found.end()) {
      found.push_back(candidate);
    } else if (candidate.distance_px < same->distance_px) {
      *same = candidate;
    }
  }
  return found;
}

int SearchMissedLights(const GuidedLightSearch& search, const cv::Mat& image,
                       const DockModel& dock, const PinholeRadtanCamera& camera,
                       const Pose3& T_C_D, const Eigen::Matrix<double, 6, 6>& covariance_local,
                       double pixel_sigma_px, double min_halo_excess,
                       std::vector<LightDetection>* detections, std::vector<int>* light_ids) {
  std::vector<int> identified;
  for (int id : *light_ids) {
    if (id >= 0) identified.push_back(id);
  }
  std::vector<PredictedLight> predictions =
      PredictLights(dock, camera, T_C_D, covariance_local, identified);
  const double size = ObservedSizeRatio(dock, camera, T_C_D, *detections, *light_ids);
  for (PredictedLight& p : predictions) {
    p.covariance += pixel_sigma_px * pixel_sigma_px * Eigen::Matrix2d::Identity();
    p.radius_px *= size;
  }
  int added = 0;
  for (const GuidedDetection& g : search.Search(image, predictions, *detections, min_halo_excess)) {
    detections->push_back(g.detection);
    light_ids->push_back(g.light_id);
    ++added;
  }
  return added;
}

}  // namespace auvdock
