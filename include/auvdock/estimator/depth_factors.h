// Adds pressure-depth samples to a Ceres problem and gates them: shared by the sliding window and
// the batch smoother, as vision_factors.h is for the lights.
//
// A sample at time t attaches to the latest state at or before t (t_k): at t = t_k as a
// DepthFactor (factors/depth_factor.h) on the state's pose; later, through the IMU's motion over
// t - t_k (TimeShiftedFactor on the pose and the velocity), so every sample is used at its own
// time whatever the sensor's rate and clock. No robust loss: a residual beyond the chi-square
// gate (1 dof) after a solve is removed instead, and counted.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include <ceres/problem.h>

#include "auvdock/estimator/vision_factors.h"
#include "auvdock/geometry/dock_model.h"
#include "auvdock/io/calibration.h"
#include "auvdock/io/measurements.h"

namespace auvdock {

// The sample's residual on `state` (whose time is t_state_ns <= sample.t_ns); nothing when the
// sample is not finite or the IMU does not reach its time.
std::optional<ceres::ResidualBlockId> AddDepthFactor(ceres::Problem* problem,
                                                     const DepthMeasurement& sample,
                                                     const DepthCalibration& calibration,
                                                     const DockModel& dock,
                                                     const VisionState& state, int64_t t_state_ns);

// Removes the residuals whose squared whitened value exceeds gate_chi2 (0 = no gate) from the
// problem and from *residuals; returns how many.
int GateDepthResiduals(ceres::Problem* problem, double gate_chi2,
                       std::vector<ceres::ResidualBlockId>* residuals);

}  // namespace auvdock
