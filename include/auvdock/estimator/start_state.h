// A starting state that the user gives (`run` / `smooth` --start FILE): what a navigator has
// before any light or fix, an INS's output, a surveyed launch position and a gyrocompass heading.
// The window starts from it at the first state at or after its time (carried there by the IMU),
// with its covariance as the priors, before any per-frame pose or acoustic start.
//
// The file (YAML, strict: an unknown key, a wrong type or a value out of range names the file and
// the key):
//
//   t_ns: 1700000000589184813      # optional: when the state holds (default: the first state)
//   p_D: [-76.3, 32.4, -6.3]        # m, the body (IMU) in the dock frame D (z down)
//   rpy_deg: [0.4, -0.5, -170.4]    # roll, pitch, yaw of R_D_B (Z-Y-X: R = Rz(yaw) Ry(pitch)
//   Rx(roll)) v_D: [-1.94, -0.68, 0.0]        # m/s in D (optional, default 0) position_sigma_m:
//   0.5           # 1-sigma per axis tilt_sigma_deg: 0.05            # about D's horizontal axes
//   (roll and pitch) heading_sigma_deg: 0.5          # about D's vertical axis velocity_sigma_mps:
//   0.05        # per axis
//
// The covariance is in the window's tangent space [dp_D, dtheta_D] (dtheta on the left, in D):
// diag(position^2 I3, tilt^2, tilt^2, heading^2). Units as named; angles in degrees in the file.
#pragma once

#include <string>

#include "auvdock/estimator/acoustic_initializer.h"

namespace auvdock {

// t_ns 0 when the file gives none. Throws InputError naming the file and the key.
InitialState LoadStartState(const std::string& path);

}  // namespace auvdock
