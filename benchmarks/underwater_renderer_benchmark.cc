// Rendering cost of one underwater frame (the simulator renders every camera frame): the dock
// seen from ~4 m, forward-down at 40 deg, coastal water, default options (noise, reflections and
// particles on). Target: <= ~15 ms for 640x512 on one core in Release.
#include <cmath>
#include <random>

#include <benchmark/benchmark.h>
#include <Eigen/Geometry>

#include "auvdock/sim/underwater_renderer.h"

namespace auvdock {
namespace {

constexpr double kPi = 3.14159265358979323846;

DockModel TDock() {
  DockModel dock;
  dock.name = "t_dock";
  const Eigen::Vector3d positions[] = {{-0.75, 0.0, -0.02}, {-0.25, 0.0, -0.02},
                                       {0.25, 0.0, -0.02},  {0.75, 0.0, -0.02},
                                       {0.75, -0.5, -0.02}, {0.75, 0.5, -0.02}};
  int id = 0;
  for (const Eigen::Vector3d& p_D : positions) {
    DockLight light;
    light.id = id++;
    light.p_D = p_D;
    dock.lights.push_back(light);
  }
  return dock;
}

// Camera 4 m from the dock centre, 40 deg below the horizontal, looking at it.
Pose3 ViewFromFourMetres() {
  const double depression = 40.0 * kPi / 180.0;
  const Eigen::Vector3d p_D_C(-4.0 * std::cos(depression), 0.0, -4.0 * std::sin(depression));
  const Eigen::Vector3d z_C = -p_D_C.normalized();
  const Eigen::Vector3d y_C =
      (Eigen::Vector3d::UnitZ() - Eigen::Vector3d::UnitZ().dot(z_C) * z_C).normalized();
  Eigen::Matrix3d R_D_C;
  R_D_C << y_C.cross(z_C), y_C, z_C;
  return Pose3(Eigen::Quaterniond(R_D_C), p_D_C);
}

void BM_RenderFrame(benchmark::State& state) {
  const int width = static_cast<int>(state.range(0));
  const int height = static_cast<int>(state.range(1));
  CameraCalibration camera;
  camera.intrinsics = PinholeRadtanCamera::FromHorizontalFov(width, height, 70.0 * kPi / 180.0,
                                                             {-0.05, 0.01, 0.0005, -0.0003, 0.0});
  const UnderwaterRenderer renderer(camera, TDock(), WaterModel::ForType(WaterType::kCoastal),
                                    RenderOptions());
  const Pose3 T_D_C = ViewFromFourMetres();
  std::mt19937_64 rng(42);
  for (auto _ : state) {
    RenderResult result = renderer.Render(T_D_C, rng);
    benchmark::DoNotOptimize(result.image.data);
  }
  state.SetItemsProcessed(state.iterations() * width * height);
}
BENCHMARK(BM_RenderFrame)->Args({640, 512})->Args({1280, 1024})->Unit(benchmark::kMillisecond);

// Geometric visibility only (what the simulator's visibility stages call per frame).
void BM_VisibleLights(benchmark::State& state) {
  CameraCalibration camera;
  camera.intrinsics = PinholeRadtanCamera::FromHorizontalFov(640, 512, 70.0 * kPi / 180.0,
                                                             {-0.05, 0.01, 0.0005, -0.0003, 0.0});
  const UnderwaterRenderer renderer(camera, TDock(), WaterModel::ForType(WaterType::kCoastal),
                                    RenderOptions());
  const Pose3 T_D_C = ViewFromFourMetres();
  for (auto _ : state) benchmark::DoNotOptimize(renderer.VisibleLights(T_D_C));
}
BENCHMARK(BM_VisibleLights);

}  // namespace
}  // namespace auvdock
