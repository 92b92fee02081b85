// The estimator's front door to the vision layer: turns one frame of the per-frame pipeline
// (PaperBaselinePipeline: detections identified against the dock model) into the estimator's
// VisionFrame.
//
//   mono:   every identified detection of the mono camera, with the camera's pixel noise or the
//           detection's own centroid covariance (sqrt(trace / 2)) when that is larger;
//   stereo: every light identified in both stereo images, triangulated (TriangulateLinear,
//           seed 000 eqs. 11-16) in S = the stereo-left camera frame, with the covariance of
//           the pair's pixel sigma propagated through the triangulation (depth is the weak
//           direction): the camera's pixel noise, or the larger of the two detections' own
//           centroid sigmas when that is larger (a saturated or smeared light in either image);
//   T_D_B_initial: the pipeline's fused per-frame pose, when it has one.
// A light identified twice in one image (which the matchers do not produce) is dropped.
#pragma once

#include "auvdock/estimator/vision_frame.h"
#include "auvdock/vision/paper_baseline_pipeline.h"

namespace auvdock {

// left/right/mono may be null (camera absent).
VisionFrame MakeVisionFrame(const BaselineFrame& frame, const CameraCalibration* left,
                            const CameraCalibration* right, const CameraCalibration* mono);

}  // namespace auvdock
