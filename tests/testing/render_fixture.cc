#include "tests/testing/render_fixture.h"

#include <cmath>

#include <Eigen/Geometry>

namespace auvdock::test {
namespace {
constexpr double kPi = 3.14159265358979323846;
}  // namespace

CameraCalibration MakeRigCamera(int width, int height) {
  CameraCalibration camera;
  camera.name = "cam0";
  camera.role = CameraRole::kStereoLeft;
  camera.intrinsics = PinholeRadtanCamera::FromHorizontalFov(width, height, 70.0 * kPi / 180.0,
                                                             {-0.05, 0.01, 0.0005, -0.0003, 0.0});
  camera.rate_hz = 30.0;
  return camera;
}

DockModel MakeTDock() {
  DockModel dock;
  dock.name = "t_dock";
  const double z = -0.02;
  const Eigen::Vector3d positions[] = {{-0.75, 0.0, z}, {-0.25, 0.0, z}, {0.25, 0.0, z},
                                       {0.75, 0.0, z},  {0.75, -0.5, z}, {0.75, 0.5, z}};
  int id = 0;
  for (const Eigen::Vector3d& p_D : positions) {
    DockLight light;
    light.id = id++;
    light.p_D = p_D;
    light.radius_m = 0.05;
    light.intensity = 1.0;
    dock.lights.push_back(light);
  }
  dock.deck_length_m = 3.0;
  dock.deck_width_m = 2.0;
  dock.deck_height_m = 0.5;
  return dock;
}

Pose3 LookAt(const Eigen::Vector3d& p_D_C, const Eigen::Vector3d& target_D) {
  const Eigen::Vector3d z_C = (target_D - p_D_C).normalized();
  Eigen::Vector3d down_hint = Eigen::Vector3d::UnitZ();
  if (std::abs(z_C.dot(down_hint)) > 0.99) down_hint = -Eigen::Vector3d::UnitX();
  const Eigen::Vector3d y_C = (down_hint - down_hint.dot(z_C) * z_C).normalized();
  const Eigen::Vector3d x_C = y_C.cross(z_C);
  Eigen::Matrix3d R_D_C;
  R_D_C << x_C, y_C, z_C;
  return Pose3(Eigen::Quaterniond(R_D_C), p_D_C);
}

Pose3 ApproachPose(double range_m, double depression_deg, const Eigen::Vector3d& target_D) {
  const double angle = depression_deg * kPi / 180.0;
  const Eigen::Vector3d offset(-range_m * std::cos(angle), 0.0, -range_m * std::sin(angle));
  return LookAt(target_D + offset, target_D);
}

}  // namespace auvdock::test
