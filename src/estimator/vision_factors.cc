#include "auvdock/estimator/vision_factors.h"

#include <cmath>
#include <memory>
#include <optional>
#include <utility>

#include <ceres/loss_function.h>

#include "auvdock/geometry/pose3.h"
#include "auvdock/vision/stereo_triangulation.h"
#include "factors/mono_reprojection_factor.h"
#include "factors/pose_manifold.h"
#include "factors/stereo_point_factor.h"
#include "factors/time_shifted_factor.h"

namespace auvdock {
namespace {

constexpr double kZero3[3] = {0.0, 0.0, 0.0};

// huber_sigmas = +infinity: no robust loss (plain least squares, only the weight).
ceres::LossFunction* WeightedHuber(double huber_sigmas, double weight) {
  ceres::LossFunction* huber =
      std::isinf(huber_sigmas) ? nullptr : new ceres::HuberLoss(huber_sigmas);
  if (weight == 1.0) return huber;
  return new ceres::ScaledLoss(huber, weight, ceres::TAKE_OWNERSHIP);
}

// The triangulation covariance of a light at its position predicted from the body pose
// (T_B_D, the inverse of the pose block's value): projected into both cameras (noise-free
// pixels) and propagated as the front-end does.
std::optional<Eigen::Matrix3d> PredictedStereoCovariance(const VisionRig& rig, const Pose3& T_B_D,
                                                         const Eigen::Vector3d& p_D) {
  const Eigen::Vector3d p_B = T_B_D * p_D;
  const auto uv_left = rig.stereo_left->intrinsics.Project(rig.stereo_left->T_B_C.Inverse() * p_B);
  const auto uv_right =
      rig.stereo_right->intrinsics.Project(rig.stereo_right->T_B_C.Inverse() * p_B);
  if (!uv_left || !uv_right) return std::nullopt;
  const TriangulatedPoint predicted = TriangulateLinear(*uv_left, *uv_right, *rig.stereo_left,
                                                        *rig.stereo_right,
                                                        rig.stereo_left->pixel_noise_px);
  if (!predicted.ok || !predicted.covariance.allFinite() ||
      Eigen::LLT<Eigen::Matrix3d>(predicted.covariance).info() != Eigen::Success) {
    return std::nullopt;
  }
  return predicted.covariance;
}

double Factor(const std::map<int, double>& factors, int light_id) {
  const auto it = factors.find(light_id);
  return it == factors.end() ? 1.0 : it->second;
}

}  // namespace

double CorrelatedVisionVariance(double floor_px, double correlation_time_s,
                                double frame_interval_s) {
  const auto positive = [](double x) { return std::isfinite(x) && x > 0.0; };
  if (!positive(floor_px) || !positive(correlation_time_s) || !positive(frame_interval_s)) {
    return 0.0;
  }
  const double one_minus_rho = -std::expm1(-frame_interval_s / correlation_time_s);
  const double n_c = (2.0 - one_minus_rho) / one_minus_rho;  // (1 + rho) / (1 - rho)
  return n_c * floor_px * floor_px;
}

std::vector<VisionResidual> AddVisionFactors(ceres::Problem* problem, const VisionFrame& frame,
                                             const VisionRig& rig,
                                             const VisionFactorOptions& options,
                                             const StateBlocks& state, int* n_skipped) {
  std::vector<VisionResidual> added;
  const bool mono = options.use_mono && rig.mono != nullptr;
  const bool stereo = options.use_stereo && rig.stereo_left != nullptr;
  int n_mono = mono ? static_cast<int>(frame.mono.size()) : 0;
  int n_stereo = stereo ? static_cast<int>(frame.stereo.size()) : 0;
  // Each image's pose: the state's, moved by the IMU to the image's own time.
  const std::optional<ImuPoseShift> mono_shift =
      ImuShiftFromState(state, frame.t_ns, frame.mono_dt_ns, rig.dock->gravity_D);
  const std::optional<ImuPoseShift> stereo_shift =
      ImuShiftFromState(state, frame.t_ns, frame.stereo_dt_ns, rig.dock->gravity_D);
  if (!mono_shift) *n_skipped += std::exchange(n_mono, 0);
  if (!stereo_shift) *n_skipped += std::exchange(n_stereo, 0);
  double mono_pose[kPoseSize], stereo_pose[kPoseSize];
  if (mono_shift) mono_shift->Apply(state.pose, state.velocity ? state.velocity : kZero3, mono_pose);
  if (stereo_shift) {
    stereo_shift->Apply(state.pose, state.velocity ? state.velocity : kZero3, stereo_pose);
  }
  const StageWeights weights = StageWeighting(options.stage_weighting).Compute(n_stereo, n_mono);
  for (int i = 0; i < n_mono; ++i) {
    const MonoLightObservation& obs = frame.mono[i];
    const DockLight* light = rig.dock->FindLight(obs.light_id);
    if (!light || !obs.uv.allFinite() || !std::isfinite(obs.sigma_px) || !(obs.sigma_px > 0.0)) {
      ++*n_skipped;
      continue;
    }
    const Eigen::Matrix2d covariance =
        Eigen::Matrix2d::Identity() * Factor(options.mono_variance_factor, obs.light_id) *
        (obs.sigma_px * obs.sigma_px + options.correlated_pixel_variance);
    auto factor = std::make_unique<MonoReprojectionFactor>(obs.uv, covariance, rig.mono->intrinsics,
                                                           rig.mono->T_B_C, light->p_D);
    // A light behind the camera at the current estimate cannot be evaluated there (the factor
    // returns false, and Ceres fails the whole solve at its initial point): the observation
    // contradicts the prediction and is skipped, as a gate would.
    if (!(factor->DepthInCamera(mono_pose) > MonoReprojectionFactor::kMinDepth)) {
      ++*n_skipped;
      continue;
    }
    const ceres::ResidualBlockId id = AddOnState<MonoReprojectionFactor, kMonoResidualSize>(
        problem, std::move(factor), *mono_shift, WeightedHuber(options.huber_sigmas, weights.mono),
        state);
    added.push_back({id, true, obs.light_id, weights.mono, frame.t_ns + frame.mono_dt_ns,
                     rig.mono->name, std::sqrt(covariance(0, 0))});
  }
  // The body pose the stereo covariances are evaluated at, once per frame.
  std::optional<Pose3> T_B_D_predicted;
  if (n_stereo > 0 && options.stereo_covariance_at_prediction && rig.stereo_right != nullptr) {
    T_B_D_predicted = PoseFromBlock(stereo_pose).Inverse();
  }
  for (int i = 0; i < n_stereo; ++i) {
    const StereoLightObservation& obs = frame.stereo[i];
    const DockLight* light = rig.dock->FindLight(obs.light_id);
    if (!light || !obs.p_S.allFinite() || !obs.covariance.allFinite() ||
        Eigen::LLT<Eigen::Matrix3d>(obs.covariance).info() != Eigen::Success) {
      ++*n_skipped;
      continue;
    }
    // The triangulation covariance is J (sigma^2 I) J^T: a covariance computed at one pixel
    // sigma scales to another, and adding a variance to every pixel coordinate of the pair
    // scales it too. The observation's is at its own sigma, the predicted one at the camera's.
    const double camera_sigma = rig.stereo_left->pixel_noise_px;
    const double sigma = obs.sigma_px > 0.0 ? obs.sigma_px : camera_sigma;
    Eigen::Matrix3d covariance = obs.covariance;
    double at_sigma = sigma;
    if (T_B_D_predicted) {
      if (const auto predicted = PredictedStereoCovariance(rig, *T_B_D_predicted, light->p_D)) {
        covariance = *predicted;
        at_sigma = camera_sigma;
      }
    }
    const double pixel_scale =
        at_sigma > 0.0 ? (sigma * sigma + options.correlated_pixel_variance) / (at_sigma * at_sigma)
                       : 1.0;
    const double scale = Factor(options.stereo_variance_factor, obs.light_id) * pixel_scale;
    const ceres::ResidualBlockId id = AddOnState<StereoPointFactor, kStereoPointResidualSize>(
        problem,
        std::make_unique<StereoPointFactor>(obs.p_S, scale * covariance, rig.stereo_left->T_B_C,
                                            light->p_D),
        *stereo_shift, WeightedHuber(options.huber_sigmas, weights.stereo), state);
    added.push_back({id, false, obs.light_id, weights.stereo, frame.t_ns + frame.stereo_dt_ns,
                     rig.stereo_left->name,
                     std::sqrt(scale) * at_sigma});
  }
  return added;
}

int GateVisionResiduals(ceres::Problem* problem, double mono_gate_chi2, double stereo_gate_chi2,
                        std::vector<VisionResidual>* residuals,
                        std::vector<Rejection>* rejections) {
  int gated = 0;
  std::vector<VisionResidual> kept;
  for (const VisionResidual& residual : *residuals) {
    double cost = 0.0;
    // Without the loss and its stage weight, 2 cost is the squared Mahalanobis distance.
    problem->EvaluateResidualBlock(residual.id, /*apply_loss_function=*/false, &cost, nullptr,
                                   nullptr);
    const double gate = residual.mono ? mono_gate_chi2 : stereo_gate_chi2;
    if (gate > 0.0 && 2.0 * cost > gate) {
      problem->RemoveResidualBlock(residual.id);
      ++gated;
      if (rejections) {
        rejections->push_back({residual.t_ns, residual.sensor, 2.0 * cost,
                               std::string("light ") + std::to_string(residual.light_id) +
                                   (residual.mono ? ": beyond the mono gate"
                                                  : ": beyond the stereo gate")});
      }
    } else {
      kept.push_back(residual);
    }
  }
  *residuals = std::move(kept);
  return gated;
}

}  // namespace auvdock
