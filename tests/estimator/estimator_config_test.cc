// LoadRunConfig (estimator/estimator_config.h): the shipped data/estimator/default.yaml states
// the built-in defaults, and the smoother's vision-noise keys are read and checked.
#include <fstream>

#include <gtest/gtest.h>

#include "auvdock/estimator/estimator_config.h"
#include "auvdock/io/input_error.h"
#include "tests/testing/temp_dir.h"
#include "tests/testing/test_scenarios.h"

namespace auvdock {
namespace {

TEST(EstimatorConfigTest, ShippedDefaultsEqualTheBuiltInOnes) {
  const RunConfig config = LoadRunConfig(test::SourcePath("data/estimator/default.yaml"));
  const EstimatorOptions defaults;
  EXPECT_EQ(config.estimator.smoother_vision_floor_px, defaults.smoother_vision_floor_px);
  EXPECT_EQ(config.estimator.smoother_vision_correlation_time_s,
            defaults.smoother_vision_correlation_time_s);
  EXPECT_EQ(config.estimator.window_size, defaults.window_size);
  EXPECT_EQ(config.estimator.adaptive_dvl_noise.enabled, defaults.adaptive_dvl_noise.enabled);
  EXPECT_EQ(config.estimator.adaptive_vision_floor.enabled,
            defaults.adaptive_vision_floor.enabled);
  EXPECT_EQ(config.estimator.max_window_vision_floor_px, defaults.max_window_vision_floor_px);
  EXPECT_EQ(config.estimator.max_window_vision_correlation_time_s,
            defaults.max_window_vision_correlation_time_s);
  EXPECT_EQ(config.estimator.acoustic_init.enabled, defaults.acoustic_init.enabled);
  EXPECT_EQ(config.estimator.acoustic_init.min_fixes, defaults.acoustic_init.min_fixes);
  EXPECT_EQ(config.estimator.acoustic_init.max_span_s, defaults.acoustic_init.max_span_s);
  EXPECT_EQ(config.estimator.acoustic_init.max_heading_sigma_rad,
            defaults.acoustic_init.max_heading_sigma_rad);
}

TEST(EstimatorConfigTest, WindowVisionFloorKeys) {
  const test::TempDir dir;
  const std::string path = dir.path() + "/estimator.yaml";
  {
    std::ofstream(path) << "estimator:\n  adaptive_vision_floor: false\n"
                           "  max_window_vision_floor_px: 0.3\n"
                           "  max_window_vision_correlation_time_s: 10\n";
  }
  const RunConfig config = LoadRunConfig(path);
  EXPECT_FALSE(config.estimator.adaptive_vision_floor.enabled);
  EXPECT_EQ(config.estimator.max_window_vision_floor_px, 0.3);
  EXPECT_EQ(config.estimator.max_window_vision_correlation_time_s, 10.0);
  { std::ofstream(path) << "estimator:\n  adaptive_vision_floor: maybe\n"; }
  EXPECT_THROW(LoadRunConfig(path), InputError);
}

TEST(EstimatorConfigTest, AcousticStartKeys) {
  const test::TempDir dir;
  const std::string path = dir.path() + "/estimator.yaml";
  {
    std::ofstream(path) << "estimator:\n  acoustic_init: false\n  acoustic_init_min_fixes: 6\n"
                           "  acoustic_init_max_heading_sigma_rad: 0.05\n";
  }
  const RunConfig config = LoadRunConfig(path);
  EXPECT_FALSE(config.estimator.acoustic_init.enabled);
  EXPECT_EQ(config.estimator.acoustic_init.min_fixes, 6);
  EXPECT_EQ(config.estimator.acoustic_init.max_heading_sigma_rad, 0.05);
  { std::ofstream(path) << "estimator:\n  acoustic_init_min_fixes: 2\n"; }
  try {
    LoadRunConfig(path);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("acoustic_init_min_fixes"), std::string::npos) << e.what();
  }
}

TEST(EstimatorConfigTest, DvlAdmissionKeys) {
  const test::TempDir dir;
  const std::string path = dir.path() + "/estimator.yaml";
  EXPECT_TRUE(EstimatorOptions().dvl_admission);
  {
    std::ofstream(path) << "estimator:\n  dvl_admission: false\n  dvl_admission_bias_mps: 0.3\n";
  }
  const RunConfig config = LoadRunConfig(path);
  EXPECT_FALSE(config.estimator.dvl_admission);
  EXPECT_EQ(config.estimator.dvl_admission_bias_mps, 0.3);
  { std::ofstream(path) << "estimator:\n  dvl_admission_bias_mps: -0.2\n"; }
  try {
    LoadRunConfig(path);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("dvl_admission_bias_mps"), std::string::npos) << e.what();
  }
}

TEST(EstimatorConfigTest, AdaptiveDvlNoiseSwitch) {
  const test::TempDir dir;
  const std::string path = dir.path() + "/estimator.yaml";
  { std::ofstream(path) << "estimator:\n  adaptive_dvl_noise: false\n"; }
  EXPECT_FALSE(LoadRunConfig(path).estimator.adaptive_dvl_noise.enabled);
  { std::ofstream(path) << "estimator:\n  adaptive_dvl_noise: maybe\n"; }
  EXPECT_THROW(LoadRunConfig(path), InputError);
}

TEST(EstimatorConfigTest, SmootherVisionNoiseKeys) {
  const test::TempDir dir;
  const std::string path = dir.path() + "/estimator.yaml";
  {
    std::ofstream(path) << "estimator:\n  smoother_vision_floor_px: 0.0\n"
                           "  smoother_vision_correlation_time_s: 3.5\n";
  }
  const RunConfig config = LoadRunConfig(path);
  EXPECT_EQ(config.estimator.smoother_vision_floor_px, 0.0);
  EXPECT_EQ(config.estimator.smoother_vision_correlation_time_s, 3.5);
  { std::ofstream(path) << "estimator:\n  smoother_vision_floor_px: -0.1\n"; }
  EXPECT_THROW(LoadRunConfig(path), InputError);
}

}  // namespace
}  // namespace auvdock
