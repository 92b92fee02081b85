// Cost of labelling the detected guide lights of one frame: the default dock (T, 6 lights) seen
// by the default mono camera (640x512, 70 deg HFOV) from 64 random views at 2-8 m (camera roll
// and pitch within +-60 deg of straight down, any yaw), 0.3 px centroid noise. Each iteration
// matches one frame, cycling through the views. Budget: dehaze + detect + match + pose <= 5 ms
// per 640x512 frame on one core, so matching should stay well under ~2 ms.
#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "auvdock/geometry/so3.h"
#include "auvdock/sim/scenario.h"
#include "auvdock/vision/hungarian.h"
#include "auvdock/vision/omnidirectional_matcher.h"
#include "auvdock/vision/ransac_matcher.h"
#include "auvdock/vision/tracking_matcher.h"

namespace auvdock {
namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;

struct Frame {
  Pose3 T_C_D;
  Pose3 predicted_T_C_D;  // off by 2 cm / 1 deg
  std::vector<LightDetection> detections;
};

struct Setup {
  DockModel dock;
  PinholeRadtanCamera camera;
};

const Setup& DefaultSetup() {
  static const Setup setup = [] {
    const Scenario scenario =
        LoadScenario(std::string(AUVDOCK_SOURCE_DIR) + "/data/scenarios/default.yaml");
    return Setup{scenario.dock, MakeCalibration(scenario).FindCamera("cam2")->intrinsics};
  }();
  return setup;
}

Pose3 RandomView(const Setup& s, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> yaw(0.0, 360.0 * kDeg);
  std::uniform_real_distribution<double> tilt(-60.0 * kDeg, 60.0 * kDeg);
  std::uniform_real_distribution<double> distance(2.0, 8.0);
  std::uniform_real_distribution<double> offset(-0.3, 0.3);
  Eigen::Matrix3d R_D_down;  // camera looking down
  R_D_down << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  for (;;) {
    const Eigen::Matrix3d R_D_C =
        QuaternionFromRollPitchYaw(tilt(rng), tilt(rng), yaw(rng)).toRotationMatrix() * R_D_down;
    const Eigen::Vector3d p_D_C =
        Eigen::Vector3d(offset(rng), offset(rng), 0.0) - distance(rng) * R_D_C.col(2);
    const Pose3 T_C_D = Pose3(Eigen::Quaterniond(R_D_C), p_D_C).Inverse();
    bool all_in = true;
    for (const DockLight& light : s.dock.lights) {
      const auto uv = s.camera.Project(T_C_D * light.p_D);
      all_in = all_in && uv && s.camera.InImage(*uv, 5.0);
    }
    if (all_in) return T_C_D;
  }
}

// 64 frames with num_visible random lights and num_spurious random pixels, shuffled.
std::vector<Frame> MakeFrames(int num_visible, int num_spurious) {
  const Setup& s = DefaultSetup();
  std::mt19937_64 rng(1234 + 10 * num_visible + num_spurious);
  std::normal_distribution<double> noise(0.0, 0.3), normal(0.0, 1.0);
  std::uniform_real_distribution<double> u(0.0, s.camera.width() - 1.0);
  std::uniform_real_distribution<double> v(0.0, s.camera.height() - 1.0);
  std::vector<Frame> frames;
  for (int f = 0; f < 64; ++f) {
    Frame frame;
    frame.T_C_D = RandomView(s, rng);
    std::vector<int> order(s.dock.lights.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
    std::shuffle(order.begin(), order.end(), rng);
    for (int k = 0; k < num_visible; ++k) {
      LightDetection d;
      d.uv = *s.camera.Project(frame.T_C_D * s.dock.lights[order[k]].p_D) +
             Eigen::Vector2d(noise(rng), noise(rng));
      d.score = 1.0;
      frame.detections.push_back(d);
    }
    for (int k = 0; k < num_spurious; ++k) {
      LightDetection d;
      d.uv = Eigen::Vector2d(u(rng), v(rng));
      d.score = 1.0;  // as confident as the real lights: the worst case for the search order
      frame.detections.push_back(d);
    }
    std::shuffle(frame.detections.begin(), frame.detections.end(), rng);
    Pose3 T_D_C = frame.T_C_D.Inverse();
    T_D_C.p += 0.02 * Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
    T_D_C.q = ExpQuaternion(1.0 * kDeg *
                            Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized()) *
              T_D_C.q;
    frame.predicted_T_C_D = T_D_C.Inverse();
    frames.push_back(frame);
  }
  return frames;
}

void BM_MatchOmnidirectional(benchmark::State& state) {
  const Setup& s = DefaultSetup();
  const std::vector<Frame> frames = MakeFrames(6, 0);
  size_t i = 0;
  for (auto _ : state) {
    MatchResult result = MatchOmnidirectional(frames[i++ % frames.size()].detections, s.dock);
    benchmark::DoNotOptimize(result);
  }
}
BENCHMARK(BM_MatchOmnidirectional)->Unit(benchmark::kMicrosecond);

// Arguments: visible lights, spurious detections.
void BM_MatchRansac(benchmark::State& state) {
  const Setup& s = DefaultSetup();
  const std::vector<Frame> frames =
      MakeFrames(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  const RansacMatcherOptions options;
  std::mt19937_64 rng(7);
  size_t i = 0;
  double p3p = 0.0;
  for (auto _ : state) {
    RansacMatchResult result =
        MatchRansac(frames[i++ % frames.size()].detections, s.dock, s.camera, options, rng);
    p3p += result.num_p3p;
    benchmark::DoNotOptimize(result);
  }
  state.counters["p3p_per_frame"] = p3p / static_cast<double>(state.iterations());
}
BENCHMARK(BM_MatchRansac)
    ->ArgNames({"visible", "spurious"})
    ->Args({6, 0})
    ->Args({4, 2})
    ->Args({6, 2})
    ->Unit(benchmark::kMicrosecond);

void BM_MatchByPrediction(benchmark::State& state) {
  const Setup& s = DefaultSetup();
  const std::vector<Frame> frames = MakeFrames(6, 0);
  size_t i = 0;
  for (auto _ : state) {
    const Frame& frame = frames[i++ % frames.size()];
    MatchResult result =
        MatchByPrediction(frame.detections, s.dock, s.camera, frame.predicted_T_C_D, 20.0);
    benchmark::DoNotOptimize(result);
  }
}
BENCHMARK(BM_MatchByPrediction)->Unit(benchmark::kMicrosecond);

void BM_SolveAssignment(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> value(0.0, 100.0);
  Eigen::MatrixXd cost(n, n + 2);
  for (int r = 0; r < cost.rows(); ++r) {
    for (int c = 0; c < cost.cols(); ++c) cost(r, c) = value(rng);
  }
  for (auto _ : state) {
    std::vector<int> assignment = SolveAssignment(cost);
    benchmark::DoNotOptimize(assignment);
  }
}
BENCHMARK(BM_SolveAssignment)->Arg(6)->Arg(30)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace auvdock
