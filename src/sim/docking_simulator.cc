#include "auvdock/sim/docking_simulator.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <limits>
#include <optional>
#include <thread>

#include "auvdock/io/csv.h"
#include "auvdock/io/dataset_writer.h"
#include "auvdock/sim/acoustic_simulator.h"
#include "auvdock/sim/sbl_simulator.h"
#include "auvdock/sim/depth_simulator.h"
#include "auvdock/sim/heading_simulator.h"
#include "auvdock/sim/dvl_simulator.h"
#include "auvdock/sim/imu_simulator.h"
#include "auvdock/sim/random_stream.h"
#include "auvdock/sim/synthetic_detections.h"

namespace auvdock {

DockingSimulator::DockingSimulator(const Scenario& scenario)
    : scenario_(scenario),
      calibration_(MakeCalibration(scenario)),
      trajectory_(scenario.trajectory) {
  const WaterModel water = WaterModel::ForType(scenario.water_type);
  RenderOptions render = scenario.render;
  if (!scenario.noise_enabled) render.noise_sigma = 0.0;  // a noise-free run has clean images
  for (std::size_t i = 0; i < calibration_.cameras.size(); ++i) {
    std::mt19937_64 look_rng =
        MakeRandomStream(scenario.seed, static_cast<uint64_t>(RandomStreamId::kRenderLookBase) + i);
    renderers_.emplace_back(calibration_.cameras[i], scenario.dock, water, render,
                            DrawRenderLook(scenario.randomize, scenario.dock, look_rng));
  }
}

int64_t DockingSimulator::SampleTime(int64_t k, double rate_hz) const {
  return scenario_.start_time_ns + std::llround(static_cast<double>(k) * 1e9 / rate_hz);
}

double DockingSimulator::Seconds(int64_t t_ns) const {
  return static_cast<double>(t_ns - scenario_.start_time_ns) * 1e-9;
}

Pose3 DockingSimulator::CameraPose(const CameraCalibration& camera, int64_t t_ns) const {
  return trajectory_.At(Seconds(t_ns)).T_D_B * camera.T_B_C;
}

VisibilityRecord DockingSimulator::VisibilityAt(int64_t t_ns) const {
  VisibilityRecord r;
  r.t_ns = t_ns;
  const Pose3 T_D_B = trajectory_.At(Seconds(t_ns)).T_D_B;
  for (std::size_t i = 0; i < calibration_.cameras.size(); ++i) {
    const auto& cam = calibration_.cameras[i];
    const int n = static_cast<int>(renderers_[i].VisibleLights(T_D_B * cam.T_B_C).size());
    if (cam.role == CameraRole::kStereoLeft) r.n_stereo_left = n;
    if (cam.role == CameraRole::kStereoRight) r.n_stereo_right = n;
    if (cam.role == CameraRole::kMono) r.n_mono = n;
  }
  r.stage = StageFromLightCounts(r.n_stereo_left, r.n_stereo_right, r.n_mono);
  return r;
}

namespace {

// Number of samples of a sensor at rate_hz within [0, duration_s].
int64_t SampleCount(double duration_s, double rate_hz) {
  return static_cast<int64_t>(std::floor(duration_s * rate_hz + 1e-9)) + 1;
}

std::string DistractorDetail(const RenderedDistractor& d) {
  return "u=" + FormatDouble(std::round(d.uv.x() * 100) / 100) +
         ";v=" + FormatDouble(std::round(d.uv.y() * 100) / 100) +
         ";sigma_px=" + FormatDouble(std::round(d.radius_px * 100) / 100);
}

}  // namespace

SimulationSummary DockingSimulator::Run(const std::string& dir, const CancellationToken& cancel,
                                        const std::function<void(double)>& progress,
                                        int render_workers) const {
  const Scenario& s = scenario_;
  const bool noisy = s.noise_enabled;
  const Eigen::Vector3d& g_D = s.dock.gravity_D;
  DatasetWriter writer(dir, calibration_, s.dock);

  ImuSimulator imu(s.imu, g_D, s.initial_gyro_bias, s.initial_accel_bias, noisy,
                   MakeRandomStream(s.seed, RandomStreamId::kImu), s.imu_errors);
  DepthSimulator depth(s.depth, s.depth_faults, s.dock, noisy,
                       MakeRandomStream(s.seed, RandomStreamId::kDepth));
  DvlSimulator dvl(s.dvl, s.dvl_faults, noisy, MakeRandomStream(s.seed, RandomStreamId::kDvl));
  AcousticSimulator acoustic(s.acoustic, s.dock, s.acoustic_faults, noisy,
                             MakeRandomStream(s.seed, RandomStreamId::kAcoustic));
  std::optional<HeadingSimulator> heading;
  if (s.heading) {
    heading.emplace(*s.heading, s.dock, noisy, MakeRandomStream(s.seed, RandomStreamId::kHeading));
  }
  std::optional<SblSimulator> sbl;
  if (s.sbl) {
    sbl.emplace(*s.sbl, s.dock, s.sbl_faults, noisy, MakeRandomStream(s.seed, RandomStreamId::kSbl));
  }
  std::vector<SyntheticDetector> detectors;  // without images: each camera's front-end
  if (!s.cameras.render_images) {
    for (std::size_t i = 0; i < calibration_.cameras.size(); ++i) {
      detectors.emplace_back(
          s.cameras.synthetic_detections, calibration_.cameras[i], s.dock, noisy,
          MakeRandomStream(s.seed, static_cast<uint64_t>(RandomStreamId::kSyntheticDetectionsBase) +
                                       static_cast<uint64_t>(i)));
    }
  }
  SimulationSummary summary;
  const int64_t n_imu = SampleCount(s.duration_s, s.imu.rate_hz);
  const int64_t n_depth = SampleCount(s.duration_s, s.depth.rate_hz);
  const int64_t n_dvl = SampleCount(s.duration_s, s.dvl.rate_hz);
  const int64_t n_acoustic = SampleCount(s.duration_s, s.acoustic.rate_hz);
  const int64_t n_sbl = s.sbl ? SampleCount(s.duration_s, s.sbl->rate_hz) : 0;
  const int64_t n_heading = s.heading ? SampleCount(s.duration_s, s.heading->rate_hz) : 0;
  const int64_t n_frames = SampleCount(s.duration_s, s.cameras.rate_hz);
  int64_t k_imu = 0, k_depth = 0, k_dvl = 0, k_acoustic = 0, k_sbl = 0, k_heading = 0;

  auto record_fault = [&](const std::optional<FaultRecord>& fault) {
    if (fault) {
      writer.AddFault(*fault);
      ++summary.n_faults;
    }
  };
  // Emits every non-camera sample with timestamp <= t_end_ns, in time order per sensor.
  auto emit_until = [&](int64_t t_end_ns) {
    for (; k_imu < n_imu && SampleTime(k_imu, s.imu.rate_hz) <= t_end_ns; ++k_imu) {
      const int64_t t = SampleTime(k_imu, s.imu.rate_hz);
      const KinematicState state = trajectory_.At(Seconds(t));
      std::optional<FaultRecord> fault;
      writer.AddImu(imu.Sample(t, state, &fault));
      record_fault(fault);
      writer.AddGroundTruth({t, state.T_D_B, state.v_D, imu.gyro_bias(), imu.accel_bias()});
      summary.max_speed_mps = std::max(summary.max_speed_mps, state.v_D.norm());
      ++summary.n_imu;
    }
    for (; k_depth < n_depth && SampleTime(k_depth, s.depth.rate_hz) <= t_end_ns; ++k_depth) {
      const int64_t t = SampleTime(k_depth, s.depth.rate_hz);
      std::optional<FaultRecord> fault;
      writer.AddDepth(depth.Sample(t, trajectory_.At(Seconds(t)), &fault));
      record_fault(fault);
      ++summary.n_depth;
    }
    for (; k_dvl < n_dvl && SampleTime(k_dvl, s.dvl.rate_hz) <= t_end_ns; ++k_dvl) {
      const int64_t t = SampleTime(k_dvl, s.dvl.rate_hz);
      std::optional<FaultRecord> fault;
      const std::optional<DvlMeasurement> sample =
          dvl.Sample(t, trajectory_.At(Seconds(t)), &fault);
      record_fault(fault);
      if (!sample) continue;  // no bottom lock: no sample
      writer.AddDvl(*sample);
      ++summary.n_dvl;
    }
    for (; k_heading < n_heading && SampleTime(k_heading, s.heading->rate_hz) <= t_end_ns;
         ++k_heading) {
      const int64_t t = SampleTime(k_heading, s.heading->rate_hz);
      writer.AddHeading(heading->Sample(t, trajectory_.At(Seconds(t))));
      ++summary.n_heading;
    }
    for (; k_acoustic < n_acoustic && SampleTime(k_acoustic, s.acoustic.rate_hz) <= t_end_ns;
         ++k_acoustic) {
      const int64_t t = SampleTime(k_acoustic, s.acoustic.rate_hz);
      std::optional<FaultRecord> fault;
      writer.AddAcoustic(acoustic.Sample(t, trajectory_.At(Seconds(t)), &fault));
      record_fault(fault);
      ++summary.n_acoustic;
    }
    for (; k_sbl < n_sbl && SampleTime(k_sbl, s.sbl->rate_hz) <= t_end_ns; ++k_sbl) {
      const int64_t t = SampleTime(k_sbl, s.sbl->rate_hz);
      std::vector<FaultRecord> faults;
      for (const SblRange& range : sbl->Ping(t, trajectory_.At(Seconds(t)), &faults)) {
        writer.AddSbl(range);
        ++summary.n_sbl_ranges;
      }
      for (const FaultRecord& fault : faults) record_fault(fault);
    }
  };

  const double frame_period_s = 1.0 / s.cameras.rate_hz;
  const int64_t mono_offset_ns = std::llround(s.cameras.mono_time_offset_s * 1e9);
  const size_t n_cameras = calibration_.cameras.size();
  // Each camera at its own exposure time (the mono camera may lag the stereo pair).
  auto camera_time = [&](int64_t k, size_t i) {
    const int64_t t = SampleTime(k, s.cameras.rate_hz);
    return calibration_.cameras[i].role == CameraRole::kMono ? t + mono_offset_ns : t;
  };
  auto camera_pose = [&](int64_t k, size_t i) {
    return trajectory_.At(Seconds(camera_time(k, i))).T_D_B * calibration_.cameras[i].T_B_C;
  };
  // The images are rendered a batch of frames at a time by up to one worker per processor, each
  // image from its own random stream (MakeImageRandomStream) into its own file: the output is
  // the same whatever the order and the number of threads. Then the frames' rows, truth and
  // faults are written in time order.
  const int workers = render_workers > 0
                          ? render_workers
                          : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  const int64_t batch_frames = s.cameras.render_images ? 2 * workers : 1;
  std::vector<RenderResult> images;
  for (int64_t k0 = 0; k0 < n_frames; k0 += batch_frames) {
    cancel.ThrowIfCancelled();
    const int64_t k1 = std::min(n_frames, k0 + batch_frames);
    if (s.cameras.render_images) {
      const int jobs = static_cast<int>((k1 - k0) * static_cast<int64_t>(n_cameras));
      images.assign(jobs, RenderResult{});
      std::vector<std::exception_ptr> failures(jobs);
      std::atomic<int> next{0};
      auto render = [&] {
        for (int j = next++; j < jobs; j = next++) {
          if (cancel.IsCancelled()) return;
          const int64_t k = k0 + j / static_cast<int>(n_cameras);
          const size_t i = static_cast<size_t>(j) % n_cameras;
          try {
            std::mt19937_64 rng =
                MakeImageRandomStream(s.seed, i, static_cast<uint64_t>(k));
            images[j] = renderers_[i].Render(camera_pose(k, i), rng);
            writer.WriteImageFile(calibration_.cameras[i].name, camera_time(k, i),
                                  images[j].image);
          } catch (...) {
            failures[j] = std::current_exception();
          }
        }
      };
      std::vector<std::thread> threads;
      for (int w = 1; w < std::min(workers, jobs); ++w) threads.emplace_back(render);
      render();
      for (std::thread& thread : threads) thread.join();
      cancel.ThrowIfCancelled();
      for (const std::exception_ptr& failure : failures) {
        if (failure) std::rethrow_exception(failure);  // the first image's failure, in order
      }
    }
    for (int64_t k = k0; k < k1; ++k) {
      cancel.ThrowIfCancelled();
      const int64_t t = SampleTime(k, s.cameras.rate_hz);
      emit_until(t);
      const VisibilityRecord visibility = VisibilityAt(t);
      writer.AddVisibility(visibility);
      summary.stage_duration_s[static_cast<int>(visibility.stage)] += frame_period_s;
      for (std::size_t i = 0; i < n_cameras; ++i) {
        const auto& cam = calibration_.cameras[i];
        const int64_t t_cam = camera_time(k, i);
        std::vector<RenderedLight> lights;
        if (s.cameras.render_images) {
          RenderResult& image = images[(k - k0) * static_cast<int64_t>(n_cameras) + i];
          writer.AddImageRow(cam.name, t_cam);
          lights = image.lights;
          for (const auto& d : image.distractors) {
            record_fault(FaultRecord{t_cam, cam.name, d.kind, DistractorDetail(d)});
          }
          image.image.release();
        } else {
          lights = renderers_[i].VisibleLights(camera_pose(k, i));
          std::vector<FaultRecord> faults;
          writer.AddDetections(detectors[i].Detect(t_cam, lights, &faults));
          for (const FaultRecord& f : faults) record_fault(f);
        }
        std::vector<LightTruth> truth;
        for (const RenderedLight& light : lights) {
          truth.push_back({light.light_id, light.uv, light.range_m, light.radius_px, light.peak});
        }
        writer.AddLightTruth(cam.name, t_cam, truth, cam.intrinsics.width(),
                             cam.intrinsics.height());
      }
      ++summary.n_camera_frames;
      if (progress) progress(static_cast<double>(k + 1) / static_cast<double>(n_frames));
    }
  }
  emit_until(std::numeric_limits<int64_t>::max());  // the tail after the last frame
  writer.Close();
  return summary;
}

}  // namespace auvdock
