// The lights of a camera's frames without a pose, identified from the posed frames beside them
// (FewLightTracker): from every run of at least min_start_poses consecutive posed frames, a walk
// forward in time into the frames after it and, on recorded footage, a walk backward into the
// frames before it, each until the next such run or until the walk ends. A shorter run of posed
// frames is walked through (its own labels stay): a single pose among frames without one is as
// likely a wrong one (a symmetric-looking part of the layout among fittings). A frame reached by
// two walks takes the labels of the one whose posed frames are nearer (fewer frames walked). The
// dock entering the downward camera's view shows 1-3 lights among the deck's fittings for tens of
// frames before a pose of its own is possible; the poses that follow identify them, and what
// they leave far from every light is no light of the dock.
//
// Units and frames: FewLightTracker's.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "auvdock/camera/pinhole_radtan_camera.h"
#include "auvdock/geometry/dock_model.h"
#include "auvdock/geometry/pose3.h"
#include "auvdock/vision/few_light_tracker.h"
#include "auvdock/vision/light_detection.h"

namespace auvdock {

struct BridgedFrame {
  // In: the frame's detections, and its own pose (SolvePnp's covariance) when it has one.
  std::vector<LightDetection> detections;
  std::optional<Pose3> T_C_D;
  Eigen::Matrix<double, 6, 6> covariance_local = Eigen::Matrix<double, 6, 6>::Zero();
  // The pose's residual per axis, a posteriori: rms_px sqrt(n / (2 n - 6)) for n lights (0:
  // unknown); a walk's detections are judged with the median of its start poses' at least.
  double residual_sigma_px = 0.0;
  // Out, for a frame without a pose that a walk reached (bridged):
  bool bridged = false;
  int anchor_frame = -1;           // the posed frame the walk started next to
  std::vector<int> light_ids;       // per detection: dock light id or -1
  std::vector<bool> unexplained;    // per detection: no light of the dock at the walk's pose
};

struct TwoWayLightBridgeOptions {
  FewLightTrackerOptions tracker;
  bool backward = true;  // false: forward in time only (what a live system could do)
};

// Fills the out fields of frames (in time order). Returns the number of frames bridged.
int BridgeFramesWithoutPose(const PinholeRadtanCamera& camera, const DockModel& dock,
                            double frame_interval_s, const TwoWayLightBridgeOptions& options,
                            std::vector<BridgedFrame>* frames);

}  // namespace auvdock
