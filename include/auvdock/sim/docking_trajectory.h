// The simulated vehicle's path: approach from behind and above the dock, descend, land on it
// ("situated" recovery, like a helicopter landing; seed 000 section 1, seed 004 fig. 2).
//
// Frames: the body pose T_D_B in the dock frame D (z down, deck at z = 0, vehicle at z < 0).
// Time t in seconds from the start of the run. Every coordinate is a closed-form, twice
// differentiable function of t (Smooth arithmetic), so velocity, acceleration and body rate are
// exact and an IMU built from them integrates back to the trajectory.
//
//   horizontal x, y: quintic Hermite from start_p_D (initial speed start_speed_mps towards the
//                    hover point) to hover_p_D over [0, approach_end_s]; then held.
//   vertical z:      quintic from start_p_D.z to hover_p_D.z over [0, approach_end_s], plus a
//                    second quintic from hover_p_D.z down to landed_z_D over
//                    [descent_start_s, touchdown_s] (the final, near-vertical descent).
//   perturbations:   current drift (lateral y sinusoid), heave (z), roll, pitch, yaw
//                    oscillations, each amplitude * sin(2 pi t / period + phase) multiplied by an
//                    envelope that fades to zero over the descent, so the vehicle lands.
//   attitude:        R_D_B = Rz(yaw) Ry(pitch) Rx(roll); the yaw starts at start_yaw_deg (a
//                    crab angle against the current) and converges to 0 over the approach.
// Body rates from Euler rates: w_B = [droll - dyaw sin(pitch),
//                                     dpitch cos(roll) + dyaw cos(pitch) sin(roll),
//                                     -dpitch sin(roll) + dyaw cos(pitch) cos(roll)].
#pragma once

#include <Eigen/Core>

#include "auvdock/geometry/pose3.h"

namespace auvdock {

struct OscillationConfig {
  double amplitude = 0.0;  // metres or degrees, as the field says
  double period_s = 10.0;
  double phase_rad = 0.0;
};

struct DockingTrajectoryConfig {
  Eigen::Vector3d start_p_D = Eigen::Vector3d(-8.0, 1.0, -4.5);
  double start_speed_mps = 0.5;
  double start_yaw_deg = 8.0;
  Eigen::Vector3d hover_p_D = Eigen::Vector3d(0.0, 0.0, -3.0);
  double landed_z_D = -0.65;  // body origin at touchdown (the hull rests on the deck)
  double approach_end_s = 24.0;
  double descent_start_s = 22.0;
  double touchdown_s = 38.0;
  OscillationConfig current_drift_m{0.25, 17.0, 0.3};
  OscillationConfig heave_m{0.08, 6.0, 1.1};
  OscillationConfig roll_deg{2.5, 7.0, 0.0};
  OscillationConfig pitch_deg{2.0, 9.0, 0.7};
  OscillationConfig yaw_deg{1.5, 13.0, 2.0};
};

struct KinematicState {
  Pose3 T_D_B;
  Eigen::Vector3d v_D = Eigen::Vector3d::Zero();      // m/s
  Eigen::Vector3d a_D = Eigen::Vector3d::Zero();      // m/s^2
  Eigen::Vector3d omega_B = Eigen::Vector3d::Zero();  // rad/s, body rate in B
};

class DockingTrajectory {
 public:
  explicit DockingTrajectory(const DockingTrajectoryConfig& config);
  KinematicState At(double t_s) const;
  const DockingTrajectoryConfig& config() const { return config_; }

 private:
  DockingTrajectoryConfig config_;
};

}  // namespace auvdock
