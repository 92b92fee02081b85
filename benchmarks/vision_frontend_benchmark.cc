// Cost of the vision front-end on rendered camera frames of the default scenario (coastal water,
// reflections, particles and noise on), at the rig's 640 x 512 and at 1280 x 1024:
//  * BM_Dehaze: dark-channel dehazing (seed 000's enhancement) of the stereo-left frame 8 s into
//    the run (all six lights at about 5 m);
//  * BM_DetectBlob: the real-water detector (BlobLightDetector, every command's default) on the
//    same frame;
//  * BM_DetectLearned: the learned detector (LearnedLightDetector with the shipped model,
//    data/models/light_net.onnx: the network at 320 x 256 and the core centroid) on the same
//    frame;
//  * BM_DetectBlobFixedLevels: the same without the clip level and the neck cut (for the ratio);
//  * BM_DetectBlobWithoutSurroundings: the same without the surroundings' colour test;
//  * BM_OpenCvSimpleBlobDetector: OpenCV's blob detector on the same frame, side by side;
//  * BM_FindSaturatedDiscs: `detect`'s search of the whole frame for saturated discs
//    (saturated_disc.h), per frame besides the detector, on the same frame and on the down-looking
//    camera's frame after touchdown (argument 1: one light's disc filling the image);
//  * BM_ImageLevels: its reading of the image's noise and clip level (image_levels.h);
//  * BM_PerFrame: the whole per-frame path of the paper's baseline (PaperBaselinePipeline::Process
//    with dehazing on): dehaze + detect + match (hypothesise-and-verify, MatchRansac) + pose.
//    Arguments width, height, camera, dehaze (1: on, as the budget counts; 0: the pipeline's
//    default). Camera 0 = the down-looking mono camera at t = 20 s (six
//    lights, pose by PnP), 1 = the stereo pair at t = 8 s (six lights in each image; two images
//    dehazed and detected, the left one matched, the right one labelled by prediction,
//    triangulation and SVD alignment). Counters: the same steps timed one by one on the same frame
//    (thread CPU ms): dehaze_ms and detect_ms per image, match_pose_ms for the rest
//    (PaperBaselinePipeline::ProcessDetections).
// Budget: dehaze + detect + match + pose <= 5 ms per 640 x 512 frame on one core (image decoding
// not counted). OpenCV runs single-threaded here, as on one core.
#include <ctime>
#include <optional>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>
#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "auvdock/sim/docking_trajectory.h"
#include "auvdock/sim/scenario.h"
#include "auvdock/sim/underwater_renderer.h"
#include "auvdock/vision/blob_light_detector.h"
#include "auvdock/vision/dark_channel_dehazer.h"
#include "auvdock/vision/image_levels.h"
#include "auvdock/vision/learned_light_detector.h"
#include "auvdock/vision/paper_baseline_pipeline.h"
#include "auvdock/vision/saturated_disc.h"

