#include "auvdock/imu/strapdown_integrator.h"

#include <gtest/gtest.h>

#include "auvdock/geometry/pose3.h"
#include "auvdock/sim/docking_trajectory.h"
#include "auvdock/sim/imu_simulator.h"
#include "tests/testing/test_scenarios.h"

namespace auvdock {
namespace {

// Integrating the simulator's noise-free IMU from the true initial state reproduces the true
// trajectory: < 1 mm and < 1e-4 rad over 10 s (issue "Foundation", tests).
TEST(StrapdownIntegrator, NoiseFreeImuReproducesTheTrajectory) {
  const Scenario scenario = test::DefaultScenario();
  const DockingTrajectory trajectory(scenario.trajectory);
  const Eigen::Vector3d g_D = scenario.dock.gravity_D;
  const StrapdownIntegrator integrator(g_D);

  // Two windows: the approach (fast, rolling) and the descent.
  for (double t_start : {0.0, 20.0}) {
    const int64_t dt_ns = 5000000;  // 200 Hz
    const int64_t n = 10 * 200;
    auto state_at = [&](int64_t k) { return trajectory.At(t_start + k * dt_ns * 1e-9); };
    const KinematicState s0 = state_at(0);
    NavState nav{s0.T_D_B.q, s0.T_D_B.p, s0.v_D};
    ImuSample previous = ImuSimulator::Ideal(0, s0, g_D);
    double max_pos_error = 0.0, max_att_error = 0.0;
    for (int64_t k = 1; k <= n; ++k) {
      const KinematicState truth = state_at(k);
      const ImuSample sample = ImuSimulator::Ideal(k * dt_ns, truth, g_D);
      nav = integrator.Step(nav, previous, sample);
      previous = sample;
      max_pos_error = std::max(max_pos_error, (nav.p_D - truth.T_D_B.p).norm());
      max_att_error = std::max(max_att_error, RotationAngleBetween(nav.q_D_B, truth.T_D_B.q));
    }
    EXPECT_LT(max_pos_error, 1e-3) << "window starting at " << t_start << " s";
    EXPECT_LT(max_att_error, 1e-4) << "window starting at " << t_start << " s";
  }
}

TEST(StrapdownIntegrator, AtRestStaysAtRest) {
  const Eigen::Vector3d g_D(0.0, 0.0, 9.81);
  const StrapdownIntegrator integrator(g_D);
  const Eigen::Quaterniond q = Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX()));
  ImuSample a{0, Eigen::Vector3d::Zero(), q.conjugate() * (-g_D)};
  ImuSample b = a;
  b.t_ns = 1000000000;
  const NavState out = integrator.Step({q, Eigen::Vector3d(1, 2, 3), Eigen::Vector3d::Zero()}, a, b);
  EXPECT_LT((out.p_D - Eigen::Vector3d(1, 2, 3)).norm(), 1e-12);
  EXPECT_LT(out.v_D.norm(), 1e-12);
}

}  // namespace
}  // namespace auvdock
