#include "tests/testing/trajectory_factory.h"

#include <cmath>

#include "auvdock/geometry/so3.h"

namespace auvdock::test {
namespace {

Eigen::Vector3d Position(double t) {
  return Eigen::Vector3d(-20.0 + 0.5 * t, 2.0 * std::sin(0.2 * t), 5.0 + 0.5 * std::sin(0.3 * t));
}

Eigen::Vector3d Velocity(double t) {
  return Eigen::Vector3d(0.5, 0.4 * std::cos(0.2 * t), 0.15 * std::cos(0.3 * t));
}

}  // namespace

Pose3 SmoothApproachPose(double t_s) {
  const double roll = 0.05 * std::sin(0.5 * t_s);
  const double pitch = 0.1 * std::sin(0.25 * t_s);
  const double yaw = 0.3 * std::sin(0.2 * t_s);
  return Pose3(QuaternionFromRollPitchYaw(roll, pitch, yaw), Position(t_s));
}

std::vector<GroundTruthState> MakeSmoothApproachTruth(int64_t t0_ns, int64_t dt_ns, int n) {
  std::vector<GroundTruthState> truth(n);
  for (int i = 0; i < n; ++i) {
    const double t_s = static_cast<double>(i) * static_cast<double>(dt_ns) * 1e-9;
    truth[i].t_ns = t0_ns + i * dt_ns;
    truth[i].T_D_B = SmoothApproachPose(t_s);
    truth[i].v_D = Velocity(t_s);
  }
  return truth;
}

Trajectory TrajectoryFromTruth(const std::vector<GroundTruthState>& truth) {
  Trajectory trajectory;
  trajectory.reserve(truth.size());
  for (const GroundTruthState& s : truth) trajectory.push_back({s.t_ns, s.T_D_B});
  return trajectory;
}

}  // namespace auvdock::test