namespace auvdock {
namespace {

Scenario DefaultScenarioAt(int width, int height) {
  Scenario scenario =
      LoadScenario(std::string(AUVDOCK_SOURCE_DIR) + "/data/scenarios/default.yaml");
  scenario.cameras.width = width;
  scenario.cameras.height = height;
  return scenario;
}

// The default scenario's frame of the camera with `role` at t_s, rendered at width x height.
cv::Mat RenderFrame(int width, int height, CameraRole role = CameraRole::kStereoLeft,
                    double t_s = 8.0) {
  const Scenario scenario = DefaultScenarioAt(width, height);
  const Calibration calibration = MakeCalibration(scenario);  // after the resolution change
  const CameraCalibration* camera = calibration.FindCameraByRole(role);
  if (camera == nullptr) throw std::runtime_error("camera role missing from the default rig");
  const UnderwaterRenderer renderer(*camera, scenario.dock,
                                    WaterModel::ForType(scenario.water_type), scenario.render);
  const DockingTrajectory trajectory(scenario.trajectory);
  std::mt19937_64 rng(42);
  return renderer.Render(trajectory.At(t_s).T_D_B * camera->T_B_C, rng).image;
}

void BM_Dehaze(benchmark::State& state) {
  cv::setNumThreads(1);
  const cv::Mat frame =
      RenderFrame(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  const DarkChannelDehazer dehazer;  // seed 000: 15 px window, omega 0.5
  for (auto _ : state) {
    DarkChannelDehazer::Result result = dehazer.Dehaze(frame);
    benchmark::DoNotOptimize(result.image.data);
  }
  state.SetItemsProcessed(state.iterations() * frame.total());
}
BENCHMARK(BM_Dehaze)->Args({640, 512})->Args({1280, 1024})->Unit(benchmark::kMillisecond);

// Times detector.Detect on the stereo-left frame at the benchmark's resolution.
template <typename Detector>
void TimeDetection(const Detector& detector, benchmark::State& state) {
  cv::setNumThreads(1);
  const cv::Mat frame =
      RenderFrame(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  size_t lights = 0;
  for (auto _ : state) {
    const std::vector<LightDetection> detections = detector.Detect(frame);
    lights = detections.size();
    benchmark::DoNotOptimize(detections.data());
  }
  state.counters["lights"] = static_cast<double>(lights);
  state.SetItemsProcessed(state.iterations() * frame.total());
}


// The real-water detector (blob_light_detector.h) on the same frame, with the dock's colour.
void BM_DetectBlob(benchmark::State& state) {
  BlobLightDetectorOptions options;
  options.checks.colour = LightColour::kBlueGreen;
  TimeDetection(BlobLightDetector(options), state);
}
BENCHMARK(BM_DetectBlob)->Args({640, 512})->Args({1280, 1024})->Unit(benchmark::kMillisecond);

void BM_DetectLearned(benchmark::State& state) {
  LearnedLightDetectorOptions options;
  options.model_path = std::string(AUVDOCK_SOURCE_DIR) + "/data/models/light_net.onnx";
  options.colour = LightColour::kBlueGreen;
  TimeDetection(LearnedLightDetector(options), state);
}
BENCHMARK(BM_DetectLearned)->Args({640, 512})->Args({1280, 1024})->Unit(benchmark::kMillisecond);

void BM_FindSaturatedDiscs(benchmark::State& state) {
  const cv::Mat image =
      state.range(2) == 0
          ? RenderFrame(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)))
          : RenderFrame(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)),
                        CameraRole::kMono, 39.5);
  size_t found = 0;
  for (auto _ : state) {
    const std::vector<LightDetection> discs = FindSaturatedDiscs(image);
    found = discs.size();
    benchmark::DoNotOptimize(discs.data());
  }
  state.counters["discs"] = static_cast<double>(found);
}
BENCHMARK(BM_FindSaturatedDiscs)
    ->Args({640, 512, 0})
    ->Args({640, 512, 1})
    ->Unit(benchmark::kMillisecond);

// BM_DetectBlob without what adapts it to the exposure: no clip level, no neck cut (the detector
// as it was before them), for the ratio of the two in one run.
void BM_DetectBlobFixedLevels(benchmark::State& state) {
  BlobLightDetectorOptions options;
  options.checks.colour = LightColour::kBlueGreen;
  options.adapt_to_clip_level = false;
  options.core.neck_cut_sigmas = 0.0;
  TimeDetection(BlobLightDetector(options), state);
}
BENCHMARK(BM_DetectBlobFixedLevels)
    ->Args({640, 512})
    ->Args({1280, 1024})
    ->Unit(benchmark::kMillisecond);

// BM_DetectBlob without the surroundings' colour test (light_candidate_checks.h), for the ratio.
void BM_DetectBlobWithoutSurroundings(benchmark::State& state) {
  BlobLightDetectorOptions options;
  options.checks.colour = LightColour::kBlueGreen;
  options.checks.surroundings_halo_radii = 0.0;
  TimeDetection(BlobLightDetector(options), state);
}
BENCHMARK(BM_DetectBlobWithoutSurroundings)->Args({640, 512})->Unit(benchmark::kMillisecond);

