// The simulator's sensor errors that the estimator does not model unless told: an IMU worse than
// its calibration (noise above the datasheet, scale factors, misaligned axes; sim/imu_simulator.h)
// and a depth sensor whose zero is not the dock survey's (sim/depth_simulator.h). Known answers
// from the models in those headers, the statistics of the scaled noise, and the faults.csv
// records.
#include <cmath>
#include <optional>
#include <random>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "auvdock/geometry/so3.h"
#include "auvdock/sim/depth_simulator.h"
#include "auvdock/sim/imu_simulator.h"

namespace auvdock {
namespace {

using ::testing::HasSubstr;

const Eigen::Vector3d kGravity(0.0, 0.0, 9.81);

KinematicState SomeState() {
  KinematicState s;
  s.T_D_B = Pose3(Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, -2, 1).normalized())),
                  Eigen::Vector3d(1.0, 2.0, -3.0));
  s.a_D = Eigen::Vector3d(0.2, -0.1, 0.05);
  s.omega_B = Eigen::Vector3d(0.05, -0.02, 0.1);
  return s;
}

// With the noise at zero (densities tiny) the sample is the model's deterministic part:
// (I + diag(s)) R_m^T times the ideal rate and specific force, plus the initial biases.
TEST(ImuSimulatorErrors, ScaleFactorsAndMisalignmentFollowTheModel) {
  ImuCalibration calibration;
  calibration.gyroscope_noise_density = 1e-15;
  calibration.accelerometer_noise_density = 1e-15;
  calibration.gyroscope_random_walk = 1e-15;
  calibration.accelerometer_random_walk = 1e-15;
  ImuErrorConfig errors;
  errors.gyro_scale_factor = Eigen::Vector3d(0.003, -0.002, 0.004);
  errors.accel_scale_factor = Eigen::Vector3d(-0.002, 0.003, 0.003);
  errors.misalignment_rad = Eigen::Vector3d(0.002, -0.003, 0.002);
  const Eigen::Vector3d b_g(0.001, 0.0, -0.002), b_a(0.02, 0.0, 0.01);
  ImuSimulator imu(calibration, kGravity, b_g, b_a, true, std::mt19937_64(3), errors);
  const KinematicState s = SomeState();
  std::optional<FaultRecord> fault;
  const ImuSample sample = imu.Sample(5, s, &fault);
  const ImuSample ideal = ImuSimulator::Ideal(5, s, kGravity);
  const Eigen::Matrix3d R_m_T = ExpSO3(errors.misalignment_rad).transpose();
  const Eigen::Vector3d gyro =
      (Eigen::Matrix3d::Identity() + errors.gyro_scale_factor.asDiagonal().toDenseMatrix()) *
          R_m_T * ideal.gyro + b_g;
  const Eigen::Vector3d accel =
      (Eigen::Matrix3d::Identity() + errors.accel_scale_factor.asDiagonal().toDenseMatrix()) *
          R_m_T * ideal.accel + b_a;
  EXPECT_LT((sample.gyro - gyro).norm(), 1e-9);
  EXPECT_LT((sample.accel - accel).norm(), 1e-9);
  // The errors are there: a 0.3 % scale of ~9.8 m/s^2 and 3 mrad of tilt are centimetres.
  EXPECT_GT((sample.accel - ideal.accel - b_a).norm(), 0.02);
  ASSERT_TRUE(fault.has_value());
  EXPECT_EQ(fault->sensor, "imu0");
  EXPECT_EQ(fault->kind, "model_error");
  EXPECT_THAT(fault->detail, HasSubstr("gyro_scale=0.003;-0.002;0.004"));
  std::optional<FaultRecord> second;
  imu.Sample(10, s, &second);
  EXPECT_FALSE(second.has_value());  // once, at the first sample
}

// noise_scale multiplies the white noise's sigma (and the random walks'), which the calibration
// keeps at the datasheet's figure.
TEST(ImuSimulatorErrors, NoiseAboveTheDatasheetIsScaled) {
  ImuCalibration calibration;
  ImuErrorConfig errors;
  errors.noise_scale = 3.0;
  const Eigen::Vector3d zero = Eigen::Vector3d::Zero();
  calibration.gyroscope_random_walk = 1e-15;
  calibration.accelerometer_random_walk = 1e-15;
  ImuSimulator imu(calibration, kGravity, zero, zero, true, std::mt19937_64(7), errors);
  const KinematicState s = SomeState();
  const ImuSample ideal = ImuSimulator::Ideal(0, s, kGravity);
  double sum_sq = 0.0;
  const int n = 20000;
  for (int k = 0; k < n; ++k) sum_sq += (imu.Sample(k, s).gyro - ideal.gyro).squaredNorm();
  const double sigma = std::sqrt(sum_sq / (3.0 * n));
  const double expected = 3.0 * calibration.gyroscope_noise_density * std::sqrt(calibration.rate_hz);
  EXPECT_NEAR(sigma, expected, 0.02 * expected);
  // Without errors: no record.
  ImuSimulator plain(calibration, kGravity, zero, zero, true, std::mt19937_64(7));
  std::optional<FaultRecord> fault;
  plain.Sample(0, s, &fault);
  EXPECT_FALSE(fault.has_value());
}

// The depth offset: bias_m at the first sample, drifting by bias_rate_mps; listed once.
TEST(DepthSimulatorErrors, TheOffsetAndItsDriftAreAddedAndListed) {
  DepthCalibration calibration;
  calibration.sigma_m = 1e-12;
  DockModel dock;
  dock.origin_depth_m = 30.0;
  dock.gravity_D = kGravity;
  DepthFaultConfig faults;
  faults.bias_m = 0.3;
  faults.bias_rate_mps = 2e-4;
  DepthSimulator biased(calibration, faults, dock, true, std::mt19937_64(1));
  DepthSimulator exact(calibration, DepthFaultConfig{}, dock, true, std::mt19937_64(1));
  const KinematicState s = SomeState();
  std::optional<FaultRecord> fault, none;
  const int64_t t0 = 1'000'000'000;
  EXPECT_NEAR(biased.Sample(t0, s, &fault).depth_m - exact.Sample(t0, s, &none).depth_m, 0.3,
              1e-9);
  const int64_t t1 = t0 + 10'000'000'000;  // 10 s later: +2 mm
  EXPECT_NEAR(biased.Sample(t1, s).depth_m - exact.Sample(t1, s).depth_m, 0.302, 1e-9);
  ASSERT_TRUE(fault.has_value());
  EXPECT_EQ(fault->kind, "bias");
  EXPECT_THAT(fault->detail, HasSubstr("bias_m=0.3"));
  EXPECT_FALSE(none.has_value());
}

}  // namespace
}  // namespace auvdock
