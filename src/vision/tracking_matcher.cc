#include "auvdock/vision/tracking_matcher.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include <Eigen/Dense>

#include "auvdock/geometry/so3.h"
#include "auvdock/vision/hungarian.h"

namespace auvdock {

namespace {

struct ProjectedLight {
  int index = -1;  // into dock.lights
  int light_id = -1;
  Eigen::Vector2d uv = Eigen::Vector2d::Zero();  // predicted pixel
  double gate_px = 0.0;                          // residual gate around it
};

// Support of one candidate offset: for each projected light, the nearest detection within its
// residual gate (or -1), and the mean offset of that labelling (detection minus projection over
// its support; zero without support).
struct OffsetSupport {
  Eigen::Vector2d offset = Eigen::Vector2d::Zero();
  std::vector<int> detection_of_light;
  int count = 0;
  double squared_residual = 0.0;
  Eigen::Vector2d labelled_offset = Eigen::Vector2d::Zero();
};

OffsetSupport Support(const std::vector<LightDetection>& detections,
                      const std::vector<ProjectedLight>& lights, const Eigen::Vector2d& offset) {
  OffsetSupport support;
  support.offset = offset;
  support.detection_of_light.assign(lights.size(), -1);
  for (size_t i = 0; i < lights.size(); ++i) {
    const Eigen::Vector2d predicted = lights[i].uv + offset;
    double best = lights[i].gate_px * lights[i].gate_px;
    for (size_t j = 0; j < detections.size(); ++j) {
      const double d2 = (detections[j].uv - predicted).squaredNorm();
      if (d2 <= best) {
        best = d2;
        support.detection_of_light[i] = static_cast<int>(j);
      }
    }
    if (support.detection_of_light[i] >= 0) {
      ++support.count;
      support.squared_residual += best;
      support.labelled_offset += detections[support.detection_of_light[i]].uv - lights[i].uv;
    }
  }
  support.labelled_offset /= std::max(1, support.count);
  return support;
}

bool Better(const OffsetSupport& a, const OffsetSupport& b) {
  if (a.count != b.count) return a.count > b.count;
  return a.squared_residual < b.squared_residual;
}

MatchResult Failed(const std::string& reason) {
  MatchResult result;
  result.status = MatchStatus::kFailed;
  result.reason = reason;
  return result;
}

MatchResult Ambiguous(const std::string& reason) {
  MatchResult result;
  result.status = MatchStatus::kAmbiguous;
  result.reason = reason;
  return result;
}

// Gated Hungarian between the lights (at their projections, each with its gate) and the
// detections not excluded, cost = pixel distance. Returns false with a reason when a second choice
// is within margin_px of a chosen pair (two lights for one detection, or two detections for one
// light).
// gate_scale (optional, per detection): the light's gate is widened by it for that detection.
bool AssignGated(const std::vector<LightDetection>& detections,
                 const std::vector<ProjectedLight>& lights, const std::vector<char>& excluded,
                 double margin_px, std::vector<int>* detection_of_light, std::string* reason,
                 const std::vector<double>* gate_scale = nullptr) {
  Eigen::MatrixXd cost(lights.size(), detections.size());
  for (size_t i = 0; i < lights.size(); ++i) {
    for (size_t j = 0; j < detections.size(); ++j) {
      const double d = (detections[j].uv - lights[i].uv).norm();
      const double gate = lights[i].gate_px * (gate_scale ? (*gate_scale)[j] : 1.0);
      cost(i, j) = d <= gate && !excluded[j] ? d : kForbiddenCost;
    }
  }
  *detection_of_light = SolveAssignment(cost);
  for (size_t i = 0; i < lights.size(); ++i) {
    const int j = (*detection_of_light)[i];
    if (j < 0) continue;
    const double chosen = cost(i, j);
    for (size_t k = 0; k < lights.size(); ++k) {
      if (k != i && std::isfinite(cost(k, j)) && cost(k, j) <= chosen + margin_px) {
        *reason = "lights " + std::to_string(lights[i].light_id) + " and " +
                  std::to_string(lights[k].light_id) +
                  " both project within their gate of detection " + std::to_string(j);
        return false;
      }
    }
    for (size_t l = 0; l < detections.size(); ++l) {
      if (static_cast<int>(l) != j && std::isfinite(cost(i, l)) &&
          cost(i, l) <= chosen + margin_px) {
        *reason = "detections " + std::to_string(j) + " and " + std::to_string(l) +
                  " both lie within the gate of light " + std::to_string(lights[i].light_id);
        return false;
      }
    }
  }
  return true;
}

int Count(const std::vector<int>& detection_of_light) {
  return static_cast<int>(std::count_if(detection_of_light.begin(), detection_of_light.end(),
                                        [](int j) { return j >= 0; }));
}

}  // namespace

bool PoseFitConsistentWithNoise(double squared_error_px2, int num_matches, double sigma_px,
                                double alpha) {
  // Survival function of chi-square with an even number k = 2m of degrees of freedom:
  //   P(chi2 > x) = exp(-x/2) sum_{i<m} (x/2)^i / i!.
  const int m = num_matches - 3;  // k = 2 n - 6
  if (m <= 0) return true;        // a minimal set fits exactly
  const double half = 0.5 * squared_error_px2 / (sigma_px * sigma_px);
  double term = 1.0;
  double sum = 1.0;
  for (int i = 1; i < m; ++i) {
    term *= half / i;
    sum += term;
  }
  return std::exp(-half) * sum >= alpha;
}

double RefinePoseOnCorrespondences(const std::vector<Eigen::Vector3d>& points_D,
                                   const std::vector<Eigen::Vector2d>& normalized_xy, double fx,
                                   double fy, Pose3* T_C_D, const std::vector<double>& weights) {
  const auto weight = [&](size_t i) { return weights.empty() ? 1.0 : weights[i]; };
  Eigen::Matrix3d R = T_C_D->R();
  Eigen::Vector3d t = T_C_D->p;
  auto cost_of = [&](const Eigen::Matrix3d& R_c, const Eigen::Vector3d& t_c) {
    double cost = 0.0;
    for (size_t i = 0; i < points_D.size(); ++i) {
      const Eigen::Vector3d p = R_c * points_D[i] + t_c;
      if (!(p.z() > 1e-9)) return std::numeric_limits<double>::infinity();
      const double du = fx * (p.x() / p.z() - normalized_xy[i].x());
      const double dv = fy * (p.y() / p.z() - normalized_xy[i].y());
      cost += weight(i) * (du * du + dv * dv);
    }
    return cost;
  };
  double cost = cost_of(R, t);
  double lambda = -1.0;  // set from the first normal matrix
  for (int iteration = 0; iteration < 20; ++iteration) {
    Eigen::Matrix<double, 6, 6> H = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 6, 1> g = Eigen::Matrix<double, 6, 1>::Zero();
    for (size_t i = 0; i < points_D.size(); ++i) {
      const Eigen::Vector3d RX = R * points_D[i];
      const Eigen::Vector3d p = RX + t;
      const double iz = 1.0 / p.z();
      Eigen::Matrix<double, 2, 3> J_proj;
      J_proj << fx * iz, 0.0, -fx * p.x() * iz * iz,  //
          0.0, fy * iz, -fy * p.y() * iz * iz;
      // p_C = Exp(dtheta) R X + t + dt  =>  d p_C = -[R X]x dtheta + dt.
      Eigen::Matrix<double, 2, 6> J;
      J.leftCols<3>() = -J_proj * Hat(RX);
      J.rightCols<3>() = J_proj;
      const Eigen::Vector2d r(fx * (p.x() * iz - normalized_xy[i].x()),
                              fy * (p.y() * iz - normalized_xy[i].y()));
      H.noalias() += weight(i) * J.transpose() * J;
      g.noalias() += weight(i) * J.transpose() * r;
    }
    if (lambda < 0.0) lambda = 1e-4 * H.diagonal().mean();
    bool improved = false;
    bool converged = false;
    for (int attempt = 0; attempt < 10 && !improved; ++attempt) {
      Eigen::Matrix<double, 6, 6> damped = H;
      damped.diagonal() += lambda * (H.diagonal().array() + 1e-12).matrix();
      const Eigen::Matrix<double, 6, 1> step = -damped.ldlt().solve(g);
      if (!step.allFinite()) break;
      const Eigen::Matrix3d R_candidate = ExpSO3(step.head<3>()) * R;
      const Eigen::Vector3d t_candidate = t + step.tail<3>();
      const double candidate_cost = cost_of(R_candidate, t_candidate);
      if (candidate_cost < cost) {
        converged = cost - candidate_cost < 1e-10 * (1.0 + cost);
        R = R_candidate;
        t = t_candidate;
        cost = candidate_cost;
        lambda = std::max(lambda / 10.0, 1e-12);
        improved = true;
      } else {
        lambda *= 10.0;
      }
    }
    if (!improved || converged) break;
  }
  *T_C_D = Pose3(Eigen::Quaterniond(R), t);
  return cost;
}

MatchResult MatchByPrediction(const std::vector<LightDetection>& detections, const DockModel& dock,
                              const PinholeRadtanCamera& camera, const Pose3& predicted_T_C_D,
                              double gate_px) {
  TrackingMatcherOptions options;
  options.gate_px = gate_px;
  return MatchByPrediction(detections, dock, camera, predicted_T_C_D, options);
}

MatchResult MatchByPrediction(const std::vector<LightDetection>& detections, const DockModel& dock,
                              const PinholeRadtanCamera& camera, const Pose3& predicted_T_C_D,
                              const TrackingMatcherOptions& options) {
  std::vector<ProjectedLight> lights;
  lights.reserve(dock.lights.size());
  for (size_t i = 0; i < dock.lights.size(); ++i) {
    const auto uv = camera.Project(predicted_T_C_D * dock.lights[i].p_D, options.min_depth_m);
    if (uv) lights.push_back({static_cast<int>(i), dock.lights[i].id, *uv, 0.0});
  }
  if (static_cast<int>(lights.size()) < options.min_matches) {
    return Failed("only " + std::to_string(lights.size()) + " lights in front of the camera");
  }
  if (static_cast<int>(detections.size()) < options.min_matches) {
    return Failed("only " + std::to_string(detections.size()) + " detections");
  }
  const double max_gate =
      std::max(options.residual_fraction_of_gate * options.gate_px, options.min_residual_gate_px);
  for (size_t i = 0; i < lights.size(); ++i) {
    double nearest = std::numeric_limits<double>::infinity();
    for (size_t k = 0; k < lights.size(); ++k) {
      if (k != i) nearest = std::min(nearest, (lights[k].uv - lights[i].uv).norm());
    }
    lights[i].gate_px =
        std::clamp(options.spacing_fraction * nearest, options.min_residual_gate_px, max_gate);
  }

  // Each detection's noise relative to pixel_noise_px (its own covariance, never below it), and
  // its final gate relative to final_gate_px (3 of its own sigmas, never below that gate).
  std::vector<double> scale(detections.size(), 1.0), gate_scale(detections.size(), 1.0);
  if (options.use_detection_covariance) {
    for (size_t j = 0; j < detections.size(); ++j) {
      const double own = std::sqrt(std::max(0.0, detections[j].covariance.trace() / 2.0));
      if (!std::isfinite(own)) continue;
      scale[j] = std::max(1.0, own / options.pixel_noise_px);
      gate_scale[j] = std::max(1.0, 3.0 * own / options.final_gate_px);
    }
  }

  // 1. The common image offset with the most support.
  std::vector<OffsetSupport> candidates;
  candidates.push_back(Support(detections, lights, Eigen::Vector2d::Zero()));
  const double gate2 = options.gate_px * options.gate_px;
  for (const ProjectedLight& light : lights) {
    for (const LightDetection& detection : detections) {
      const Eigen::Vector2d offset = detection.uv - light.uv;
      if (offset.squaredNorm() <= gate2) {
        candidates.push_back(Support(detections, lights, offset));
      }
    }
  }
  size_t best_index = 0;
  for (size_t c = 1; c < candidates.size(); ++c) {
    if (Better(candidates[c], candidates[best_index])) best_index = c;
  }
  if (candidates[best_index].count < options.min_matches) {
    return Failed("only " + std::to_string(candidates[best_index].count) +
                  " lights have a detection near their predicted position");
  }
  // How far a candidate's labelling lies from the prediction (pixels).
  auto labelled_offset = [](const OffsetSupport& c) { return c.labelled_offset.norm(); };
  // Among the labellings explaining the most lights, the one nearest the prediction: it wins when
  // every other is decisive_offset_ratio times as far from it.
  const int most = candidates[best_index].count;
  const OffsetSupport* nearest = &candidates[best_index];
  double nearest_px = labelled_offset(*nearest);
  for (const OffsetSupport& c : candidates) {
    if (c.count != most) continue;
    const double px = labelled_offset(c);
    if (px < nearest_px) {
      nearest = &c;
      nearest_px = px;
    }
  }
  const double decisive_px =
      options.decisive_offset_ratio * std::max(nearest_px, options.min_residual_gate_px);
  bool decisive = options.decisive_offset_ratio > 0.0;
  for (const OffsetSupport& other : candidates) {
    if (other.count == most && other.detection_of_light != nearest->detection_of_light &&
        !(labelled_offset(other) > decisive_px)) {
      decisive = false;
    }
  }
  const OffsetSupport& best_candidate = decisive ? *nearest : candidates[best_index];
  // One light more, far from the prediction: a labelling with one light less decisively nearer
  // to it, which contradicts the chosen one, may be the truth with a light missed, and the chosen
  // one a pattern shifted along a row of lights that a spurious detection completes.
  if (options.decisive_offset_ratio > 0.0) {
    const double chosen_px = labelled_offset(best_candidate);
    for (const OffsetSupport& other : candidates) {
      // Three lights fix an offset (fewer may coincide with clutter anywhere); min_matches does
      // not apply: the contradicting labelling is not taken, only heard.
      if (other.count != most - 1 || other.count < 3) continue;
      const double other_px = labelled_offset(other);
      if (!(chosen_px > options.decisive_offset_ratio *
                            std::max(other_px, options.min_residual_gate_px))) {
        continue;
      }
      bool contradicts = false;
      for (size_t i = 0; i < lights.size() && !contradicts; ++i) {
        const int j = other.detection_of_light[i];
        contradicts = j >= 0 && best_candidate.detection_of_light[i] != j;
      }
      if (!contradicts) continue;
      std::ostringstream reason;
      reason.precision(3);
      reason << "the labelling of " << most << " lights lies " << chosen_px
             << " px from the prediction, one of " << other.count << " other lights " << other_px
             << " px: a light may be missed, or the pattern shifted along a row";
      return Ambiguous(reason.str());
    }
  }
  // Another offset explaining as many lights with a different labelling: refuse to choose.
  for (const OffsetSupport& other : candidates) {
    if (!decisive && other.count == best_candidate.count &&
        other.detection_of_light != best_candidate.detection_of_light) {
      std::ostringstream reason;
      reason.precision(3);
      reason << "two image offsets of the prediction, (" << best_candidate.offset.x() << ", "
             << best_candidate.offset.y() << ") and (" << other.offset.x() << ", "
             << other.offset.y() << ") px, each explain " << best_candidate.count
             << " lights with different labels";
      return Ambiguous(reason.str());
    }
  }
  const Eigen::Vector2d offset = best_candidate.labelled_offset;

  // 2. Gated Hungarian around the offset-corrected projections.
  std::vector<ProjectedLight> shifted = lights;
  for (ProjectedLight& light : shifted) light.uv += offset;
  std::vector<int> detection_of_light;
  std::string reason;
  std::vector<char> excluded(detections.size(), 0);
  if (!AssignGated(detections, shifted, excluded, options.ambiguity_margin_px, &detection_of_light,
                   &reason)) {
    return Ambiguous(reason);
  }
  std::vector<ProjectedLight> final_lights = shifted;

  // 3. Pose refinement on these matches, then re-association at the refined pose with the tight
  //    final gate, until the labelling is stable. While the refined pose does not explain the
  //    matches at the noise level, the match whose removal leaves the best fit is excluded if
  //    that removal alone accounts for the misfit (leave-one-out: with few, partly collinear
  //    lights the largest residual is often on an innocent light); never below 4 matches, a
  //    minimal set being unverifiable.
  if (options.refine_pose) {
    std::vector<Eigen::Vector2d> normalized(detections.size());
    for (size_t j = 0; j < detections.size(); ++j) {
      normalized[j] = camera.Unproject(detections[j].uv);
    }
    // Refines T_C_D on the matches of `assignment` (skipping light `skip`); returns the squared
    // error in raw pixels (the noise model's space) and whether every match is within the gate.
    auto fit = [&](const std::vector<int>& assignment, int skip, Pose3* T_C_D, int* count,
                   bool* within_gate) {
      std::vector<Eigen::Vector3d> points_D;
      std::vector<Eigen::Vector2d> points_xy;
      std::vector<double> weights;
      for (size_t i = 0; i < lights.size(); ++i) {
        if (assignment[i] < 0 || static_cast<int>(i) == skip) continue;
        points_D.push_back(dock.lights[lights[i].index].p_D);
        points_xy.push_back(normalized[assignment[i]]);
        const double k = scale[assignment[i]];
        weights.push_back(1.0 / (k * k));
      }
      *count = static_cast<int>(points_D.size());
      if (*count < 3) return std::numeric_limits<double>::infinity();
      RefinePoseOnCorrespondences(points_D, points_xy, camera.fx(), camera.fy(), T_C_D, weights);
      double squared_error = 0.0;
      *within_gate = true;
      for (size_t i = 0; i < lights.size(); ++i) {
        if (assignment[i] < 0 || static_cast<int>(i) == skip) continue;
        const auto uv = camera.Project(*T_C_D * dock.lights[lights[i].index].p_D);
        const double k = scale[assignment[i]];
        const double gate = options.final_gate_px * gate_scale[assignment[i]];
        const double r2 = uv ? (*uv - detections[assignment[i]].uv).squaredNorm()
                             : std::numeric_limits<double>::infinity();
        squared_error += r2 / (k * k);
        *within_gate = *within_gate && r2 <= gate * gate;
      }
      return squared_error;
    };
    Pose3 T_C_D = predicted_T_C_D;
    for (int round = 0; round < 4; ++round) {
      for (;;) {
        int count = 0;
        bool within_gate = false;
        const double squared_error = fit(detection_of_light, -1, &T_C_D, &count, &within_gate);
        if (count < std::max(3, options.min_matches)) {
          return Failed("only " + std::to_string(count) + " matches");
        }
        if (within_gate && PoseFitConsistentWithNoise(squared_error, count, options.pixel_noise_px,
                                                      options.consistency_alpha)) {
          break;
        }
        if (count <= 4) {
          return Failed("the " + std::to_string(count) +
                        " matches are not consistent with one pose at the pixel noise");
        }
        int drop = -1;
        double best_error = std::numeric_limits<double>::infinity();
        Pose3 best_pose = T_C_D;
        for (size_t i = 0; i < lights.size(); ++i) {
          if (detection_of_light[i] < 0) continue;
          Pose3 candidate = T_C_D;
          int remaining = 0;
          bool candidate_within_gate = false;
          const double candidate_error = fit(detection_of_light, static_cast<int>(i), &candidate,
                                             &remaining, &candidate_within_gate);
          if (candidate_error < best_error) {
            best_error = candidate_error;
            drop = static_cast<int>(i);
            best_pose = candidate;
          }
        }
        // The removal must explain the excess by itself (a leave-one-out outlier test with 2
        // degrees of freedom at the same false-alarm rate); otherwise the misfit is spread over
        // the matches -- noise heavier than modelled, not a wrong match -- and they are kept.
        const double explained =
            (squared_error - best_error) / (options.pixel_noise_px * options.pixel_noise_px);
        if (within_gate && explained < -2.0 * std::log(options.consistency_alpha)) break;
        excluded[detection_of_light[drop]] = 1;  // not offered again at the refined pose
        detection_of_light[drop] = -1;
        T_C_D = best_pose;
      }
      std::vector<ProjectedLight> refined;
      for (const ProjectedLight& light : lights) {
        const auto uv = camera.Project(T_C_D * dock.lights[light.index].p_D, options.min_depth_m);
        // A light now behind the camera gets a far-away position and so no detection.
        refined.push_back({light.index, light.light_id, uv ? *uv : Eigen::Vector2d::Constant(1e9),
                           options.final_gate_px});
      }
      std::vector<int> reassigned;
      if (!AssignGated(detections, refined, excluded, options.ambiguity_margin_px, &reassigned,
                       &reason, &gate_scale)) {
        return Ambiguous("at the refined pose: " + reason);
      }
      const bool unchanged = reassigned == detection_of_light;
      detection_of_light = reassigned;
      final_lights = refined;
      if (unchanged) break;
    }
  }

  MatchResult result;
  double squared_sum = 0.0;
  for (size_t i = 0; i < final_lights.size(); ++i) {
    const int j = detection_of_light[i];
    if (j < 0) continue;
    result.matches.push_back({j, final_lights[i].light_id});
    squared_sum += (detections[j].uv - final_lights[i].uv).squaredNorm() / (scale[j] * scale[j]);
  }
  if (Count(detection_of_light) < options.min_matches) {
    return Failed("only " + std::to_string(result.matches.size()) + " matches");
  }
  if (options.refine_pose &&
      !PoseFitConsistentWithNoise(squared_sum, static_cast<int>(result.matches.size()),
                                  options.pixel_noise_px, options.acceptance_alpha)) {
    std::ostringstream reason;
    reason.precision(3);
    reason << "the refined pose leaves an rms of "
           << std::sqrt(squared_sum / static_cast<double>(result.matches.size()))
           << " px, far more than " << options.pixel_noise_px << " px noise explains";
    return Failed(reason.str());
  }
  std::sort(result.matches.begin(), result.matches.end(),
            [](const LightMatch& a, const LightMatch& b) { return a.detection < b.detection; });
  result.status = MatchStatus::kOk;
  result.cost = std::sqrt(squared_sum / static_cast<double>(result.matches.size()));
  return result;
}

}  // namespace auvdock
