// Sliding-window factor-graph estimator (fixed-lag smoother) of the vehicle's pose in the dock
// frame, on Ceres: the heart of auvdock.
//
// States live at camera frames (on a log without cameras, at a steady rate: estimator/
// state_times.h): x_k = (T_D_B, v_D, b_g, b_a) (layout in factors/pose_manifold.h), and, when
// estimated, the DVL's bias b_S (estimate_dvl_bias, on by default) and the depth sensor's offset.
// The cost over the window of the last N states is
//   |r_prior|^2                                      marginalization prior (or the initial priors)
// + sum_k |r_imu(x_k, x_k+1)|^2                      IMU preintegration between consecutive states
// + sum_k sum_lights w_mono(k)   rho(|r_mono|^2)     mono reprojection of identified dock lights
// + sum_k sum_lights w_stereo(k) rho(|r_stereo|^2)   triangulated lights against the dock model
// + sum_depth |r_depth|^2                            pressure depth against the dock's depth
//   (+ sum_k |r_offset(b_k, b_k+1)|^2                 its offset's random walk, when estimated)
// + sum_dvl |r_dvl|^2                                DVL velocity over ground, in its frame
//   (+ sum_k |r_walk(b_S,k, b_S,k+1)|^2                with its bias b_S, a random walk)
// + USBL fixes, SBL ranges, AHRS/compass headings      (estimator/sensor_factors.h)
// where every r is whitened by its own noise model (pixel noise, triangulation covariance,
// preintegrated IMU covariance), rho is a Huber loss, and w are the stage weights
// (estimator/stage_weighting.h: by default pure information weighting, w = 1). This is the
// source paper's stage-weighted mono/stereo fusion done inside one problem, not as an average
// of two poses after the fact.
//
// Each new frame: preintegrate the IMU since the previous state, predict the new state, add the
// factors, solve (Levenberg-Marquardt, iteration and time budget), gate vision residuals whose
// Mahalanobis distance exceeds the chi-square gate and re-solve without them (to convergence
// within the iteration budget: the outliers' pull can be long to undo), then marginalize
// the oldest state into the prior when the window is full (estimator/marginalization.h), and
// report the newest pose's marginal covariance (estimator/marginal_covariance.h).
// Without vision the window carries on on the IMU alone; the covariance grows accordingly.
// Depth and DVL samples (AddDepth, AddDvl) join the state at or before their time
// (estimator/sensor_factors.h).
//
// The IMU factors carry the Earth's rotation when the dock gives its latitude
// (geometry/dock_model.h EarthRate_D). A start the user gives (SetStartState: an INS's output)
// comes before the two starts below. A window that refuses most of the agreeing acoustic fixes
// with no light in use is reset and restarted from them (divergence_fixes).
// Initialisation: at the first frame with a per-frame pose (VisionFrame::T_D_B_initial): that
// pose, zero velocity and zero biases, each with a prior (EstimatorOptions), unless the pose's
// tilt disagrees with the accelerometer (init_max_tilt_error_rad). The attitude then refines
// against gravity through the IMU factors (gravity_D is the dock's, not a constant).
// Without lights (far from the dock): the acoustic start (estimator/acoustic_initializer.h), at
// the first frame after a fix with which the fixes, the DVL's path and the IMU give a state (its
// pose, velocity and their covariance as the priors); the window then runs on the acoustic, DVL,
// depth and IMU factors, and the lights join it when they appear.
// Reset: an IMU gap longer than max_imu_gap_s, or a failed solve, drops the window and waits
// for the next per-frame pose; every reset is counted and logged, an IMU outage once however
// many frames it lasts (the window restarts at each of them without a count).
//
// Causality: a frame's output uses only the IMU samples up to its timestamp (the last sample is
// held to the frame time) and frames up to it.
//
// Frames and units: D dock (z down), B body = IMU, S stereo-left camera, C mono camera; metres,
// radians, seconds; time stamps in ns. Covariances are in the PoseManifold tangent space
// [dp_D (3), dtheta_D (3)].
#pragma once

#include <cstdint>
#include <deque>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "auvdock/estimator/acoustic_initializer.h"
#include "auvdock/estimator/imu_buffer.h"
#include "auvdock/estimator/stage_weighting.h"
#include "auvdock/estimator/adaptive_noise_scale.h"
#include "auvdock/estimator/usbl_rate_test.h"
#include "auvdock/estimator/dvl_rate_test.h"
#include "auvdock/estimator/rejection.h"
#include "auvdock/estimator/second_difference.h"
#include "auvdock/estimator/sensor_factors.h"
#include "auvdock/estimator/vision_error_statistics.h"
#include "auvdock/estimator/vision_factors.h"
#include "auvdock/estimator/vision_frame.h"
#include "auvdock/geometry/dock_model.h"
#include "auvdock/geometry/pose3.h"
#include "auvdock/imu/imu_preintegration.h"
#include "auvdock/io/calibration.h"
#include "auvdock/io/measurements.h"

namespace ceres {
class Problem;
}

