// Scene helpers for renderer and simulator tests: the default rig's forward camera, a T-shaped
// dock, and a look-at pose.
//
// Frames as in CONVENTIONS.md: dock frame D (origin on the deck, x along the docking axis, z down),
// camera frame C (OpenCV: x right, y down, z optical axis). Units: metres, pixels.
#pragma once

#include <Eigen/Core>

#include "auvdock/camera/camera_calibration.h"
#include "auvdock/geometry/dock_model.h"
#include "auvdock/geometry/pose3.h"

namespace auvdock::test {

// A camera like the default rig's: HFOV 70 deg, principal point at the centre, mild radtan
// distortion (k1 -0.05, k2 0.01, p1 0.0005, p2 -0.0003). T_B_C is the identity.
CameraCalibration MakeRigCamera(int width = 640, int height = 512);

// Seed 004's T-shape: four lights on the centre line (x = -0.75 .. 0.75 m, 0.5 m apart) and two
// on the cross bar at x = 0.75 m, y = +-0.5 m; 2 cm above the deck, radius 5 cm, intensity 1.
// Deck 3 m x 2 m, 0.5 m above the seabed.
DockModel MakeTDock();

// T_D_C of a camera at p_D_C whose optical axis points at target_D. The image's down direction
// (y of C) is the projection of +z of D (down) when the view is oblique, and -x of D (so the
// docking direction points up in the image) when looking straight down.
Pose3 LookAt(const Eigen::Vector3d& p_D_C, const Eigen::Vector3d& target_D);

// A camera at the given range from target_D, on the docking axis's approach side (x < 0),
// looking down at target_D at depression_deg below the horizontal (90 = straight down).
Pose3 ApproachPose(double range_m, double depression_deg,
                   const Eigen::Vector3d& target_D = Eigen::Vector3d::Zero());

}  // namespace auvdock::test
