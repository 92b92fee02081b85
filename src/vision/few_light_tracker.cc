#include "auvdock/vision/few_light_tracker.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include "auvdock/estimator/adaptive_noise_scale.h"
#include "auvdock/geometry/so3.h"
#include "auvdock/vision/guided_light_search.h"

namespace auvdock {
namespace {

struct ProjectedLight {
  int light_id = -1;
  Eigen::Vector3d p_D = Eigen::Vector3d::Zero();
  Eigen::Vector2d uv = Eigen::Vector2d::Zero();
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Zero();
  double spacing_px = 0.0;  // to the nearest other light's projection (in the image or not)
  bool near_image = false;  // within the image or image_margin_px of it
};

// Every light in front of the camera that it can project, in the image or not (PredictLights
// without its image margin).
std::vector<ProjectedLight> ProjectLights(const PinholeRadtanCamera& camera, const DockModel& dock,
                                          const Pose3& T_C_D,
                                          const Eigen::Matrix<double, 6, 6>& P_pose,
                                          double margin_px) {
  const std::vector<PredictedLight> predicted =
      PredictLights(dock, camera, T_C_D, P_pose, {}, -std::numeric_limits<double>::infinity());
  std::vector<ProjectedLight> out;
  for (const PredictedLight& p : predicted) {
    // A light whose projection has no Jacobian (at the lens's fold) is not followed.
    if (p.covariance.isZero() && !P_pose.isZero()) continue;
    ProjectedLight v;
    v.light_id = p.light_id;
    v.p_D = dock.FindLight(p.light_id)->p_D;
    v.uv = p.uv;
    v.covariance = p.covariance;
    v.near_image = camera.InImage(p.uv, margin_px);
    v.spacing_px = std::numeric_limits<double>::infinity();
    for (const PredictedLight& other : predicted) {
      if (other.light_id != p.light_id) {
        v.spacing_px = std::min(v.spacing_px, (other.uv - p.uv).norm());
      }
    }
    out.push_back(v);
  }
  return out;
}

double SquaredMahalanobis(const Eigen::Vector2d& r, const Eigen::Matrix2d& S) {
  return r.dot(S.ldlt().solve(r));
}

Pose3 Retract(const Pose3& T, const Eigen::Matrix<double, 6, 1>& x) {
  return Pose3(ExpQuaternion(x.head<3>()) * T.q, T.p + x.tail<3>());
}

}  // namespace

FewLightTracker::FewLightTracker(const PinholeRadtanCamera& camera, const DockModel& dock,
                                 double frame_interval_s, const FewLightTrackerOptions& options)
    : camera_(camera), dock_(dock), dt_(frame_interval_s), options_(options) {
  if (!(dt_ > 0.0) || options.min_start_poses < 3 ||
      options.max_start_poses < options.min_start_poses ||
      !(options.max_acceleration_mps2 >= 0.0) ||
      !(options.max_angular_acceleration_radps2 >= 0.0) || !(options.acceleration_time_s > 0.0) || !(options.gate_chi2 > 0.0) ||
      !(options.unexplained_chi2 >= options.gate_chi2) || !(options.unexplained_floor_px >= 0.0) ||
      !(options.unexplained_spacing_fraction >= 0.0) ||
      !(options.consistency_alpha > 0.0 && options.consistency_alpha < 1.0) ||
      !(options.pixel_noise_px > 0.0) || !(options.max_sigma_px > 0.0) ||
      !(options.guide_spacing_fraction >= 0.0) || options.max_frames < 1 ||
      options.max_unlabelled_frames < 0) {
    throw std::invalid_argument("FewLightTrackerOptions out of range");
  }
}

void FewLightTracker::End(const std::string& reason) {
  walking_ = false;
  end_reason_ = reason;
}

bool FewLightTracker::Start(const std::vector<Pose3>& poses,
                            const std::vector<Matrix6>& covariances, double residual_sigma_px) {
  walking_ = false;
  unlabelled_frames_ = 0;
  noise_px_ = std::max(options_.pixel_noise_px, residual_sigma_px);
  frames_ = 0;
  end_reason_.clear();
  if (poses.size() != covariances.size() ||
      static_cast<int>(poses.size()) < options_.min_start_poses) {
    end_reason_ = "too few posed frames to start from";
    return false;
  }
  const int m = std::min<int>(static_cast<int>(poses.size()), options_.max_start_poses);
  const size_t first = poses.size() - m;
  const Pose3& anchor = poses.back();
  // Least-squares slope of (Log(R_i R_a^T), p_i - p_a) against i.
  using Vector6 = Eigen::Matrix<double, 6, 1>;
  std::vector<Vector6> y(m);
  Vector6 mean = Vector6::Zero();
  Matrix6 mean_covariance = Matrix6::Zero();
  for (int i = 0; i < m; ++i) {
    const Pose3& T = poses[first + i];
    y[i].head<3>() = LogQuaternion(T.q * anchor.q.conjugate());
    y[i].tail<3>() = T.p - anchor.p;
    mean += y[i] / m;
    mean_covariance += covariances[first + i] / m;
  }
  const double x_mean = 0.5 * (m - 1);
  const double sxx = m * (static_cast<double>(m) * m - 1.0) / 12.0;
  Vector6 slope = Vector6::Zero();
  for (int i = 0; i < m; ++i) slope += (i - x_mean) * (y[i] - mean) / sxx;
  T_C_D_ = anchor;
  omega_ = slope.head<3>();
  v_ = slope.tail<3>();
  P_.setZero();
  P_.topLeftCorner<6, 6>() = covariances.back();
  P_.bottomRightCorner<6, 6>() = mean_covariance / sxx;
  walking_ = true;
  return true;
}

std::optional<FewLightStep> FewLightTracker::Step(const std::vector<LightDetection>& detections,
                                                  const std::vector<LightDetection>& doubtful) {
  if (!walking_) return std::nullopt;
  if (frames_ >= options_.max_frames) {
    End("walked " + std::to_string(frames_) + " frames");
    return std::nullopt;
  }
  ++frames_;
  // Predict.
  // White-noise acceleration of spectral density (acceleration)^2 tau: the rate per frame
  // (velocity dt) changes by a variance of (acceleration)^2 tau dt^3 per frame.
  const double per_frame = std::sqrt(options_.acceleration_time_s * dt_ * dt_ * dt_);
  const double sigma_omega = options_.max_angular_acceleration_radps2 * per_frame;
  const double sigma_v = (options_.max_acceleration_mps2 +
                          options_.max_angular_acceleration_radps2 * T_C_D_.p.norm()) *
                             per_frame +
                         omega_.norm() * v_.norm();
  T_C_D_ = Pose3(ExpQuaternion(omega_) * T_C_D_.q, T_C_D_.p + v_);
  // The rate persists for about acceleration_time_s (first-order Gauss-Markov): what no light
  // observes (the range to a single light) stops changing instead of running on.
  const double rho = std::exp(-dt_ / options_.acceleration_time_s);
  omega_ *= rho;
  v_ *= rho;
  Matrix12 F = Matrix12::Identity();
  F.block<6, 6>(0, 6).setIdentity();
  F.bottomRightCorner<6, 6>() *= rho;
  P_ = F * P_ * F.transpose();
  P_.block<3, 3>(6, 6) += sigma_omega * sigma_omega * Eigen::Matrix3d::Identity();
  P_.block<3, 3>(9, 9) += sigma_v * sigma_v * Eigen::Matrix3d::Identity();
  P_ = 0.5 * (P_ + P_.transpose());

  const Matrix6 P_pose = P_.topLeftCorner<6, 6>();
  const std::vector<ProjectedLight> lights =
      ProjectLights(camera_, dock_, T_C_D_, P_pose, options_.image_margin_px);
  if (std::none_of(lights.begin(), lights.end(),
                   [](const ProjectedLight& l) { return l.near_image; })) {
    End("no light of the dock in the image");
    return std::nullopt;
  }
  // Lights more uncertain than max_sigma_px (or guide_spacing_fraction of their spacing) guide
  // nothing (they are not labelled), but their wide gates still keep what lies near them from
  // being judged.
  std::vector<bool> guides(lights.size(), false);
  bool any_guide = false;
  for (size_t l = 0; l < lights.size(); ++l) {
    const double largest = Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(lights[l].covariance)
                               .eigenvalues()
                               .maxCoeff();
    const double max_sigma =
        std::max(options_.max_sigma_px, options_.guide_spacing_fraction * lights[l].spacing_px);
    guides[l] = lights[l].near_image && std::sqrt(std::max(largest, 0.0)) <= max_sigma;
    any_guide |= guides[l] && camera_.InImage(lights[l].uv);
  }
  if (!any_guide) {
    End("the prediction is too uncertain to guide");
    return std::nullopt;
  }

  // Gate and label: j is L when each is the other's only candidate.
  const size_t n_det = detections.size(), n_light = lights.size();
  std::vector<Eigen::Matrix2d> R(n_det);
  std::vector<std::vector<double>> d2(n_det, std::vector<double>(n_light));
  for (size_t j = 0; j < n_det; ++j) {
    R[j] = PixelCovarianceAtLeast(detections[j], noise_px_);
    for (size_t l = 0; l < n_light; ++l) {
      d2[j][l] = SquaredMahalanobis(detections[j].uv - lights[l].uv, lights[l].covariance + R[j]);
    }
  }
  FewLightStep step;
  step.light_ids.assign(n_det, -1);
  step.unexplained.assign(n_det, false);
  std::vector<std::pair<size_t, size_t>> labels;  // (detection, light)
  for (size_t j = 0; j < n_det; ++j) {
    int only = -1, count = 0;
    for (size_t l = 0; l < n_light; ++l) {
      if (guides[l] && d2[j][l] <= options_.gate_chi2) {
        only = static_cast<int>(l);
        ++count;
      }
    }
    if (count != 1) continue;
    int holders = 0;
    for (size_t k = 0; k < n_det; ++k) holders += d2[k][only] <= options_.gate_chi2;
    if (holders == 1) labels.emplace_back(j, static_cast<size_t>(only));
  }
  // A guiding light with no detection in its gate takes a doubtful candidate there: the one
  // nearest the prediction, when no other light's gate holds it and every other doubtful
  // candidate in the gate is the same blob at another scale (within its radius).
  step.doubtful_light_ids.assign(doubtful.size(), -1);
  std::vector<Eigen::Matrix2d> R_doubtful(doubtful.size());
  for (size_t k = 0; k < doubtful.size(); ++k) {
    R_doubtful[k] = PixelCovarianceAtLeast(doubtful[k], noise_px_);
  }
  std::vector<std::pair<size_t, size_t>> doubtful_labels;  // (doubtful candidate, light)
  for (size_t l = 0; l < n_light && !doubtful.empty(); ++l) {
    if (!guides[l]) continue;
    bool held = false;
    for (size_t j = 0; j < n_det; ++j) held |= d2[j][l] <= options_.gate_chi2;
    if (held) continue;
    std::vector<std::pair<double, size_t>> in_gate;
    for (size_t k = 0; k < doubtful.size(); ++k) {
      const double d2_kl =
          SquaredMahalanobis(doubtful[k].uv - lights[l].uv, lights[l].covariance + R_doubtful[k]);
      if (d2_kl <= options_.gate_chi2) in_gate.emplace_back(d2_kl, k);
    }
    if (in_gate.empty()) continue;
    const size_t best = std::min_element(in_gate.begin(), in_gate.end())->second;
    bool one_blob = true;
    for (const auto& [unused, k] : in_gate) {
      one_blob &= (doubtful[k].uv - doubtful[best].uv).norm() <=
                  std::max(doubtful[best].radius_px, doubtful[k].radius_px);
    }
    // Another light that guides and whose gate holds it competes (one that does not guide,
    // pinned down by nothing seen, may reach anywhere through the linearised projection).
    bool other_light = false;
    for (size_t o = 0; o < n_light; ++o) {
      other_light |= o != l && guides[o] &&
                     SquaredMahalanobis(doubtful[best].uv - lights[o].uv,
                                        lights[o].covariance + R_doubtful[best]) <=
                         options_.gate_chi2;
    }
    if (one_blob && !other_light) doubtful_labels.emplace_back(best, l);
  }

  // Iterated update on the labelled lights, the prediction as prior.
  struct Observed {
    Eigen::Vector2d uv;
    Eigen::Matrix2d R;
    size_t light;
  };
  std::vector<Observed> observed;
  for (const auto& [j, l] : labels) observed.push_back({detections[j].uv, R[j], l});
  for (const auto& [k, l] : doubtful_labels) observed.push_back({doubtful[k].uv, R_doubtful[k], l});
  if (!observed.empty()) {
    const int n = static_cast<int>(observed.size());
    const Pose3 predicted = T_C_D_;
    Eigen::MatrixXd Rm = Eigen::MatrixXd::Zero(2 * n, 2 * n);
    for (int i = 0; i < n; ++i) Rm.block<2, 2>(2 * i, 2 * i) = observed[i].R;
    Eigen::Matrix<double, 12, 1> x = Eigen::Matrix<double, 12, 1>::Zero();
    Eigen::MatrixXd H(2 * n, 12), K;
    double nis = 0.0;
    for (int iteration = 0; iteration < 5; ++iteration) {
      const Pose3 T = Retract(predicted, x.head<6>());
      Eigen::VectorXd r(2 * n);
      H.setZero();
      bool projected = true;
      for (int i = 0; i < n; ++i) {
        const ProjectedLight& l = lights[observed[i].light];
        const auto uv = camera_.Project(T * l.p_D, 0.05);
        if (!uv) {
          projected = false;
          break;
        }
        r.segment<2>(2 * i) = observed[i].uv - *uv;
        H.block<2, 6>(2 * i, 0) = ProjectionPoseJacobian(camera_, T, l.p_D);
      }
      if (!projected) {
        End("lost: a labelled light left the camera's view in the update");
        return std::nullopt;
      }
      const Eigen::MatrixXd S = H * P_ * H.transpose() + Rm;
      const Eigen::LDLT<Eigen::MatrixXd> S_ldlt(S);
      if (iteration == 0) nis = r.dot(S_ldlt.solve(r));
      K = P_ * H.transpose() * S_ldlt.solve(Eigen::MatrixXd::Identity(2 * n, 2 * n));
      const Eigen::Matrix<double, 12, 1> next = K * (r + H * x);
      const double change = (next - x).norm();
      x = next;
      if (change < 1e-9) break;
    }
    if (1.0 - ChiSquareCdf(2 * n, nis) < options_.consistency_alpha) {
      End("lost: " + std::to_string(n) + " labelled lights disagree with the prediction");
      return std::nullopt;
    }
    T_C_D_ = Retract(predicted, x.head<6>());
    omega_ += x.segment<3>(6);
    v_ += x.tail<3>();
    P_ = (Matrix12::Identity() - K * H) * P_;
    P_ = 0.5 * (P_ + P_.transpose());
    for (const auto& [j, l] : labels) step.light_ids[j] = lights[l].light_id;
    for (const auto& [k, l] : doubtful_labels) step.doubtful_light_ids[k] = lights[l].light_id;
    step.labelled = static_cast<int>(labels.size());
  }

  // Detections but none where a light should be: the prediction may have lost the lights (a jerk
  // the rate model cannot follow), so nothing is judged; a few such frames in a row end the walk.
  if (observed.empty() && n_det > 0) {
    if (++unlabelled_frames_ > options_.max_unlabelled_frames) {
      End("lost: " + std::to_string(unlabelled_frames_) +
          " frames in a row with detections and none where a light should be");
      return std::nullopt;
    }
    step.T_C_D = T_C_D_;
    step.covariance_local = P_.topLeftCorner<6, 6>();
    return step;
  }
  if (!observed.empty()) unlabelled_frames_ = 0;
  // Verdict, against the prediction's gates (the wider ones), of every light in front of the
  // camera: a model that misplaces a light may put it just outside the image. A light labelled
  // with another detection (or doubtful candidate) is taken: near it is a second detection.
  std::vector<bool> taken(n_light, false);
  for (const auto& [j, l] : labels) taken[l] = true;
  for (const auto& [k, l] : doubtful_labels) taken[l] = true;
  for (size_t j = 0; j < n_det; ++j) {
    if (step.light_ids[j] >= 0) continue;
    bool near_a_light = false;
    for (size_t l = 0; l < n_light; ++l) {
      if (taken[l]) continue;
      const double distance = (detections[j].uv - lights[l].uv).norm();
      near_a_light |= d2[j][l] <= options_.unexplained_chi2 ||
                      distance <= options_.unexplained_floor_px ||
                      distance <= options_.unexplained_spacing_fraction * lights[l].spacing_px;
    }
    step.unexplained[j] = !near_a_light;
  }
  step.T_C_D = T_C_D_;
  step.covariance_local = P_.topLeftCorner<6, 6>();
  return step;
}

}  // namespace auvdock
