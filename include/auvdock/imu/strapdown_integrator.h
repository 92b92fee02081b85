// Strapdown integration of bias-corrected IMU samples (dead reckoning), 4th-order Runge-Kutta.
//
// Kinematics in D, with gravity g_D a vector (nominally (0, 0, +9.81) in the z-down dock frame):
//   dq_D_B/dt = 1/2 q_D_B (x) [0, w_B],   dp_D/dt = v_D,   dv_D/dt = R_D_B f_B + g_D
// Between two samples (t_k, w_k, f_k) and (t_k+1, ...) the inputs are linearly interpolated, and
// one RK4 step is taken over the interval; the quaternion is renormalized after each step.
// The local error is O(dt^5) in the state and O(dt^2 * d2/dt2 input) from the interpolation, so
// a noise-free 200 Hz IMU of a smooth trajectory integrates to sub-millimetre over 10 s.
// This is the propagator for the IMU-rate pose the controller reads and the test oracle for the
// simulator's IMU.
#pragma once

#include "auvdock/imu/nav_state.h"
#include "auvdock/io/measurements.h"

namespace auvdock {

class StrapdownIntegrator {
 public:
  explicit StrapdownIntegrator(const Eigen::Vector3d& gravity_D) : gravity_D_(gravity_D) {}

  // Propagates `state`, valid at a.t_ns, to b.t_ns using the two samples (biases removed).
  NavState Step(const NavState& state, const ImuSample& a, const ImuSample& b) const;

 private:
  Eigen::Vector3d gravity_D_;
};

}  // namespace auvdock
