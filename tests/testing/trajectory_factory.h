// Synthetic ground truth for evaluation tests: a smooth, analytic docking-like approach.
//
// Position in the dock frame D (m), t in seconds since the first sample:
//   p(t) = (-20 + 0.5 t,  2 sin(0.2 t),  5 + 0.5 sin(0.3 t))
// and attitude R_D_B = Rz(yaw) Ry(pitch) Rx(roll) with
//   roll = 0.05 sin(0.5 t), pitch = 0.1 sin(0.25 t), yaw = 0.3 sin(0.2 t)  (rad).
// The path is curved in all three axes, so it is never collinear (SE(3) alignment is
// well posed). v_D is the exact derivative of p; biases are zero.
#pragma once

#include <cstdint>
#include <vector>

#include "auvdock/geometry/stamped_pose.h"
#include "auvdock/io/measurements.h"

namespace auvdock::test {

// The analytic pose at t_s seconds after the start.
Pose3 SmoothApproachPose(double t_s);

// n samples at t0_ns, t0_ns + dt_ns, ...
std::vector<GroundTruthState> MakeSmoothApproachTruth(int64_t t0_ns, int64_t dt_ns, int n);

// The truth's poses as a trajectory (same times, same poses).
Trajectory TrajectoryFromTruth(const std::vector<GroundTruthState>& truth);

}  // namespace auvdock::test