namespace auvdock {

class PoseManifold;

using Matrix6d = Eigen::Matrix<double, 6, 6>;

struct EstimatorOptions {
  int window_size = 10;                  // states in the window (>= 2)
  int max_solver_iterations = 10;        // per solve
  double max_solver_time_s = 0.0;        // per solve; 0 = no time limit (deterministic)
  // A solve stops once a successful step lowers the cost (1/2 chi^2) by less than this, an
  // absolute amount. Its warm start (the IMU's prediction for the newest state, the last
  // solution for the others) is close: Ceres' relative tolerance (1e-6 of a cost of ~25) took 6
  // steps a frame on the default run, the last ones moving the estimate by a hundredth of its
  // standard deviation (most of those steps were spent shrinking the damping: see
  // solver_initial_damping). A step that lowers the cost by d moves the estimate
  // by a Mahalanobis length of about sqrt(2 d): 0.14 sigma at 0.01. 0: the solver's relative
  // tolerance (1e-6 of the cost) alone.
  double solver_cost_tolerance = 0.01;
  // Solve the window's chain (IMU factors between neighbours, every other factor on one state)
  // with its own block-tridiagonal Levenberg-Marquardt (chain_solver.h) instead of Ceres'
  // sparse Cholesky; Ceres solves whatever is not such a chain. The same minimum, faster (see
  // chain_solver.h). false: Ceres always (for comparison).
  bool chain_solver = true;
  // The chain solver's first Levenberg-Marquardt damping lambda of each solve (chain_solver.h;
  // relative to the information's diagonal), Ceres' own start (its trust region's radius 1e4):
  // the chain solver then takes Ceres' steps and gives its estimates. Most of a solve's steps
  // shrink lambda at ~0.1 of cost each until the Gauss-Newton step moves along the weakly
  // observed directions (the biases early in a run; the height with one light in view and no
  // depth sensor). A smaller start (1e-8) converges in 2 steps instead of 6 and is as accurate
  // wherever the depth sensor or the DVL observes those directions, but with vision and IMU
  // alone the converged window drifts further along them (the damping had held them at the
  // IMU's prediction): measured in the README ("Speed"). 1e-8 since 2026-12-07: that hold is
  // the damping acting as a prior that no factor states, and the marginalisation then keeps the
  // unconverged window as if it were the minimum. On a real AUV's IMU, DVL and fixes (A-KIT,
  // README "Real navigation sensors"), where the DVL's slowly varying bias is such a weakly
  // observed direction, the window at 1e-4 stopped short along it frame after frame and diverged
  // (16 m off, 156 of 396 fixes refused); at 1e-8, or at 1e-4 solved to convergence, 0.45 m.
  double solver_initial_damping = 1e-8;
  VisionFactorOptions vision;           // mono/stereo on/off, Huber threshold, stage weights
  // Chi-square gates on the squared Mahalanobis distance of each vision residual after the
  // solve (p = 0.999: 13.82 for a pixel pair, 16.27 for a 3-D point); 0 = no gating.
  double mono_gate_chi2 = 13.82;
  double stereo_gate_chi2 = 16.27;
  double max_imu_gap_s = 0.1;            // a longer gap between IMU samples resets the window
  // Initial priors (1-sigma).
  double init_position_sigma_m = 0.5;
  double init_attitude_sigma_rad = 0.2;
  double init_velocity_sigma_mps = 0.5;
  double init_gyro_bias_sigma = 0.01;   // rad/s
  double init_accel_bias_sigma = 0.1;   // m/s^2
  // A first pose whose tilt disagrees with the accelerometer is refused: the mean specific
  // force f_B over the last init_tilt_window_s before the frame must lie within
  // init_max_tilt_error_rad of the direction the pose predicts for a vehicle that does not
  // accelerate, -R_DB^T g_D (a docking vehicle's accelerations, well under 1 m/s^2, and the
  // accelerometer's bias tilt it by a few degrees at most). A wrongly identified frame can give a
  // pose turned upside down about the docking axis; started from it, the window took seconds to
  // recover (Monte-Carlo audit, README). 0: no check.
  double init_max_tilt_error_rad = 0.26;  // 15 degrees
  double init_tilt_window_s = 0.5;
  bool compute_covariance = true;       // marginal covariance of the newest pose every frame
  // Online variance factors of each light's mono pixels and stereo points, from each frame's
  // residuals after the solve and their leverage on the newest pose (adaptive_noise_scale.h;
  // needs compute_covariance): larger-than-configured centroid errors widen that light's
  // covariance, better ones narrow it, within the bounds. On white synthetic errors at the
  // configured sigma the factors stay within ~0.85-1.12. Off by default: on our renders they
  // settle at the white part of the errors (~0.4 mono, the 0.25 bound stereo), and the window,
  // which does not model the slowly varying part, then becomes overconfident (default scenario
  // NEES 8.4 instead of 5.7; README, "Real water and any dock").
  AdaptiveNoiseOptions adaptive_vision_noise = AdaptiveNoiseOptions{/*enabled=*/false};
  // Online variance factor of the DVL (the same mechanism, adaptive_noise_scale.h), from the
  // rate-of-change test's innovations (dvl_rate_test.h): the difference of two samples against
  // the IMU's velocity change, whose statistic has the expectation 3 when the configured sigma
  // is right, and which does not depend on the state's estimate (so no leverage: redundancy 3).
  // A statistic above innovation_outlier_gates x the test's gate is an outlier (a spike) and
  // left out, AdaptiveNoiseScale::UpdateCensored; one between the gate and that still counts,
  // so a DVL much noisier than configured, whose samples first mostly fail the test, raises the
  // factor until they pass. The factor sets the rate test's and the DVL factor's variance (and
  // so the gate's). Needs dvl_rate_test.
  // Never below 1 (kStateFreeNoiseOptions): a difference of consecutive samples sees only the
  // part of the error that changes between them, so it can show that a sensor is noisier than
  // configured but not that it is better. A real DVL's error is correlated over seconds
  // (docs/real_navigation_sensors.md): its rate-test innovations said 0.5x the datasheet's
  // sigma, and the window that believed it was overconfident (NEES 11-14 on the A-KIT data).
  AdaptiveNoiseOptions adaptive_dvl_noise = kStateFreeNoiseOptions;
  // The same for the pressure depth, from the second difference of consecutive samples
  // (second_difference.h: state-free, chi-square 1 dof), censored at innovation_outlier_gates x
  // depth_gate_chi2. Time constant 100 samples (10 s at 10 Hz): one dof per sample.
  AdaptiveNoiseOptions adaptive_depth_noise = AdaptiveNoiseOptions{true, 100.0, 1.0};  // never below 1, as the DVL's
  SecondDifferenceOptions depth_innovation;  // a docking AUV's vertical acceleration: 0.1 m/s^2
  // The cutoff of those state-free statistics, in gates: above it a statistic is an outlier,
  // left out of the factor. Clipped at the gate instead, 2 % SBL multipath (0.5-1 m) gave a
  // factor of 1.3-2.5 on ranges as configured; censored at the gate itself, a DVL 3x noisier
  // than configured took most of a run to be found (61 % of its statistics above the gate
  // while the factor is 1). At 4 gates (43 for 1 dof, 65 for 3) a multipath range or a DVL
  // spike is far beyond, and 3x noise mostly below. A second difference's outlier also takes
  // the statistics beside it out (second_difference.h): they share the bad sample.
  double innovation_outlier_gates = 4.0;
  // Batch smoother only (estimator/batch_smoother.h): the slowly varying part of the detection
  // errors, per pixel coordinate (1-sigma, px) and its correlation time (s); either 0 = white
  // errors only. The sliding window ignores them. README, "Vision noise".
  double smoother_vision_floor_px = 0.10;
  double smoother_vision_correlation_time_s = 5.0;
  // The same model for the sliding window, whose marginalisation prior carries the past frames'
  // information as the smoother's batch does: N_c s^2 added to every pixel coordinate's variance,
  // N_c from the interval since the previous frame (0.05 px, 1 s at 10 Hz: N_c = 20,
  // +0.05 px^2). Without it, centroids biased by a light's asymmetric lobe (randomised renders)
  // give a mean NEES of 11-12; with it 8.4, and 4.8 on our plain renders (0.07 px until
  // 2026-12-06: 7.7 and 4.2, and the Monte-Carlo audit's runs mostly below their NEES band;
  // README, "Replaying detections; the Monte-Carlo audit"). 0 = white errors only.
  double window_vision_floor_px = 0.05;
  double window_vision_correlation_time_s = 1.0;
  // The floor follows the data (vision_error_statistics.h, SlowVisionError): once enough
  // consecutive residual pairs are seen, the floor in use is the larger of
  // window_vision_floor_px and the slow error they show (the lag-1 autocovariance of what of
  // each state's residuals no pose change explains, corrected for the share the fit takes), at
  // most max_window_vision_floor_px. What another sensor pulls the pose to (an unmodelled depth
  // offset) moves the lights as a pose change does and does not raise it. The configured floor
  // is the least the window allows, not a figure to be right about: replayed detections of the
  // default scenario whose lights carry view-dependent biases of 0.15-0.3 px gave a mean NEES of
  // 9.1-15.8 at the fixed 0.05 px, 4.0-5.7 with the floor following (docs/light_detectors.md).
  // Once the floor is raised, its correlation time may follow too: from the decay of the lag
  // products between consecutive frames and frames 9 apart, at least the configured one and at
  // most max_window_vision_correlation_time_s (by default the configured 1 s: off). Constant
  // per-light offsets (a dock whose lights are not where its file says) do not decay; there it
  // helps (synthetic, vision only: NEES 9.5 -> 5.7
  // at 10 s) but it cost accuracy where the offsets turn with the view (biases of 0.3-0.6 px:
  // 15.6 -> 18.2 mm before the projection), so it is the user's choice; summary.json shows the
  // floor and the time in use.
  SlowVisionErrorOptions adaptive_vision_floor;
  double max_window_vision_floor_px = 0.5;
  double max_window_vision_correlation_time_s = 1.0;
  // Pressure depth (estimator/sensor_factors.h; needs the calibration's depth sensor): each sample
  // against the dock's origin_depth_m, at its own time; a whitened residual beyond the gate
  // (chi-square, 1 dof, p = 0.999) after the solve is removed.
  bool use_depth = true;
  double depth_gate_chi2 = 10.83;
  // The depth sensor's offset against the dock survey's depth (the tide since the survey, the
  // air pressure, the water's density, a sensor bias) as a state: one number per window state,
  // a random walk of depth_offset_random_walk (m/sqrt(s)) between neighbours, a prior of
  // depth_offset_prior_sigma_m about 0 at the window's start (factors/depth_offset_factor.h).
  // The lights and the acoustic fixes then observe the offset, and the depth gives the height
  // relative to what they saw. Off: the depth is taken as the survey's zero. Off by default:
  // with a zero that is the survey's, the free offset costs the height its anchor (a looser
  // height until the lights have measured it; the lights' own biases then reach the height, and
  // a run that starts from a wrong pose can run away along it). On for a sensor whose zero is
  // not the survey's: an offset of 0.3 m taken at its word made the default scenario's NEES 557
  // with unsafe GO. Measured in the README ("Depth and DVL"). `run` and `smooth` warn when the
  // depth gate rejects most samples (EstimatorStats::depth_gated), the sign of such an offset.
  bool estimate_depth_offset = false;
  double depth_offset_prior_sigma_m = 0.5;
  double depth_offset_random_walk = 0.001;
  // DVL velocity over ground (the same, needs the calibration's DVL): 3 dof, p = 0.999. A sample
  // that is not finite is bottom lock lost: no measurement, counted apart.
  bool use_dvl = true;
  double dvl_gate_chi2 = 16.27;
  // The DVL's slowly varying error as a state (factors/dvl_factor.h): a bias b_S (m/s, in the
  // DVL's frame) per window state, a random walk of dvl_bias_random_walk (m/s/sqrt(s), per axis)
  // between neighbours, a prior of dvl_bias_prior_sigma_mps about 0 at the window's start.
  // Why: a real DVL's bottom-track velocity is off by more than its white noise for tens of
  // seconds at a time: its scale (0.2-0.5 % of the speed), a mounting misalignment (0.5 deg is
  // 1.7 cm/s across track at 2 m/s), the seabed. Taken as white noise, averaged by the IMU between
  // samples, it made the window 10x overconfident on a real AUV (A-KIT: docs/
  // real_navigation_sensors.md). The prior (2 cm/s: 1 % of 2 m/s) is the datasheet's long-term
  // accuracy (RDI Workhorse: 0.2-0.4 % +- 1-2 mm/s) with a margin. The walk (3 mm/s/sqrt(s): 3 cm/s
  // over 100 s) is what the A-KIT logs show against their reference, whose position wanders from
  // its own velocity's integral by 0.4-0.6 m over tens of seconds: 1 mm/s/sqrt(s), the datasheet's
  // figure, left `run` overconfident there (mean NEES 9-35), 3 mm/s/sqrt(s) gave 4-14. A DVL over a
  // flat seabed against a better reference may need less: measure yours (docs/user_guide.md 6.3).
  // The acoustic fixes and the lights observe b_S; without them its sigma grows and so does the
  // position's. Off: the DVL's errors are white.
  bool estimate_dvl_bias = true;
  double dvl_bias_prior_sigma_mps = 0.02;
  double dvl_bias_random_walk = 0.003;
  // Acoustic (USBL) fixes of the transponder (the same, needs the calibration's acoustic
  // sensor): 3 dof, p = 0.999, with each fix's own sigma.
  bool use_usbl = true;
  double usbl_gate_chi2 = 16.27;
  UsblRateTestOptions usbl_rate_test;  // seed 001's rate-of-change test (usbl_rate_test.h)
  // A fix arrives late (AcousticFix::latency_ns); one whose time has already left the window by
  // up to this much attaches to the oldest state through the IMU shifted backward
  // (factors/time_shifted_factor.h); an older one is rejected ("no state"). A fix from before
  // the estimator's first state (measured before it initialised, or before a reset) is rejected
  // too: shifted back from a fresh state, whose velocity only its loose prior holds, it would be
  // absorbed by the velocity and pass its gate however wrong it is (an outlier fix measured
  // before initialisation and arriving after it caused 5 of the 7 Monte-Carlo runs with unsafe
  // GO, README).
  double usbl_max_backward_shift_s = 1.0;
  // Divergence: when the gate refuses at least divergence_gated_share of the last
  // divergence_fixes acoustic fixes (each of which passed the rate test, so the fixes agree with
  // each other), and no light was used over the same span, it is the state that is wrong, not
  // the fixes: the window is reset (logged, counted in EstimatorStats::divergences) and starts
  // again from the fixes and the DVL's path (the acoustic start), NO-GO meanwhile (no estimate).
  // With lights in use, the lights are believed and the fixes stay refused (a beacon that is not
  // where the dock file says). Without it, a window that started from a wrong heading or a wrong
  // given start refused every later fix ("0 of 394 fixes used"). 0 fixes: off.
  int divergence_fixes = 10;
  double divergence_gated_share = 0.8;
  // Short-baseline ranges (the same, needs the calibration's sbl array and the dock's beacon):
  // each range on its own, 1 dof, p = 0.999, with its own sigma.
  bool use_sbl = true;
  double sbl_gate_chi2 = 10.83;
  // Heading samples of an AHRS or compass (the same, needs the calibration's heading sensor and
  // the dock's heading_rad): 1 dof, p = 0.999.
  bool use_heading = true;
  double heading_gate_chi2 = 10.83;
  // The Huber threshold (whitened norm) of the depth, DVL, USBL and SBL residuals: their gates
  // act after the solve, and without a bounded influence one absurd sample (a depth of 1e9 m)
  // drags the whole window in that solve, every light out of its gate with it. Wider than the
  // lights' (2.5): a window that started wrong is pulled back by these sensors, and a tight
  // loss slows that down (README, "The fault matrix"). 1e9: in effect no loss.
  double sensor_huber_sigmas = 10.0;
  // The rate-of-change test per transducer (usbl_rate_test.h, with usbl_rate_test's speed and
  // gate): a multipath reply that lengthens a range faster than the vehicle moves.
  bool sbl_rate_test = true;
  // The SBL ranges' variance factor (one for the array; the same mechanism), from each
  // transducer's second difference of its ranges that passed the rate test (second_difference.h,
  // sbl_range_innovation: accel_sigma 0.03 m/s^2 for the slant range's own curvature, 0.01-0.02 m
  // of second difference over 0.5 s on the default approach against 0.05 m of noise), censored
  // at innovation_outlier_gates x sbl_gate_chi2. It scales every range's sigma, in the factor and
  // so in the gate. Time constant 100 statistics (about 15 s at 2 pings a second and 4
  // transducers).
  AdaptiveNoiseOptions adaptive_sbl_noise = AdaptiveNoiseOptions{true, 100.0, 1.0};  // never below 1, as the DVL's
  SecondDifferenceOptions sbl_range_innovation = SecondDifferenceOptions{0.03, 2.5};
  // Multiplies the calibration's IMU noise densities and random walks (sigma, not variance).
  // Datasheet values are measured on a bench, at constant temperature, without vibration; on a
  // vehicle the effective noise is larger (a real EuRoC sequence gives a chi-square about 100x
  // its dof with the ADIS16448's datasheet values, i.e. 10x in sigma). Common practice (Kalibr,
  // VINS-Fusion, OpenVINS configurations) inflates them 2-10x; measure it with the NEES of a
  // run against ground truth, or the adaptive noise factors, and set it here.
  double imu_noise_scale = 1.0;
  // Seed 001's rate-of-change test on each DVL sample before it joins (estimator/dvl_rate_test.h).
  DvlRateTestOptions dvl_rate_test;
  // The DVL's admission after a start or a reset. The rate test compares samples with each
  // other, so a bias present from the start (or the start of its reference) is never seen as a
  // jump: it is admitted, and the window then follows it. At ranges of metres the lights do not
  // object: a lateral drift and a yaw drift (absorbed by the loosely known gyro bias) look alike
  // to a camera for seconds (sensor_faults.yaml, 40 seeds from detections: 3 runs off by
  // 0.4-2 m, 59 unsafe GO). So until one DVL sample has been admitted, each is tested before it
  // joins against the window's own velocity without it: whitened innovation r with covariance
  // S = I + J P J^T (J the factor's Jacobian on the newest state's pose and velocity, P their
  // marginal after the last solve), statistic r^T S^-1 r against dvl_gate_chi2. A sample is only
  // tested once the test can see a bias of dvl_admission_bias_mps along any axis
  // (lambda_max(S) <= (bias / sigma)^2 / gate); until then it is left out, with that reason.
  // The first sample that passes admits the DVL (the rate test and the gate then take over);
  // one that fails is rejected. An acoustic start admits it at once (the fit checked the DVL's
  // path against the fixes). Needs compute_covariance and the DVL gate (without either the DVL
  // is admitted at once). A DVL that the window never learns to test (no lights and no acoustic
  // start) stays out, every sample with that reason in rejections.csv.
  bool dvl_admission = true;
  double dvl_admission_bias_mps = 0.2;  // seed 003's gross-error level
  // The start without lights from acoustic fixes, the DVL and the IMU (acoustic_initializer.h;
  // needs use_usbl, use_dvl and both sensors). A frame with a per-frame pose starts the window
  // first when it comes first.
  AcousticInitOptions acoustic_init;
};

// Whether the states carry the depth sensor's offset (estimate_depth_offset, with the depth in
// use and a depth sensor in the calibration): the window and the batch smoother alike.
inline bool EstimatesDepthOffset(const EstimatorOptions& options, const Calibration& calibration) {
  return options.estimate_depth_offset && options.use_depth && calibration.depth.has_value();
}

// Whether the states carry the DVL's bias (estimate_dvl_bias, with the DVL in use and one in the
// calibration): the window and the batch smoother alike.
inline bool EstimatesDvlBias(const EstimatorOptions& options, const Calibration& calibration) {
  return options.estimate_dvl_bias && options.use_dvl && calibration.dvl.has_value();
}

// The estimate at one state.
struct EstimatorOutput {
  int64_t t_ns = 0;
  Pose3 T_D_B;
  Eigen::Vector3d v_D = Eigen::Vector3d::Zero();
  ImuBias bias;
  // The depth sensor's estimated offset and its 1-sigma (m; NaN when not estimated, or the sigma
  // when the covariance was not computed): EstimatorOptions::estimate_depth_offset.
  double depth_offset_m = std::numeric_limits<double>::quiet_NaN();
  double depth_offset_sigma_m = std::numeric_limits<double>::quiet_NaN();
  bool covariance_ok = false;                   // false: rank-deficient or not computed
  Matrix6d covariance = Matrix6d::Zero();       // tangent [dp_D, dtheta_D]
  int n_mono = 0, n_stereo = 0;                 // vision residuals used in this frame
  int n_gated = 0;                              // vision residuals rejected in this frame
  // Depth samples attached with this frame and how many of them the depth gate rejected.
  int n_depth = 0, n_depth_gated = 0;
  double seconds_since_vision = -1.0;           // age of the newest used vision (-1: never)
  double seconds_since_dvl = -1.0;              // of the newest used DVL sample (-1: never)
  // The window started from a pose chosen among a symmetric dock's rival poses by nothing
  // (VisionFrame::symmetry_unresolved), and the track has followed that choice since: the pose
  // may be any of the rivals (the dock's symmetries applied to it). Until a reset.
  bool symmetry_unresolved = false;
};

// Why a frame produced no estimate, or what it skipped.
struct EstimatorStats {
  int frames = 0;
  int frames_with_output = 0;
  int imu_samples = 0;
  int skipped_imu = 0;          // out of order, repeated, NaN/Inf
  int skipped_frames = 0;       // out of order or repeated timestamps
  int skipped_observations = 0; // NaN/Inf or unknown light ids
  int gated_observations = 0;
  int used_observations = 0;
  int resets = 0;
  int init_refused = 0;  // per-frame poses refused as the first state (tilt against the IMU)
  int acoustic_starts = 0;  // windows started without lights (acoustic_initializer.h)
  int solver_failures = 0;
  int covariance_failures = 0;
  int depth_used = 0;     // depth samples in the cost (after gating)
  int depth_gated = 0;    // beyond the depth gate
  int depth_skipped = 0;  // not finite, above the surface, out of order, no state or IMU
  int dvl_used = 0;       // DVL samples in the cost (after gating)
  int dvl_gated = 0;      // beyond the DVL gate
  int dvl_no_lock = 0;    // not finite: bottom lock lost
  int dvl_skipped = 0;    // out of order, held, before the first state or beyond the IMU
  int dvl_rate_rejected = 0;  // failed the rate-of-change test
  int dvl_not_admitted = 0;  // before admission: untestable yet, or disagreeing (dvl_admission)
  int divergences = 0;    // resets because the gate refused the agreeing fixes (divergence_fixes)
  int usbl_used = 0;      // acoustic fixes in the cost (after gating)
  int usbl_gated = 0;     // beyond the USBL gate
  int usbl_skipped = 0;   // not finite, out of order, no state or IMU
  int usbl_rate_rejected = 0;  // failed the rate-of-change test
  int sbl_used = 0;       // SBL ranges in the cost (after gating)
  int sbl_gated = 0;      // beyond the SBL gate
  int sbl_skipped = 0;    // not finite, unknown transducer, out of order, no state or IMU
  int sbl_rate_rejected = 0;  // failed the rate-of-change test
  int heading_used = 0;     // heading samples in the cost (after gating)
  int heading_gated = 0;    // beyond the heading gate
  int heading_skipped = 0;  // not finite, out of order, no state or IMU
  // The adaptive variance factors in use at the end, per light id.
  std::map<int, double> mono_variance_factor;
  std::map<int, double> stereo_variance_factor;
  double dvl_variance_factor = 1.0;  // adaptive_dvl_noise's factor in use at the end
  double depth_variance_factor = 1.0;  // adaptive_depth_noise's
  double sbl_variance_factor = 1.0;    // adaptive_sbl_noise's
  double window_vision_floor_px = 0.0;  // the slow-error floor in use at the end (px)
  double window_vision_correlation_time_s = 0.0;  // ... and its correlation time (s)
  // The depth sensor's offset at the newest estimate and its 1-sigma (m; NaN when not
  // estimated: EstimatorOptions::estimate_depth_offset).
  double depth_offset_m = std::numeric_limits<double>::quiet_NaN();
  double depth_offset_sigma_m = std::numeric_limits<double>::quiet_NaN();
  std::vector<std::string> log;  // one line per skip/reset, for the caller's log
};

// A state as it left the window (its smoothed, final fixed-lag estimate), for the batch smoother.
struct StateRecord {
  int64_t t_ns = 0;
  double pose[7];
  double velocity[3];
  double bias[6];
  double depth_offset = 0.0;  // m (0 when not estimated)
  double dvl_bias[3] = {0.0, 0.0, 0.0};  // m/s in the DVL's frame (0 when not estimated)
};

class SlidingWindowEstimator {
 public:
  // Needs the calibration's IMU and the cameras with roles stereo_left (for stereo points) and
  // mono (for mono reprojections). Throws std::invalid_argument for bad options.
  SlidingWindowEstimator(const Calibration& calibration, const DockModel& dock,
                         const EstimatorOptions& options = {});
  ~SlidingWindowEstimator();
  SlidingWindowEstimator(const SlidingWindowEstimator&) = delete;
  SlidingWindowEstimator& operator=(const SlidingWindowEstimator&) = delete;