// OpenCV's own building block on the same frame: cv::SimpleBlobDetector on the gray image,
// bright blobs of at least 3 px, no shape filters (it has no colour, halo or covariance).
void BM_OpenCvSimpleBlobDetector(benchmark::State& state) {
  cv::setNumThreads(1);
  const cv::Mat frame =
      RenderFrame(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  cv::SimpleBlobDetector::Params params;
  params.filterByColor = true;
  params.blobColor = 255;
  params.minThreshold = 50;
  params.maxThreshold = 255;
  params.thresholdStep = 10;
  params.filterByArea = true;
  params.minArea = 3;
  params.maxArea = 1e5;
  params.filterByCircularity = false;
  params.filterByInertia = false;
  params.filterByConvexity = false;
  const cv::Ptr<cv::SimpleBlobDetector> detector = cv::SimpleBlobDetector::create(params);
  size_t blobs = 0;
  for (auto _ : state) {
    cv::Mat gray;
    cv::cvtColor(frame, gray, cv::COLOR_BGR2GRAY);
    std::vector<cv::KeyPoint> keypoints;
    detector->detect(gray, keypoints);
    blobs = keypoints.size();
    benchmark::DoNotOptimize(keypoints.data());
  }
  state.counters["blobs"] = static_cast<double>(blobs);
}
BENCHMARK(BM_OpenCvSimpleBlobDetector)
    ->Args({640, 512})
    ->Args({1280, 1024})
    ->Unit(benchmark::kMillisecond);

// The part of BM_DetectBlob that reads the image's own levels (image_levels.h): its noise and
// clip level, on the same frame's luma.
void BM_ImageLevels(benchmark::State& state) {
  cv::setNumThreads(1);
  const cv::Mat frame =
      RenderFrame(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  cv::Mat gray, luma;
  cv::cvtColor(frame, gray, cv::COLOR_BGR2GRAY);
  gray.convertTo(luma, CV_32F);
  for (auto _ : state) {
    double noise = EstimatePixelNoise(luma);
    std::optional<double> clip = EstimateClipLevel(gray, frame);
    benchmark::DoNotOptimize(noise);
    benchmark::DoNotOptimize(clip);
  }
}
BENCHMARK(BM_ImageLevels)->Args({640, 512})->Args({1280, 1024})->Unit(benchmark::kMillisecond);

double ThreadCpuSeconds() {
  timespec now{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &now);
  return static_cast<double>(now.tv_sec) + 1e-9 * static_cast<double>(now.tv_nsec);
}

// Mean CPU time of this thread (ms; one core, whatever else the machine runs) of `step` over
// `repetitions` calls.
template <typename Step>
double MeanMilliseconds(int repetitions, Step step) {
  const double start = ThreadCpuSeconds();
  for (int i = 0; i < repetitions; ++i) step();
  return 1e3 * (ThreadCpuSeconds() - start) / repetitions;
}

void BM_PerFrame(benchmark::State& state) {
  cv::setNumThreads(1);
  const int width = static_cast<int>(state.range(0));
  const int height = static_cast<int>(state.range(1));
  const bool stereo = state.range(2) == 1;
  const double t_s = stereo ? 8.0 : 20.0;
  const int64_t t_ns = static_cast<int64_t>(t_s * 1e9);
  const Scenario scenario = DefaultScenarioAt(width, height);
  const Calibration calibration = MakeCalibration(scenario);
  const cv::Mat none;
  const cv::Mat left = stereo ? RenderFrame(width, height, CameraRole::kStereoLeft, t_s) : none;
  const cv::Mat right = stereo ? RenderFrame(width, height, CameraRole::kStereoRight, t_s) : none;
  const cv::Mat mono = stereo ? none : RenderFrame(width, height, CameraRole::kMono, t_s);
  PaperBaselineOptions options;
  options.dehaze = state.range(3) == 1;  // the budget counts it; off by default
  PaperBaselinePipeline pipeline(calibration, scenario.dock, options);

  BaselineFrame frame;
  for (auto _ : state) {
    frame = pipeline.Process(t_ns, left, right, mono);
    benchmark::DoNotOptimize(frame.T_D_B);
  }
  const int lights = stereo ? frame.n_stereo_lights : frame.n_mono_lights;
  if (!(stereo ? frame.T_D_B_stereo : frame.T_D_B_mono)) {
    state.SkipWithError(("no pose: " + frame.reason).c_str());
    return;
  }
  state.counters["lights"] = lights;

  // The same steps one by one, on one image of the frame (outside the timed loop).
  const cv::Mat& image = stereo ? left : mono;
  const DarkChannelDehazer dehazer(options.dehaze_options);
  BlobLightDetectorOptions blob_options = options.blob_detector;
  blob_options.checks.colour = ParseLightColour(scenario.dock.light_colour);
  const BlobLightDetector blob(blob_options);
  auto detect = [&](const cv::Mat& image) {
    return blob.Detect(options.dehaze ? dehazer.Dehaze(image).image : image);
  };
  constexpr int kRepetitions = 20;
  const double dehaze_ms = !options.dehaze ? 0.0 : MeanMilliseconds(kRepetitions, [&] {
    benchmark::DoNotOptimize(dehazer.Dehaze(image).image.data);
  });
  const double dehaze_detect_ms = MeanMilliseconds(
      kRepetitions, [&] { benchmark::DoNotOptimize(detect(image).data()); });
  std::optional<std::vector<LightDetection>> left_detections, right_detections, mono_detections;
  if (stereo) {
    left_detections = detect(left);
    right_detections = detect(right);
  } else {
    mono_detections = detect(mono);
  }
  const double match_pose_ms = MeanMilliseconds(kRepetitions, [&] {
    benchmark::DoNotOptimize(
        pipeline.ProcessDetections(t_ns, left_detections, right_detections, mono_detections));
  });
  state.counters["dehaze_ms"] = dehaze_ms;
  state.counters["detect_ms"] = dehaze_detect_ms - dehaze_ms;
  state.counters["match_pose_ms"] = match_pose_ms;
}
BENCHMARK(BM_PerFrame)
    ->ArgNames({"w", "h", "stereo", "dehaze"})
    ->Args({640, 512, 0, 1})
    ->Args({640, 512, 1, 1})
    ->Args({640, 512, 0, 0})
    ->Args({640, 512, 1, 0})
    ->Args({1280, 1024, 0, 1})
    ->Args({1280, 1024, 1, 1})
    ->Args({1280, 1024, 0, 0})
    ->Args({1280, 1024, 1, 0})
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace auvdock
