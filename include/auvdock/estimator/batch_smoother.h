// Batch smoother for offline trajectory reconstruction: every state of a whole log in one sparse
// Ceres problem, solved as a chain (estimator/chain_solver.h: block-tridiagonal Levenberg-
// Marquardt, Ceres' steps at Ceres' tolerances; Ceres' SuiteSparse Cholesky when the problem is
// not a chain or EstimatorOptions::chain_solver is off), the same factors as the sliding window
// (estimator/vision_factors.h, IMU preintegration, initial priors) but nothing marginalized, so
// every state sees all the data before and after it.
//
// States are the warm start's (the sliding-window run's StateRecords, one per output frame):
// their times, and their values as the initial guess. Consecutive states are joined by an IMU
// factor when the IMU covers the interval; where it does not (an IMU gap, a reset of the run),
// the trajectory splits into independent segments, each with the initial priors on its first
// state. Vision residuals are gated after a first solve and the problem re-solved without them.
// The marginal covariance of every pose comes from the chain's two sweeps over its block-
// tridiagonal information (estimator/chain_marginals.h: linear in the log's length), or from
// ceres::Covariance (SPARSE_QR, SuiteSparse: quadratic) if a factor ever joins states that are
// not neighbours or the sweeps find a segment rank-deficient (they square J's condition number;
// the QR of J decides); in the PoseManifold tangent space. A rank-deficient problem reports no
// covariance rather than a wrong one.
//
// Time-correlated vision errors. The image pipeline's light centres are not white: besides the
// frame-to-frame scatter (which the cameras' pixel_noise_px covers) they carry a slowly varying
// error of ~0.1 px, mostly along the image v axis and common to the lights of one camera (the
// detector's fit of each light's reflection, which the renderer draws below it; README, "Vision
// noise": on the default scenario the per-camera mean v error keeps an autocorrelation of
// 0.78 / 0.57 after 1 s / 4 s in the stereo-left camera). A sliding window fuses about a second
// of frames and stays honest with pixel_noise_px; the smoother fuses every frame of the log as
// if independent, and the slow error, which does not average out over frames, would shrink the
// reported covariance with the number of frames. Model: per pixel coordinate, error = white
// (pixel_noise_px) + a stationary slow part of 1-sigma s (EstimatorOptions::
// smoother_vision_floor_px) with the autocorrelation exp(-|t| / tau) (smoother_vision_
// correlation_time_s), i.e. AR(1) with rho = exp(-dt / tau)
// at the frame interval dt. Over n >> 1 / (1 - rho) frames the mean of that part has the
// variance s^2 N_c / n with N_c = (1 + rho) / (1 - rho) (~2 tau / dt): the frames carry the
// information of n / N_c independent looks, one per ~2 tau. Least squares over frames treated as
// independent reports that variance when each frame's variance includes N_c s^2, so the smoother
// adds N_c s^2 to every pixel coordinate's variance (VisionFactorOptions::
// correlated_pixel_variance; propagated into the stereo points' triangulation covariance): the
// effective sample size n (1 - rho) / (1 + rho) of an AR(1) series, applied to the correlated
// part only. It is a de-weighting inside the problem - the estimate and its covariance both
// follow from it - not a scaling of the reported covariance. Gating uses the same (inflated)
// covariances. The defaults (0.10 px, 5 s) cover a light's bias of 0.1-0.3 px from an asymmetric
// beam, which changes only with the view, within the measured decay of the slow part (4-15 s).
// The residuals cannot tell that bias (most of it goes into the pose: vision_error_statistics.h
// measures what is left, reported as summary.json `vision_errors`), so the figures are set by
// the NEES over seeds of our plain and our randomised renders together: 0.075 px and 2 s gave
// 5.4 and 12.5, 0.14 px and 5 s 3.0 and 7.1, 0.10 px and 5 s 3.4 and 8.5 (README, "Vision
// noise", and "Real water and any dock").
#pragma once

#include <functional>
#include <optional>
#include <vector>

#include "auvdock/estimator/sliding_window_estimator.h"
#include "auvdock/estimator/vision_error_statistics.h"

namespace auvdock {

struct BatchSmootherOptions {
  int max_iterations = 50;
  // The Fisher information of the problem at the warm start instead of a solve: no iteration,
  // no robust loss (every kept measurement with its full configured weight), the gates applied
  // at the warm-start values. With the true states as the warm start, each pose's marginal
  // covariance is its Cramér–Rao bound under the configured noise models (crlb_command.cc): a
  // misidentified light or a sensor fault fails its gate at the truth and is left out, as the
  // estimator would leave it out.
  bool information_at_warm_start = false;
  // Called after every solver iteration with (iteration, cost); may be empty.
  std::function<void(int, double)> progress;
  // A starting state the user gave (estimator/start_state.h), as the window's first state took
  // it (SlidingWindowEstimator::applied_start): the priors of the state at its time, instead of
  // the initial priors about the warm start.
  std::optional<InitialState> start;
};

struct BatchResult {
  std::vector<EstimatorOutput> outputs;  // one per warm-start state, in time order
  int segments = 0;
  int iterations = 0;
  double initial_cost = 0.0, final_cost = 0.0;
  bool converged = false;
  EstimatorStats stats;  // skipped / gated / used counts
  std::vector<Rejection> rejections;  // every measurement left out, in time order
  VisionErrorStatistics vision_errors;  // measured from the final residuals
};

// The navigation sensors' samples of a log, each stream in time order.
struct NavigationSamples {
  std::vector<DepthMeasurement> depth;
  std::vector<DvlMeasurement> dvl;
  // The DVL's variance factor (the window's adaptive estimate, EstimatorStats::
  // dvl_variance_factor): multiplies its configured variance.
  double dvl_variance_factor = 1.0;
  double depth_variance_factor = 1.0;  // the same for the depth
  std::vector<AcousticFix> usbl;        // acoustic fixes (estimator_options.use_usbl)
  std::vector<SblRange> sbl;            // SBL ranges (estimator_options.use_sbl)
  double sbl_variance_factor = 1.0;     // the window's adaptive estimate for the SBL ranges
  std::vector<HeadingMeasurement> heading;  // an AHRS or compass (estimator_options.use_heading)
};

// frames: every vision frame of the log, in time order (frames without a warm-start state are
// ignored); imu: all samples in time order; sensors: the depth and DVL samples (each used with
// its estimator_options.use_* switch and the calibration's sensor, on the state at or before
// it, estimator/sensor_factors.h, and gated with the vision). Throws std::invalid_argument
// without an IMU calibration.
BatchResult SmoothBatch(const Calibration& calibration, const DockModel& dock,
                        const std::vector<VisionFrame>& frames,
                        const std::vector<ImuSample>& imu,
                        const std::vector<StateRecord>& warm_start,
                        const EstimatorOptions& estimator_options,
                        const BatchSmootherOptions& options = {},
                        const NavigationSamples& sensors = {});

}  // namespace auvdock
