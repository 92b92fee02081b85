// Adds one frame's vision residuals to a Ceres problem and gates them: shared by the sliding
// window and the batch smoother, so both optimise exactly the same cost.
//
// Per identified light:
//   mono   MonoReprojectionFactor (2): raw pixel against the projected dock light, whitened by
//          the detection's pixel sigma;
//   stereo StereoPointFactor (3): triangulated p_S against the dock light, whitened by the
//          triangulation covariance at the pair's pixel sigma (StereoLightObservation::
//          sigma_px) -- by default evaluated at the light's position predicted
//          from the pose block's value when the factor is added (the IMU prediction in the
//          sliding window, the warm start in the batch smoother), not at the measured point:
//          the first-order covariance grows as z^4 (depth sigma ~ z^2 / (f b)), so evaluated at
//          the noisy point it gives more weight to the lights whose noise made them come out
//          nearer, which biases the fit towards the cameras and makes the covariance of a pose
//          fitted over many frames too small. On 10 seeded synthetic runs this took the batch
//          smoother's position NEES over the far-range stereo stage from 4.6 to 3.3 (3-dof) and
//          the sliding window's from 3.35 to 2.8. The measured-point covariance is used when the
//          light does not project into both cameras or the option is off.
// correlated_pixel_variance (px^2, default 0) is added to the white variance of every pixel
// coordinate: to sigma_px^2 of a mono pixel, and to the stereo pair's sigma_px^2 in its
// triangulation covariance, which is linear in the (i.i.d.) pixel variance and so is scaled by
// (sigma_px^2 + correlated_pixel_variance) / s^2, s the sigma it was computed at (the pair's, or
// the camera's pixel_noise_px for the predicted one). The batch smoother uses it for the
// time-correlated part of the detection errors (estimator/batch_smoother.h); the sliding window
// leaves it at 0.
// Each gets a Huber loss (threshold huber_sigmas on the whitened norm; none when +infinity)
// scaled by the frame's stage weight for its camera system (estimator/stage_weighting.h): the
// weight multiplies the residual's information, which is the source paper's stage weighting inside the problem.
// Images later than the state (VisionFrame::mono_dt_ns, stereo_dt_ns > 0: cameras not
// synchronised with each other) are attached to the state through the IMU's motion over dt
// (TimeShiftedFactor, factors/time_shifted_factor.h: on the pose and the velocity blocks), so
// the frame keeps one state and its stage ("both" included). Without IMU coverage of
// [t, t + dt] that image's observations are skipped.
// Gating: after a solve, a residual whose squared Mahalanobis distance (without loss or
// weight) exceeds its chi-square gate is removed.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include <ceres/problem.h>

#include "auvdock/estimator/imu_buffer.h"
#include "factors/time_shifted_factor.h"
#include "auvdock/estimator/stage_weighting.h"
#include "auvdock/estimator/rejection.h"
#include "auvdock/estimator/state_blocks.h"
#include "auvdock/estimator/vision_frame.h"
#include "auvdock/geometry/dock_model.h"
#include "auvdock/io/calibration.h"

namespace auvdock {

struct VisionFactorOptions {
  bool use_mono = true;
  bool use_stereo = true;
  double huber_sigmas = 2.5;
  bool stereo_covariance_at_prediction = true;
  StageWeightingOptions stage_weighting;
  double correlated_pixel_variance = 0.0;  // px^2 added per pixel coordinate (see above)
  // Variance factors per light id of the mono pixels and of the stereo points
  // (adaptive_noise_scale.h: the sliding window's online estimate of each light's effective
  // centroid noise in each camera system); a missing id = 1, as configured. They multiply the
  // covariances above.
  std::map<int, double> mono_variance_factor;
  std::map<int, double> stereo_variance_factor;
};

struct VisionResidual {
  ceres::ResidualBlockId id = nullptr;
  bool mono = false;
  int light_id = -1;
  double weight = 1.0;  // the stage weight on its information
  int64_t t_ns = 0;     // the image's time
  std::string sensor;   // the camera's name (the mono camera, or the stereo pair's left)
  // The pixel sigma the residual is whitened with (px, variance factor and correlated variance
  // included): whitened residual x pixel_sigma_px is the error in pixel-equivalent units (the
  // pixel error for mono; for stereo the point error in the units of the pair's pixel noise).
  double pixel_sigma_px = 1.0;
};

// What the factors need to know about the rig and the dock. Any camera may be null (without
// stereo_right the stereo covariance is the measured point's).
struct VisionRig {
  const CameraCalibration* stereo_left = nullptr;
  const CameraCalibration* stereo_right = nullptr;
  const CameraCalibration* mono = nullptr;
  const DockModel* dock = nullptr;
};

// The variance (px^2) added to every pixel coordinate of the vision residuals (the batch smoother's and, when configured, the sliding window's) for a
// slow error of 1-sigma floor_px and correlation time correlation_time_s, at the frame interval
// frame_interval_s: N_c floor_px^2, N_c = (1 + rho) / (1 - rho), rho = exp(-dt / tau). 0 when
// any argument is 0 (or not finite and positive).
double CorrelatedVisionVariance(double floor_px, double correlation_time_s,
                                double frame_interval_s);

// Adds the frame's residuals on the state's blocks (already in the problem). Observations with
// an unknown light id or non-finite values, mono observations of a light behind the camera at
// the current estimate, and observations of an image whose time the IMU does not reach, are
// skipped and counted in *n_skipped.
std::vector<VisionResidual> AddVisionFactors(ceres::Problem* problem, const VisionFrame& frame,
                                             const VisionRig& rig,
                                             const VisionFactorOptions& options,
                                             const StateBlocks& state, int* n_skipped);

// Removes the residuals beyond their gate (0 = no gate) from the problem and from *residuals;
// returns how many, each also appended to *rejections when given.
int GateVisionResiduals(ceres::Problem* problem, double mono_gate_chi2, double stereo_gate_chi2,
                        std::vector<VisionResidual>* residuals,
                        std::vector<Rejection>* rejections = nullptr);

}  // namespace auvdock
