// The lights of a camera's frames without a pose, identified from the posed frames beside them
// (FewLightTracker), and tracked poses that the longer record around them refutes.
//
// Chains: a posed frame that was tracked from the pose before it (MonoPoseResult::tracked)
// continues that pose's chain; one from scratch starts a new one. A chain is one labelling
// hypothesis carried along, right or wrong as a whole.
//
// 1. Refutation (refute_margin > 0), longest chains first: a walk from a chain's first and last
//    consecutive poses (min_start_poses of them at least) into the frames beside it meets the
//    next chain; when, in the frame where they meet, the walk labels at least refute_margin
//    detections more than that frame's own pose identified (and passes its consistency test
//    there), and the walking chain holds more posed frames, the met chain is refuted: all its
//    poses are withdrawn and the walk goes on through it. Tracking can carry one light and a few
//    fittings that fit the dock for tens of frames (randomised renders, seed 4, cam2: 31 frames,
//    2 m off) until a pose from scratch on the true lights takes over; walking back from that
//    longer chain finds the true lights unexplained beside the wrong labels.
//    A chain too short to start a walk of its own (a lone pose among frames without one) is
//    refuted as well when the walk that meets it judges at least lone_refute_contradicted of the
//    detections its pose took for lights to be no light of the dock at all (FewLightStep::
//    unexplained: a contradiction whatever the dock's symmetry, and one that a poor camera model's
//    extrapolation does not make, since the verdict allows a third of a light's spacing). Between
//    frames whose 4 detections two labellings explain equally, a fitting that happens to fit
//    lends one frame a wrong pose from 5 (randomised renders, seed 3, cam2: 0.26 px rms, NEES
//    40000).
// 2. Bridging: from every chain that stands, a walk forward in time into the frames after it
//    and, on recorded footage (backward), one backward into the frames before it, each until a
//    standing chain's pose (a chain too short to start a walk is walked through; its own labels
//    stay) or until the walk ends. A frame reached by two walks takes the labels of the one whose
//    posed frames are nearer (fewer frames walked).
// A frame's doubtful candidates (FewLightTracker::Step) that a walk puts a light on are that
// light's; nothing else of them is used.
// The dock entering the downward camera's view shows 1-3 lights among the deck's fittings for
// tens of frames before a pose of its own is possible; the poses that follow identify them, and
// what they leave far from every light is no light of the dock.
//
// Units and frames: FewLightTracker's.
#pragma once

#include <algorithm>
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
  bool tracked = false;  // the pose was tracked from the pose before it
  std::vector<int> own_light_ids;  // per detection: its own pose's light id, or -1 (empty: none)
  // The pose's residual per axis, a posteriori: rms_px sqrt(n / (2 n - 6)) for n lights (0:
  // unknown); a walk's detections are judged with the median of its start poses' at least.
  double residual_sigma_px = 0.0;
  // Candidates the detector rejected on appearance alone, and saturated discs (FewLightTracker::
  // Step's doubtful ones).
  std::vector<LightDetection> doubtful;
  // Out: a frame whose pose a longer chain refuted (its pose is to be withdrawn) ...
  bool refuted = false;
  int refuted_by = -1;  // the first or last frame of the chain whose walk refuted it
  int contradicted = 0;  // a lone pose refuted for this many lights the walk judged none
  // ... or without a pose, that a walk reached (bridged; a refuted frame may be bridged too):
  bool bridged = false;
  int anchor_frame = -1;           // the posed frame the walk started next to
  std::vector<int> light_ids;       // per detection: dock light id or -1
  std::vector<bool> unexplained;    // per detection: no light of the dock at the walk's pose
  std::vector<int> doubtful_light_ids;  // per doubtful candidate: the walk's light there, or -1
  std::optional<Pose3> walk_T_C_D;      // the walk's (filtered) pose of the frame

  // Detections its own pose labelled.
  int identified() const {
    return static_cast<int>(
        std::count_if(own_light_ids.begin(), own_light_ids.end(), [](int id) { return id >= 0; }));
  }
};

struct TwoWayLightBridgeOptions {
  FewLightTrackerOptions tracker;
  bool backward = true;  // false: forward in time only (what a live system could do)
  int refute_margin = 1;  // 0: no refutation
  int lone_refute_contradicted = 2;  // 0: lone poses are not refuted
};

// Fills the out fields of frames (in time order). Returns the number of frames bridged.
int BridgeFramesWithoutPose(const PinholeRadtanCamera& camera, const DockModel& dock,
                            double frame_interval_s, const TwoWayLightBridgeOptions& options,
                            std::vector<BridgedFrame>* frames);

}  // namespace auvdock
