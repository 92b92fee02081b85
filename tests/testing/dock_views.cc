#include "tests/testing/dock_views.h"

#include <gtest/gtest.h>

#include "auvdock/geometry/so3.h"
#include "auvdock/io/dock_io.h"
#include "auvdock/sim/scenario.h"
#include "tests/testing/test_scenarios.h"

namespace auvdock::test {

namespace {
constexpr double kDeg = 3.14159265358979323846 / 180.0;
}  // namespace

PinholeRadtanCamera DefaultMonoCamera() {
  const Calibration calibration = MakeCalibration(DefaultScenario());
  const CameraCalibration* camera = calibration.FindCamera("cam2");
  EXPECT_NE(camera, nullptr);
  return camera->intrinsics;
}

DockModel LoadDock(const std::string& name) {
  return LoadDockModel(SourcePath("data/docks/" + name));
}

Pose3 RandomView(const DockModel& dock, const PinholeRadtanCamera& camera, double max_tilt_rad,
                 std::mt19937_64& rng) {
  std::uniform_real_distribution<double> yaw(0.0, 360.0 * kDeg);
  std::uniform_real_distribution<double> tilt(-max_tilt_rad, max_tilt_rad);
  std::uniform_real_distribution<double> distance(2.0, 8.0);
  std::uniform_real_distribution<double> offset(-0.3, 0.3);
  Eigen::Matrix3d R_D_down;  // camera looking down: z_C = z_D, x_C = y_D, y_C = -x_D
  R_D_down << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  for (;;) {
    const Eigen::Matrix3d R_D_C =
        QuaternionFromRollPitchYaw(tilt(rng), tilt(rng), yaw(rng)).toRotationMatrix() * R_D_down;
    const Eigen::Vector3d target(offset(rng), offset(rng), 0.0);
    const Eigen::Vector3d p_D_C = target - distance(rng) * R_D_C.col(2);
    const Pose3 T_C_D = Pose3(Eigen::Quaterniond(R_D_C), p_D_C).Inverse();
    bool all_in = true;
    for (const DockLight& light : dock.lights) {
      const auto uv = camera.Project(T_C_D * light.p_D);
      all_in = all_in && uv && camera.InImage(*uv, 5.0);
    }
    if (all_in) return T_C_D;
  }
}

}  // namespace auvdock::test
