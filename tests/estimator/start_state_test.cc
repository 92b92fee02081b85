#include "auvdock/estimator/start_state.h"

#include <cmath>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "auvdock/io/input_error.h"
#include "tests/testing/temp_dir.h"

namespace auvdock {
namespace {

using ::testing::HasSubstr;

TEST(StartState, AFileGivesThePoseVelocityAndTheirCovariance) {
  test::TempDir tmp;
  const std::string path = tmp / "start.yaml";
  test::WriteTextFile(path,
                      "t_ns: 1700000000500000000\np_D: [-76.3, 32.4, -6.3]\n"
                      "rpy_deg: [0.0, 0.0, 90.0]\nv_D: [0.0, 2.0, 0.0]\nposition_sigma_m: 0.5\n"
                      "tilt_sigma_deg: 0.1\nheading_sigma_deg: 2.0\nvelocity_sigma_mps: 0.05\n");
  const InitialState start = LoadStartState(path);
  EXPECT_EQ(start.t_ns, 1700000000500000000);
  EXPECT_TRUE(start.T_D_B.p.isApprox(Eigen::Vector3d(-76.3, 32.4, -6.3)));
  // Yaw 90 deg: the body's x axis points along D's y.
  EXPECT_TRUE((start.T_D_B.q * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitY(), 1e-12));
  EXPECT_TRUE(start.v_D.isApprox(Eigen::Vector3d(0.0, 2.0, 0.0)));
  const double tilt = 0.1 * M_PI / 180.0, heading = 2.0 * M_PI / 180.0;
  Eigen::Matrix<double, 6, 1> expected;
  expected << 0.25, 0.25, 0.25, tilt * tilt, tilt * tilt, heading * heading;
  EXPECT_TRUE(start.pose_covariance.diagonal().isApprox(expected, 1e-12));
  EXPECT_DOUBLE_EQ(start.pose_covariance(0, 3), 0.0);
  EXPECT_TRUE(start.velocity_covariance.isApprox(Eigen::Matrix3d::Identity() * 0.0025));
}

TEST(StartState, BadKeysAndValuesNameTheFileAndTheKey) {
  test::TempDir tmp;
  const std::string path = tmp / "start.yaml";
  const std::string rest =
      "rpy_deg: [0, 0, 0]\nposition_sigma_m: 0.5\ntilt_sigma_deg: 0.1\nheading_sigma_deg: 2\n"
      "velocity_sigma_mps: 0.05\n";
  const auto error_of = [&](const std::string& text) {
    test::WriteTextFile(path, text);
    try {
      LoadStartState(path);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_THAT(error_of(rest), AllOf(HasSubstr(path), HasSubstr("p_D")));
  EXPECT_THAT(error_of("p_D: [0, 0]\n" + rest), HasSubstr("3 numbers"));
  EXPECT_THAT(error_of("p_D: [0, 0, 0]\nposition: 1\n" + rest), HasSubstr("position"));
  EXPECT_THAT(error_of("p_D: [0, 0, 0]\nt_ns: -5\n" + rest), HasSubstr("t_ns"));
  std::string zero_sigma = rest;
  zero_sigma.replace(zero_sigma.find("0.05"), 4, "0");
  EXPECT_THAT(error_of("p_D: [0, 0, 0]\n" + zero_sigma), HasSubstr("velocity_sigma_mps"));
  EXPECT_EQ(error_of("p_D: [0, 0, 0]\n" + rest), "");
}

}  // namespace
}  // namespace auvdock
