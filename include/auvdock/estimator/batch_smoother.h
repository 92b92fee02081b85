// Batch smoother for offline trajectory reconstruction: every state of a whole log in one sparse
// Ceres problem (SuiteSparse Cholesky), the same factors as the sliding window
// (estimator/vision_factors.h, IMU preintegration, initial priors) but nothing marginalized, so
// every state sees all the data before and after it.
//
// States are the warm start's (the sliding-window run's StateRecords, one per output frame):
// their times, and their values as the initial guess. Consecutive states are joined by an IMU
// factor when the IMU covers the interval; where it does not (an IMU gap, a reset of the run),
// the trajectory splits into independent segments, each with the initial priors on its first
// state. Vision residuals are gated after a first solve and the problem re-solved without them.
// The marginal covariance of every pose comes from ceres::Covariance (SPARSE_QR, SuiteSparse),
// in the PoseManifold tangent space; a rank-deficient problem reports no covariance rather than
// a wrong one.
#pragma once

#include <functional>
#include <vector>

#include "auvdock/estimator/sliding_window_estimator.h"

namespace auvdock {

struct BatchSmootherOptions {
  int max_iterations = 50;
  // Called after every solver iteration with (iteration, cost); may be empty.
  std::function<void(int, double)> progress;
};

struct BatchResult {
  std::vector<EstimatorOutput> outputs;  // one per warm-start state, in time order
  int segments = 0;
  int iterations = 0;
  double initial_cost = 0.0, final_cost = 0.0;
  bool converged = false;
  EstimatorStats stats;  // skipped / gated / used counts
};

// frames: every vision frame of the log, in time order (frames without a warm-start state are
// ignored); imu: all samples in time order. Throws std::invalid_argument without an IMU
// calibration.
BatchResult SmoothBatch(const Calibration& calibration, const DockModel& dock,
                        const std::vector<VisionFrame>& frames,
                        const std::vector<ImuSample>& imu,
                        const std::vector<StateRecord>& warm_start,
                        const EstimatorOptions& estimator_options,
                        const BatchSmootherOptions& options = {});

}  // namespace auvdock
