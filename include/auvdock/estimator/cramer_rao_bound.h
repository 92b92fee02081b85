// The Cramér–Rao bound of every pose of a log: how well any unbiased estimator could know each
// pose from the measurements the log holds, under the configured noise models.
//
// Math. For measurements z = h(x) + n with Gaussian noise n ~ N(0, R), the Fisher information
// of the states x is I(x) = J^T R^-1 J with J = dh/dx at the true states, and every unbiased
// estimator has Cov(x_hat) >= I(x)^-1 (Cramér–Rao). With the initial priors in the problem (a
// Gaussian prior N(x_0, P_0) on the first state of each segment) it is the Bayesian bound
// (van Trees): I = J^T R^-1 J + P_0^-1. The problem is the batch smoother's
// (estimator/batch_smoother.h): the same states (one per vision frame), factors, stage weights
// and noise models (the cameras' pixel_noise_px and the smoother's allowance for time-correlated
// centroid errors, the IMU's densities, depth, DVL and USBL noise), with every measurement at its
// full weight (no robust loss). Its information is evaluated at the truth, interpolated to every
// frame time (pose: linear and slerp; velocity and biases: linear), and each pose's bound is the
// pose block of I^-1 (ceres::Covariance), in the PoseManifold tangent space of covariance.csv
// (io/pose_covariance_csv.h). h is nonlinear: this is the bound of the problem linearised at the
// truth, which a converged estimator attains as the noise goes to zero.
//
// Which measurements count: those of the log, as the estimator would use them. A vision
// measurement's value does not enter J, but its gate does: at the truth, a misidentified light
// or a faulted sensor sample fails its chi-square gate and is left out, as the smoother leaves
// it out; a frame whose lights were not detected or identified adds no vision information.
//
// Units: metres and radians (the covariance), nanoseconds (time).
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "auvdock/estimator/batch_smoother.h"
#include "auvdock/io/pose_covariance_csv.h"

namespace auvdock {

// The true state at t_ns in the blocks' layout (eval/truth_interpolation.h); nothing outside the
// truth's span or between two samples more than max_gap_s apart. `truth` in strictly increasing
// time.
std::optional<StateRecord> TrueStateAt(const std::vector<GroundTruthState>& truth, int64_t t_ns,
                                       double max_gap_s);

struct CramerRaoBound {
  std::vector<StampedPoseCovariance> poses;  // in time order, one per state with a bound
  int frames = 0;                // vision frames given
  int frames_without_truth = 0;  // frames outside the truth or in a truth gap: no state
  int covariance_failures = 0;   // states whose pose block was not computable (rank deficient)
  EstimatorStats stats;          // measurements used, gated and skipped
};

// frames: the log's vision frames in time order (the same the smoother would get); imu, sensors:
// as for SmoothBatch. Throws std::invalid_argument without an IMU calibration or with an empty
// truth.
CramerRaoBound ComputeCramerRaoBound(const Calibration& calibration, const DockModel& dock,
                                     const std::vector<VisionFrame>& frames,
                                     const std::vector<ImuSample>& imu,
                                     const std::vector<GroundTruthState>& truth,
                                     const EstimatorOptions& estimator_options,
                                     const NavigationSamples& sensors = {},
                                     double max_truth_gap_s = 0.1);

}  // namespace auvdock
