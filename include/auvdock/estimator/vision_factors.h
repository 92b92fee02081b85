// Adds one frame's vision residuals to a Ceres problem and gates them: shared by the sliding
// window and the batch smoother, so both optimise exactly the same cost.
//
// Per identified light:
//   mono   MonoReprojectionFactor (2): raw pixel against the projected dock light, whitened by
//          the detection's pixel sigma;
//   stereo StereoPointFactor (3): triangulated p_S against the dock light, whitened by the
//          triangulation covariance.
// Each gets a Huber loss (threshold huber_sigmas on the whitened norm) scaled by the frame's
// stage weight for its camera system (estimator/stage_weighting.h): the weight multiplies the
// residual's information, which is the source paper's stage weighting inside the problem.
// Gating: after a solve, a residual whose squared Mahalanobis distance (without loss or
// weight) exceeds its chi-square gate is removed.
#pragma once

#include <vector>

#include <ceres/problem.h>

#include "auvdock/estimator/stage_weighting.h"
#include "auvdock/estimator/vision_frame.h"
#include "auvdock/geometry/dock_model.h"
#include "auvdock/io/calibration.h"

namespace auvdock {

struct VisionFactorOptions {
  bool use_mono = true;
  bool use_stereo = true;
  double huber_sigmas = 2.5;
  StageWeightingOptions stage_weighting;
};

struct VisionResidual {
  ceres::ResidualBlockId id = nullptr;
  bool mono = false;
};

// What the factors need to know about the rig and the dock. stereo_left / mono may be null.
struct VisionRig {
  const CameraCalibration* stereo_left = nullptr;
  const CameraCalibration* mono = nullptr;
  const DockModel* dock = nullptr;
};

// Adds the frame's residuals on `pose` (a block already in the problem). Observations with an
// unknown light id or non-finite values are skipped and counted in *n_skipped.
std::vector<VisionResidual> AddVisionFactors(ceres::Problem* problem, const VisionFrame& frame,
                                             const VisionRig& rig,
                                             const VisionFactorOptions& options, double* pose,
                                             int* n_skipped);

// Removes the residuals beyond their gate (0 = no gate) from the problem and from *residuals;
// returns how many.
int GateVisionResiduals(ceres::Problem* problem, double mono_gate_chi2, double stereo_gate_chi2,
                        std::vector<VisionResidual>* residuals);

}  // namespace auvdock