  // IMU samples in time order; a sample out of order, repeated or not finite is skipped.
  void AddImu(const ImuSample& sample);

  // A depth sample, in time order; used with the first frame at or after its time (frames and
  // samples must reach the estimator in time order: the caller feeds the samples up to the
  // frame's last image before the frame).
  void AddDepth(const DepthMeasurement& sample);
  // A DVL sample, the same way.
  void AddDvl(const DvlMeasurement& sample);
  // An acoustic fix, the same way (by its measurement time).
  void AddUsbl(const AcousticFix& fix);
  // A heading sample (AHRS, compass), the same way.
  void AddHeading(const HeadingMeasurement& sample);
  // An SBL range, the same way (by its ping's time).
  void AddSblRange(const SblRange& range);

  // A starting state the user gives (estimator/start_state.h): the window starts from it at the
  // first frame at or after start.t_ns (any frame when 0), carried to the frame's time by the
  // IMU, before a per-frame pose or the acoustic start could. Used once: a reset later restarts
  // as without it. Call before the frames.
  void SetStartState(const InitialState& start) { given_start_ = start; }
  // The given start as the window's first state took it (at that state's time), once applied.
  const std::optional<InitialState>& applied_start() const { return applied_start_; }

  // A camera frame (identified lights; possibly none). Returns the newest state's estimate, or
  // nothing before initialisation / after a reset until the next per-frame pose.
  std::optional<EstimatorOutput> AddVisionFrame(const VisionFrame& frame);

