#include "tests/testing/dock_views.h"

#include <algorithm>
#include <utility>

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

Pose3 ViewFromElevation(const DockModel& dock, double distance_m, double elevation_rad,
                        double azimuth_rad) {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const DockLight& light : dock.lights) centre += light.p_D / dock.lights.size();
  const Eigen::Vector3d camera_D =
      centre + distance_m * Eigen::Vector3d(-std::cos(elevation_rad) * std::cos(azimuth_rad),
                                            -std::cos(elevation_rad) * std::sin(azimuth_rad),
                                            -std::sin(elevation_rad));
  const Eigen::Vector3d z_C = (centre - camera_D).normalized();
  const Eigen::Vector3d x_C = Eigen::Vector3d::UnitZ().cross(z_C).normalized();
  Eigen::Matrix3d R_D_C;
  R_D_C << x_C, z_C.cross(x_C), z_C;
  return Pose3(Eigen::Quaterniond(R_D_C), camera_D).Inverse();
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

View MakeView(const DockModel& dock, const PinholeRadtanCamera& camera, const Pose3& T_C_D,
              const std::vector<int>& visible_ids, int num_spurious, double noise_px,
              std::mt19937_64& rng) {
  std::normal_distribution<double> noise(0.0, noise_px);
  std::uniform_real_distribution<double> u(0.0, camera.width() - 1.0);
  std::uniform_real_distribution<double> v(0.0, camera.height() - 1.0);
  std::vector<std::pair<LightDetection, int>> items;
  for (int id : visible_ids) {
    LightDetection d;
    d.uv =
        *camera.Project(T_C_D * dock.FindLight(id)->p_D) + Eigen::Vector2d(noise(rng), noise(rng));
    d.score = 1.0;
    items.emplace_back(d, id);
  }
  for (int s = 0; s < num_spurious; ++s) {
    LightDetection d;
    d.uv = Eigen::Vector2d(u(rng), v(rng));
    d.score = 0.5;
    items.emplace_back(d, -1);
  }
  std::shuffle(items.begin(), items.end(), rng);
  View view;
  view.T_C_D = T_C_D;
  for (const auto& [detection, id] : items) {
    view.detections.push_back(detection);
    view.truth.push_back(id);
  }
  return view;
}

std::vector<int> AllLightIds(const DockModel& dock) {
  std::vector<int> ids;
  for (const DockLight& light : dock.lights) ids.push_back(light.id);
  return ids;
}

}  // namespace auvdock::test
