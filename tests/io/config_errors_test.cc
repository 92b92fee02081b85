// Bad input in scenario, calibration and dock files: one error naming the file and the key.
#include <cmath>

#include <gtest/gtest.h>
#include <gmock/gmock.h>

#include "auvdock/geometry/dock_model.h"
#include "auvdock/io/calibration.h"
#include "auvdock/io/dock_io.h"
#include "auvdock/io/input_error.h"
#include "auvdock/sim/scenario.h"
#include "tests/testing/temp_dir.h"
#include "tests/testing/test_scenarios.h"

namespace auvdock {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;

// The message of the InputError that f throws ("" if none).
template <typename F>
std::string ErrorOf(F f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

class ScenarioErrors : public ::testing::Test {
 protected:
  // A scenario file next to a copy of the default dock, with `extra` appended.
  std::string WriteScenario(const std::string& body) {
    test::WriteTextFile(tmp_ / "docks/t_shape.yaml",
                        test::ReadTextFile(test::SourcePath("data/docks/t_shape.yaml")));
    const std::string path = tmp_ / "scenarios/s.yaml";
    test::WriteTextFile(path, body);
    return path;
  }
  test::TempDir tmp_;
};

TEST_F(ScenarioErrors, MinimalScenarioLoadsWithDefaults) {
  const Scenario s = LoadScenario(WriteScenario("dock: ../docks/t_shape.yaml\n"));
  EXPECT_EQ(s.dock.lights.size(), 6u);
  EXPECT_DOUBLE_EQ(s.imu.rate_hz, 200.0);
}

TEST_F(ScenarioErrors, RandomizeSectionIsOffByDefaultAndChecked) {
  EXPECT_FALSE(LoadScenario(WriteScenario("dock: ../docks/t_shape.yaml\n")).randomize.enabled);
  const Scenario s = LoadScenario(
      WriteScenario("dock: ../docks/t_shape.yaml\nrandomize: {enabled: true, jpeg: false}\n"));
  EXPECT_TRUE(s.randomize.enabled);
  EXPECT_FALSE(s.randomize.jpeg);
  EXPECT_TRUE(s.randomize.blur);
  const std::string path =
      WriteScenario("dock: ../docks/t_shape.yaml\nrandomize: {enabled: true, blurr: false}\n");
  EXPECT_THAT(ErrorOf([&] { LoadScenario(path); }),
              AllOf(HasSubstr(path), HasSubstr("randomize.blurr"), HasSubstr("unknown")));
  EXPECT_NO_THROW(LoadScenario(test::SourcePath("data/scenarios/randomized.yaml")));
}

TEST_F(ScenarioErrors, UnknownKeyIsNamedWithItsPath) {
  const std::string path =
      WriteScenario("dock: ../docks/t_shape.yaml\ncameras:\n  stereo: {tilt_dgr: 30}\n");
  EXPECT_THAT(ErrorOf([&] { LoadScenario(path); }),
              AllOf(HasSubstr(path), HasSubstr("cameras.stereo.tilt_dgr"), HasSubstr("unknown")));
}

TEST_F(ScenarioErrors, NonPositiveRateIsRejected) {
  const std::string path = WriteScenario("dock: ../docks/t_shape.yaml\nimu: {rate_hz: 0}\n");
  EXPECT_THAT(ErrorOf([&] { LoadScenario(path); }),
              AllOf(HasSubstr(path), HasSubstr("imu.rate_hz"), HasSubstr("positive")));
}

TEST_F(ScenarioErrors, MonoTimeOffsetMustBeWithinOneFrameInterval) {
  const std::string path = WriteScenario(
      "dock: ../docks/t_shape.yaml\ncameras:\n  rate_hz: 10\n  mono: {time_offset_s: 0.1}\n");
  EXPECT_THAT(ErrorOf([&] { LoadScenario(path); }),
              AllOf(HasSubstr(path), HasSubstr("cameras.mono.time_offset_s"),
                    HasSubstr("frame interval")));
  EXPECT_DOUBLE_EQ(LoadScenario(test::SourcePath("data/scenarios/unsynchronised.yaml"))
                       .cameras.mono_time_offset_s,
                   0.037);
}

TEST_F(ScenarioErrors, WrongTypeIsRejected) {
  const std::string path = WriteScenario("dock: ../docks/t_shape.yaml\nduration_s: long\n");
  EXPECT_THAT(ErrorOf([&] { LoadScenario(path); }),
              AllOf(HasSubstr("duration_s"), HasSubstr("number")));
}

TEST_F(ScenarioErrors, MissingDockKeyAndMissingDockFile) {
  EXPECT_THAT(ErrorOf([&] { LoadScenario(WriteScenario("name: x\n")); }),
              AllOf(HasSubstr("'dock'"), HasSubstr("missing")));
  EXPECT_THAT(ErrorOf([&] { LoadScenario(WriteScenario("dock: nowhere.yaml\n")); }),
              AllOf(HasSubstr("nowhere.yaml"), HasSubstr("cannot open")));
}

TEST_F(ScenarioErrors, MissingAndMalformedFiles) {
  EXPECT_THAT(ErrorOf([&] { LoadScenario(tmp_ / "absent.yaml"); }), HasSubstr("absent.yaml"));
  const std::string path = WriteScenario("dock: [unclosed\n");
  EXPECT_THAT(ErrorOf([&] { LoadScenario(path); }),
              AllOf(HasSubstr(path), HasSubstr("malformed YAML"), HasSubstr("line")));
}

TEST_F(ScenarioErrors, BadDockFileNamesTheDockFileAndKey) {
  const std::string dock = tmp_ / "docks/bad.yaml";
  test::WriteTextFile(dock,
                      "name: bad\nlights:\n  - {id: 0, p_D: [0, 0, 0]}\n  - {id: 0, p_D: [1, 0, 0]}\n"
                      "  - {id: 2, p_D: [1, 1, 0]}\n");
  EXPECT_THAT(ErrorOf([&] { LoadDockModel(dock); }),
              AllOf(HasSubstr(dock), HasSubstr("lights[1].id"), HasSubstr("duplicate")));
  test::WriteTextFile(dock, "name: bad\nlights:\n  - {id: 0, p_D: [0, 0]}\n");
  EXPECT_THAT(ErrorOf([&] { LoadDockModel(dock); }),
              AllOf(HasSubstr("lights[0].p_D"), HasSubstr("3 numbers")));
  test::WriteTextFile(dock,
                      "name: bad\nlights:\n  - {id: 0, p_D: [0, 0, 0]}\n  - {id: 1, p_D: [1, 0, 0]}\n"
                      "  - {id: 2, p_D: [1, 0, 0.0002]}\n");
  EXPECT_THAT(ErrorOf([&] { LoadDockModel(dock); }),
              AllOf(HasSubstr(dock), HasSubstr("lights 1 and 2 coincide")));
  test::WriteTextFile(dock,
                      "name: bad\ncolour: purple\nlights:\n  - {id: 0, p_D: [0, 0, 0]}\n"
                      "  - {id: 1, p_D: [1, 0, 0]}\n  - {id: 2, p_D: [1, 1, 0]}\n");
  EXPECT_THAT(ErrorOf([&] { LoadDockModel(dock); }),
              AllOf(HasSubstr(dock), HasSubstr("colour"), HasSubstr("purple")));
  const std::string three_lights =
      "lights:\n  - {id: 0, p_D: [0, 0, 0]}\n  - {id: 1, p_D: [1, 0, 0]}\n"
      "  - {id: 2, p_D: [1, 1, 0]}\n";
  test::WriteTextFile(dock, "name: bad\nlatitude_deg: 132.85\n" + three_lights);
  EXPECT_THAT(ErrorOf([&] { LoadDockModel(dock); }),
              AllOf(HasSubstr(dock), HasSubstr("latitude_deg"), HasSubstr("between -90 and 90")));
}

// The site's latitude: absent, no Earth's rotation; given, read, written back, and the rate in D.
TEST_F(ScenarioErrors, TheDocksLatitudeIsReadAndWrittenBack) {
  const std::string path = tmp_ / "docks/lat.yaml";
  const std::string three_lights =
      "lights:\n  - {id: 0, p_D: [0, 0, 0]}\n  - {id: 1, p_D: [1, 0, 0]}\n"
      "  - {id: 2, p_D: [1, 1, 0]}\n";
  test::WriteTextFile(path, "name: plain\n" + three_lights);
  const DockModel plain = LoadDockModel(path);
  EXPECT_FALSE(plain.HasLatitude());
  EXPECT_EQ(EarthRate_D(plain), Eigen::Vector3d::Zero());
  test::WriteTextFile(path, "name: haifa\nlatitude_deg: 32.85\nheading_deg: 90\n" + three_lights);
  const DockModel haifa = LoadDockModel(path);
  ASSERT_TRUE(haifa.HasLatitude());
  EXPECT_NEAR(haifa.latitude_rad, 32.85 * M_PI / 180.0, 1e-15);
  // D's x points east: the north component lies along -y.
  const Eigen::Vector3d w = EarthRate_D(haifa);
  EXPECT_NEAR(w.x(), 0.0, 1e-18);
  EXPECT_NEAR(w.y(), -kEarthRotationRate * std::cos(haifa.latitude_rad), 1e-18);
  EXPECT_NEAR(w.z(), -kEarthRotationRate * std::sin(haifa.latitude_rad), 1e-18);
  SaveDockModel(haifa, tmp_ / "docks/lat_out.yaml");
  EXPECT_NEAR(LoadDockModel(tmp_ / "docks/lat_out.yaml").latitude_rad, haifa.latitude_rad, 1e-12);
}

TEST(CalibrationErrors, BadRotationAndMissingKey) {
  test::TempDir tmp;
  const std::string path = tmp / "calibration.yaml";
  test::WriteTextFile(path,
                      "cameras:\n  - name: cam0\n    resolution: [640, 480]\n"
                      "    intrinsics: [500, 500, 320, 240]\n"
                      "    distortion_model: radial-tangential\n"
                      "    distortion_coefficients: [0, 0, 0, 0]\n    rate_hz: 10\n"
                      "    T_B_S: [2, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]\n");
  EXPECT_THAT(ErrorOf([&] { LoadCalibration(path); }),
              AllOf(HasSubstr(path), HasSubstr("cameras[0].T_B_S"), HasSubstr("rotation")));
  test::WriteTextFile(path, "cameras:\n  - name: cam0\n    resolution: [640, 480]\n");
  EXPECT_THAT(ErrorOf([&] { LoadCalibration(path); }),
              AllOf(HasSubstr("cameras[0].intrinsics"), HasSubstr("missing")));
}

}  // namespace
}  // namespace auvdock
