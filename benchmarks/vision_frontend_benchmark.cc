// Cost of the vision front-end's first two steps on one rendered camera frame: dark-channel
// dehazing (seed 000's enhancement) and guide-light detection. The frame is the default
// scenario's stereo-left camera 8 s into the run (all six lights in view at about 5 m, coastal
// water, reflections, particles and noise on), at the rig's 640 x 512 and at 1280 x 1024.
// Budget: dehaze + detect + match + pose <= 5 ms per 640 x 512 frame on one core, so detection
// (without dehazing) should stay near 2 ms. OpenCV runs single-threaded here, as on one core.
#include <random>
#include <stdexcept>
#include <string>

#include <benchmark/benchmark.h>
#include <opencv2/core.hpp>

#include "auvdock/sim/docking_trajectory.h"
#include "auvdock/sim/scenario.h"
#include "auvdock/sim/underwater_renderer.h"
#include "auvdock/vision/dark_channel_dehazer.h"
#include "auvdock/vision/light_detector.h"

namespace auvdock {
namespace {

// The default scenario's stereo-left frame at t = 8 s, rendered at width x height.
cv::Mat RenderFrame(int width, int height) {
  Scenario scenario = LoadScenario(std::string(AUVDOCK_SOURCE_DIR) + "/data/scenarios/default.yaml");
  scenario.cameras.width = width;
  scenario.cameras.height = height;
  const Calibration calibration = MakeCalibration(scenario);  // after the resolution change
  const CameraCalibration* camera = calibration.FindCameraByRole(CameraRole::kStereoLeft);
  if (camera == nullptr) throw std::runtime_error("no stereo-left camera in the default rig");
  const UnderwaterRenderer renderer(*camera, scenario.dock,
                                    WaterModel::ForType(scenario.water_type), scenario.render);
  const DockingTrajectory trajectory(scenario.trajectory);
  std::mt19937_64 rng(42);
  return renderer.Render(trajectory.At(8.0).T_D_B * camera->T_B_C, rng).image;
}

void BM_Dehaze(benchmark::State& state) {
  cv::setNumThreads(1);
  const cv::Mat frame = RenderFrame(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  const DarkChannelDehazer dehazer;  // seed 000: 15 px window, omega 0.5
  for (auto _ : state) {
    DarkChannelDehazer::Result result = dehazer.Dehaze(frame);
    benchmark::DoNotOptimize(result.image.data);
  }
  state.SetItemsProcessed(state.iterations() * frame.total());
}
BENCHMARK(BM_Dehaze)->Args({640, 512})->Args({1280, 1024})->Unit(benchmark::kMillisecond);

void BM_Detect(benchmark::State& state) {
  cv::setNumThreads(1);
  const cv::Mat frame = RenderFrame(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  const LightDetector detector;  // default options: no dehazing
  size_t lights = 0;
  for (auto _ : state) {
    const std::vector<LightDetection> detections = detector.Detect(frame);
    lights = detections.size();
    benchmark::DoNotOptimize(detections.data());
  }
  state.counters["lights"] = static_cast<double>(lights);
  state.SetItemsProcessed(state.iterations() * frame.total());
}
BENCHMARK(BM_Detect)->Args({640, 512})->Args({1280, 1024})->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace auvdock