  // The newest estimate propagated with the IMU samples received after it (for the controller,
  // at IMU rate); nothing when not initialised or t_ns is before the newest state.
  std::optional<Pose3> PropagatedPose(int64_t t_ns) const;

  // States that have left the window, oldest first, plus the ones still in it (Flush order).
  std::vector<StateRecord> History() const;

  // The measurements rejected since the previous call (gated, out of order, not finite, without
  // a state at their time), in the order they were rejected; for OUTDIR/rejections.csv.
  std::vector<Rejection> TakeRejections();

  const EstimatorStats& stats() const { return stats_; }
  bool initialized() const { return !window_.empty(); }
  // Why the last frame with a per-frame pose, or the last try of the acoustic start, did not
  // start the window (empty if none did not).
  const std::string& init_refusal() const { return init_refusal_; }

 private:
  struct State;

  bool Initialize(const VisionFrame& frame);
  // The given start (SetStartState) at t_ns, when it is due and the IMU carries it there.
  bool InitializeFromGivenStart(int64_t t_ns);
  // The divergence test (EstimatorOptions::divergence_fixes) after a frame's gating: true when
  // the window was reset for it.
  bool ResetOnDivergence(int kept_fixes, int gated_fixes, int64_t t_ns);
  // The acoustic start at t_ns, tried when a fix came since the last try.
  bool InitializeAcoustically(int64_t t_ns);
  // The window's first state with its priors (the biases' from EstimatorOptions).
  void StartWindow(const InitialState& initial);
  void Reset(const std::string& reason);
  bool AddState(int64_t t_ns);
  // stop_early: stop once a step lowers the cost by less than solver_cost_tolerance. The chain
  // solver when the window is a chain and chain_solver is on, Ceres otherwise.
  bool Solve(bool stop_early = true);
  // One state's parameter blocks: pose, velocity, bias, the DVL's bias and the depth offset when
  // estimated (the depth offset last).
  std::vector<double*> ParameterBlocks(State& state) const;
  // Each window state's blocks (ParameterBlocks), oldest first.
  std::vector<std::vector<double*>> StateBlocksInOrder() const;
  void MarginalizeOldest();
  // The pending depth samples up to t_ns onto the states at or before them; returns the
  // residuals added.
  std::vector<SensorResidual> AttachDepth(int64_t t_ns);
  std::vector<SensorResidual> AttachDvl(int64_t t_ns);
  std::vector<SensorResidual> AttachUsbl(int64_t t_ns);
  std::vector<SensorResidual> AttachSbl(int64_t t_ns);
  std::vector<SensorResidual> AttachHeading(int64_t t_ns);
  // The pending samples up to t_ns, each by add(sample, state) onto StateFor(its time,
  // max_before_s) (the factor, or nothing: then, as without a state, skipped with
  // kNoStateReason).
  template <typename Sample, typename AddFactor>
  std::vector<SensorResidual> AttachPending(std::deque<Sample>* pending, int64_t t_ns,
                                            const std::string& sensor, int* skipped,
                                            const AddFactor& add, double max_before_s = 0.0);
  // The state's blocks for the measurement factors (estimator/state_blocks.h).
  StateBlocks BlocksOf(State& state) const;
  // sqrt(|g|^2 lambda_max(tilt covariance) + lambda_max(accelerometer bias covariance)), m/s^2:
  // the attitude covariance's part about the horizontal axes (dtheta in D) turns g.
  double AccelUncertainty(const Eigen::Matrix3d& attitude_covariance,
                          const Eigen::Matrix3d& accel_bias_covariance) const;
  // Why the frame's per-frame pose may not start the window (init_max_tilt_error_rad), or empty;
  // empty too when fewer than 3 accelerometer samples lie in init_tilt_window_s before it.
  std::string TiltRefusal(const VisionFrame& frame) const;
  // The state a measurement at t_ns attaches to: the newest at or before it, else the oldest
  // when t_ns is at most max_before_s before it (a late measurement) and not before the first
  // state since the last initialisation, else none.
  State* StateFor(int64_t t_ns, double max_before_s = 0.0);
  EstimatorOutput Output(const State& state);
  // The marginal covariance of a state's pose (6 x 6, tangent space): for the newest state the
  // forward sweep over the window's chain (chain_marginals.h), else, or when the problem is not a
  // chain, the general method (marginal_covariance.h). nullopt with the reason when there is none.
  std::optional<Eigen::MatrixXd> PoseCovariance(const State& state, std::string* reason);
  // The newest frame's vision residuals, with their leverage on the newest pose (its covariance
  // in the tangent space), into the adaptive noise factors of their lights.
  // The DVL admission test's statistic (EstimatorOptions::dvl_admission) of a DVL residual
  // block already in the problem; reason says why it cannot be computed or trusted yet.
  double DvlAdmissionStatistic(ceres::ResidualBlockId id, std::string* reason);
  void UpdateNoiseScales(const State& state, const Matrix6d& covariance);
  // The slow-error floor for the next frame's vision residuals (px): window_vision_floor_px,
  // raised to what the residuals show (adaptive_vision_floor).
  double WindowVisionFloorPx() const;
  // Its correlation time (s): window_vision_correlation_time_s, or, once the floor is raised,
  // the one the residuals show, at most max_window_vision_correlation_time_s.
  double WindowVisionCorrelationTimeS() const;

