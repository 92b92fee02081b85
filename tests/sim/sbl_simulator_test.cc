// The simulated short-baseline array: exact ranges without noise, the blind zone, multipath
// outliers listed, and the whole path scenario -> dataset -> reader.
#include "auvdock/sim/sbl_simulator.h"

#include <gtest/gtest.h>

#include "auvdock/io/dataset.h"
#include "auvdock/sim/docking_simulator.h"
#include "auvdock/sim/random_stream.h"
#include "tests/testing/temp_dir.h"
#include "tests/testing/test_scenarios.h"

namespace auvdock {
namespace {

SblCalibration FourCorners() {
  SblCalibration c;
  c.p_B_transducers = {{0.4, -0.15, 0.2}, {0.4, 0.15, 0.2}, {-0.4, 0.15, 0.2}, {-0.4, -0.15, 0.2}};
  return c;
}

KinematicState At(const Eigen::Vector3d& p_D_B) {
  KinematicState s;
  s.T_D_B = Pose3(Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ())), p_D_B);
  return s;
}

TEST(SblSimulatorTest, NoiseFreeRangesAreTheGeometryAndTheBlindZoneHasNone) {
  DockModel dock;
  dock.p_D_beacon = Eigen::Vector3d(0.1, -0.2, 0.0);
  SblFaultConfig faults;
  faults.min_range_m = 1.0;
  SblSimulator sim(FourCorners(), dock, faults, /*noise_enabled=*/false, MakeRandomStream(1, 5));
  std::vector<FaultRecord> records;
  const KinematicState far = At(Eigen::Vector3d(3.0, 1.0, -4.0));
  const std::vector<SblRange> ranges = sim.Ping(1000, far, &records);
  ASSERT_EQ(ranges.size(), 4u);
  for (int k = 0; k < 4; ++k) {
    EXPECT_EQ(ranges[k].transducer, k);
    EXPECT_EQ(ranges[k].t_ns, 1000);
    EXPECT_NEAR(ranges[k].range_m,
                (far.T_D_B * FourCorners().p_B_transducers[k] - dock.p_D_beacon).norm(), 1e-12);
    EXPECT_GT(ranges[k].sigma_m, 0.0);
  }
  // 0.3-0.9 m from the beacon: inside the blind zone, no range at all.
  EXPECT_TRUE(sim.Ping(2000, At(Eigen::Vector3d(0.1, -0.2, -0.5)), &records).empty());
  EXPECT_TRUE(records.empty());
}

TEST(SblSimulatorTest, MultipathLengthensTheRangeAndIsListed) {
  DockModel dock;
  SblFaultConfig faults;
  faults.dropout_probability = 0.0;
  faults.outlier_probability = 1.0;
  faults.outlier_m = 2.0;
  SblSimulator sim(FourCorners(), dock, faults, /*noise_enabled=*/true, MakeRandomStream(1, 5));
  std::vector<FaultRecord> records;
  const KinematicState s = At(Eigen::Vector3d(5.0, 0.0, -3.0));
  const std::vector<SblRange> ranges = sim.Ping(1000, s, &records);
  ASSERT_EQ(ranges.size(), 4u);
  ASSERT_EQ(records.size(), 4u);
  for (int k = 0; k < 4; ++k) {
    const double truth = (s.T_D_B * FourCorners().p_B_transducers[k] - dock.p_D_beacon).norm();
    EXPECT_GT(ranges[k].range_m - truth, 1.0 - 5 * ranges[k].sigma_m);
    EXPECT_LT(ranges[k].range_m - truth, 2.0 + 5 * ranges[k].sigma_m);
    EXPECT_EQ(records[k].kind, "outlier");
    EXPECT_EQ(records[k].sensor, "sbl0");
  }
}

TEST(SblSimulatorTest, AScenarioWithAnArrayWritesItsRangesAndCalibration) {
  test::TempDir tmp;
  Scenario scenario = test::ShortScenario(2.0);
  scenario.cameras.render_images = false;
  scenario.sbl = FourCorners();
  scenario.sbl->rate_hz = 2.0;
  const SimulationSummary summary = DockingSimulator(scenario).Run(tmp.path(), CancellationToken());
  const Dataset ds = LoadDataset(tmp.path());
  ASSERT_TRUE(ds.calibration.sbl.has_value());
  EXPECT_EQ(ds.calibration.sbl->p_B_transducers, scenario.sbl->p_B_transducers);
  EXPECT_EQ(static_cast<int>(ds.sbl.size()), summary.n_sbl_ranges);
  EXPECT_GE(ds.sbl.size(), 8u);  // 5 pings of 4 ranges, a few dropped
  EXPECT_LE(ds.sbl.size(), 20u);
}

}  // namespace
}  // namespace auvdock