  Calibration calibration_;
  DockModel dock_;
  EstimatorOptions options_;
  VisionRig rig_;
  std::unique_ptr<PoseManifold> pose_manifold_;
  std::unique_ptr<ceres::Problem> problem_;
  std::deque<std::unique_ptr<State>> window_;
  ImuBuffer imu_;
  std::vector<StateRecord> history_;
  std::deque<DepthMeasurement> pending_depth_;
  std::deque<DvlMeasurement> pending_dvl_;
  std::deque<AcousticFix> pending_usbl_;
  std::deque<SblRange> pending_sbl_;
  std::deque<HeadingMeasurement> pending_heading_;
  std::vector<Rejection> rejections_;  // not yet taken
  DvlRateTest dvl_rate_test_;
  AdaptiveNoiseScale dvl_noise_;  // the DVL's variance factor (adaptive_dvl_noise)
  AdaptiveNoiseScale depth_noise_;  // the depth's (adaptive_depth_noise)
  SecondDifference depth_innovation_;
  AdaptiveNoiseScale sbl_noise_;                    // the SBL ranges' (adaptive_sbl_noise)
  SlowVisionError slow_vision_error_;  // the floor's estimate (adaptive_vision_floor)
  std::vector<SecondDifference> sbl_innovations_;  // one per transducer
  UsblRateTest usbl_rate_test_;
  AcousticInitializer acoustic_init_;
  std::vector<UsblRateTest> sbl_rate_tests_;  // one per transducer
  std::map<ceres::ResidualBlockId, int> sbl_transducer_of_;  // the newest frame's SBL residuals
  HeldDvlReadingCheck held_dvl_reading_;
  int64_t last_depth_sample_t_ns_ = INT64_MIN;  // of the newest sample taken
  int64_t last_dvl_sample_t_ns_ = INT64_MIN;
  int64_t last_usbl_sample_t_ns_ = INT64_MIN;
  int64_t last_heading_sample_t_ns_ = INT64_MIN;
  int64_t last_sbl_sample_t_ns_ = INT64_MIN;  // and its transducer: (time, transducer) increase
  int last_sbl_transducer_ = -1;
  int64_t last_frame_t_ns_ = INT64_MIN;
  int64_t first_state_t_ns_ = INT64_MIN;  // since the last initialisation
  int64_t last_vision_t_ns_ = INT64_MIN;
  bool symmetry_unresolved_ = false;  // of the window's first pose (EstimatorOutput)
  std::optional<int64_t> imu_outage_newest_t_ns_;  // the newest IMU sample at the last gap reset
  int64_t last_dvl_t_ns_ = INT64_MIN;
  bool dvl_admitted_ = false;  // since the last start (EstimatorOptions::dvl_admission)
  // The newest state's marginal covariance of [pose tangent, velocity] after the last solve
  // (for the DVL's admission test); empty when not computed.
  std::optional<Eigen::Matrix<double, 9, 9>> newest_pose_velocity_covariance_;
  std::optional<double> newest_depth_offset_variance_;  // with the above
  // The newest state's uncertainty of g in B (tilt) and of the accelerometer bias, as one sigma
  // in m/s^2 (AccelUncertainty): the DVL rate test's prediction leans on both. From the start's
  // priors until the first covariance (with compute_covariance off it keeps the start's value,
  // and the rate test stays as wide as at the start).
  double newest_accel_uncertainty_mps2_ = 0.0;
  // estimate_depth_offset with a depth sensor in use: every state has its offset block.
  bool depth_offset_on_ = false;
  // estimate_dvl_bias with a DVL in use: every state has its DVL-bias block.
  bool dvl_bias_on_ = false;
  // The Earth's rotation in D (EarthRate_D of the dock; zero without its latitude).
  Eigen::Vector3d earth_rate_D_ = Eigen::Vector3d::Zero();
  std::string init_refusal_;
  std::optional<InitialState> given_start_;    // SetStartState, until applied
  // The gate's verdicts on the latest fixes (true: refused), with the time of the frame that
  // gated each (EstimatorOptions::divergence_fixes).
  std::deque<std::pair<int64_t, bool>> recent_fix_gated_;
  std::optional<InitialState> applied_start_;  // as the first state took it
  EstimatorStats stats_;
  // Per light id: the adaptive variance factors of its mono pixels and its stereo points.
  std::map<int, AdaptiveNoiseScale> mono_noise_;
  std::map<int, AdaptiveNoiseScale> stereo_noise_;
};

}  // namespace auvdock
