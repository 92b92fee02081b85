#include <map>
#include "tests/testing/synthetic_vision.h"

#include <cmath>
#include <random>

#include "auvdock/sim/depth_simulator.h"
#include "auvdock/sim/dvl_simulator.h"
#include "auvdock/sim/heading_simulator.h"
#include "auvdock/sim/docking_simulator.h"
#include "auvdock/sim/imu_simulator.h"
#include "auvdock/sim/random_stream.h"
#include "auvdock/vision/stereo_triangulation.h"

namespace auvdock::test {
namespace {

// The noisy pixel of a dock light in a camera, if the camera sees it (in front, in the image,
// within range, the camera above the light's deck so that the light faces it).
std::optional<Eigen::Vector2d> See(const CameraCalibration& camera, const Pose3& T_D_B,
                                   const Eigen::Vector3d& p_D, double sigma, std::mt19937_64& rng) {
  const Pose3 T_D_C = T_D_B * camera.T_B_C;
  if (T_D_C.p.z() >= p_D.z() || (T_D_C.p - p_D).norm() > 15.0) return std::nullopt;
  const Eigen::Vector3d p_C = T_D_C.Inverse() * p_D;
  if (p_C.z() < 0.3) return std::nullopt;
  const std::optional<Eigen::Vector2d> uv = camera.intrinsics.Project(p_C);
  if (!uv || !camera.intrinsics.InImage(*uv, 3.0)) return std::nullopt;
  const double nu = StandardNormal(rng), nv = StandardNormal(rng);
  return *uv + sigma * Eigen::Vector2d(nu, nv);
}

}  // namespace

SyntheticRun MakeSyntheticRun(const Scenario& scenario, uint64_t seed, double pixel_sigma) {
  SyntheticPixelNoise noise;
  noise.white_px = pixel_sigma;
  return MakeSyntheticRun(scenario, seed, noise);
}

SyntheticRun MakeSyntheticRun(const Scenario& scenario, uint64_t seed,
                              const SyntheticPixelNoise& noise) {
  const double pixel_sigma = noise.white_px;
  const DockingSimulator simulator(scenario);
  SyntheticRun run;
  run.calibration = simulator.calibration();
  run.dock = scenario.dock;
  const CameraCalibration* left = run.calibration.FindCameraByRole(CameraRole::kStereoLeft);
  const CameraCalibration* right = run.calibration.FindCameraByRole(CameraRole::kStereoRight);
  const CameraCalibration* mono = run.calibration.FindCameraByRole(CameraRole::kMono);
  for (CameraCalibration& camera : run.calibration.cameras) camera.pixel_noise_px = pixel_sigma;

  ImuSimulator imu(scenario.imu, scenario.dock.gravity_D, scenario.initial_gyro_bias,
                   scenario.initial_accel_bias, true, MakeRandomStream(seed, 101),
                   scenario.imu_errors);
  for (int64_t k = 0;; ++k) {
    const int64_t t = simulator.SampleTime(k, scenario.imu.rate_hz);
    if (simulator.Seconds(t) > scenario.duration_s) break;
    const KinematicState state = simulator.trajectory().At(simulator.Seconds(t));
    run.imu.push_back(imu.Sample(t, state));
    run.states.push_back({t, state.T_D_B, state.v_D, imu.gyro_bias(), imu.accel_bias()});
  }

  DepthSimulator depth(scenario.depth, scenario.depth_faults, scenario.dock, true,
                       MakeRandomStream(seed, 104));
  for (int64_t k = 0;; ++k) {
    const int64_t t = simulator.SampleTime(k, scenario.depth.rate_hz);
    if (simulator.Seconds(t) > scenario.duration_s) break;
    run.depth.push_back(depth.Sample(t, simulator.trajectory().At(simulator.Seconds(t))));
  }

  DvlSimulator dvl(scenario.dvl, scenario.dvl_faults, true, MakeRandomStream(seed, 105));
  for (int64_t k = 0;; ++k) {
    const int64_t t = simulator.SampleTime(k, scenario.dvl.rate_hz);
    if (simulator.Seconds(t) > scenario.duration_s) break;
    std::optional<FaultRecord> fault;
    const std::optional<DvlMeasurement> sample =
        dvl.Sample(t, simulator.trajectory().At(simulator.Seconds(t)), &fault);
    if (fault) run.dvl_faults.push_back(*fault);
    if (sample) run.dvl.push_back(*sample);
  }

  if (scenario.heading) {
    HeadingSimulator heading(*scenario.heading, scenario.dock, true, MakeRandomStream(seed, 106));
    for (int64_t k = 0;; ++k) {
      const int64_t t = simulator.SampleTime(k, scenario.heading->rate_hz);
      if (simulator.Seconds(t) > scenario.duration_s) break;
      run.heading.push_back(heading.Sample(t, simulator.trajectory().At(simulator.Seconds(t))));
    }
  }

  std::mt19937_64 rng = MakeRandomStream(seed, 102);
  const double rate = left ? left->rate_hz : mono->rate_hz;
  // Per-camera slow offsets (left, right, mono): stationary AR(1) at the frame interval.
  std::mt19937_64 offset_rng = MakeRandomStream(seed, 103);
  const double rho =
      noise.correlated_px > 0.0 ? std::exp(-1.0 / (rate * noise.correlation_time_s)) : 0.0;
  Eigen::Vector2d offset[3];
  for (Eigen::Vector2d& o : offset) {
    o = noise.correlated_px *
        Eigen::Vector2d(StandardNormal(offset_rng), StandardNormal(offset_rng));
  }
  // Per-light constant offsets (left, right, mono), by light id.
  std::mt19937_64 bias_rng = MakeRandomStream(seed, 107);
  std::map<int, Eigen::Vector2d> light_bias[3];
  for (std::map<int, Eigen::Vector2d>& camera : light_bias) {
    for (const DockLight& light : run.dock.lights) {
      camera[light.id] = noise.light_bias_px *
                         Eigen::Vector2d(StandardNormal(bias_rng), StandardNormal(bias_rng));
    }
  }
  // A light's offset in one camera where it is seen at uv.
  const auto bias = [&](int camera, const CameraCalibration& calibration, int light_id,
                        const Eigen::Vector2d& uv) -> Eigen::Vector2d {
    const Eigen::Vector2d& b = light_bias[camera][light_id];
    if (!noise.view_dependent_bias) return b;
    const PinholeRadtanCamera& k = calibration.intrinsics;
    const double angle = std::atan2(b.y(), b.x()) + std::atan2(uv.y() - k.cy(), uv.x() - k.cx());
    return b.norm() * Eigen::Vector2d(std::cos(angle), std::sin(angle));
  };
  for (int64_t k = 0;; ++k) {
    const int64_t t = simulator.SampleTime(k, rate);
    if (simulator.Seconds(t) > scenario.duration_s) break;
    const Pose3 T_D_B = simulator.trajectory().At(simulator.Seconds(t)).T_D_B;
    VisionFrame frame;
    frame.t_ns = t;
    if (k > 0) {
      const double innovation = noise.correlated_px * std::sqrt(1.0 - rho * rho);
      for (Eigen::Vector2d& o : offset) {
        o = rho * o +
            innovation * Eigen::Vector2d(StandardNormal(offset_rng), StandardNormal(offset_rng));
      }
    }
    // The mono camera's exposure may lag the stereo pair's (cameras.mono_time_offset_s).
    const int64_t mono_dt_ns =
        left ? std::llround(scenario.cameras.mono_time_offset_s * 1e9) : int64_t{0};
    const Pose3 T_D_B_mono =
        simulator.trajectory().At(simulator.Seconds(t + mono_dt_ns)).T_D_B;
    frame.mono_dt_ns = mono_dt_ns;
    for (const DockLight& light : run.dock.lights) {
      if (mono) {
        if (const auto uv = See(*mono, T_D_B_mono, light.p_D, pixel_sigma, rng)) {
          frame.mono.push_back(
              {light.id, *uv + offset[2] + bias(2, *mono, light.id, *uv), pixel_sigma});
        }
      }
      if (left && right) {
        const auto uv_left = See(*left, T_D_B, light.p_D, pixel_sigma, rng);
        const auto uv_right = See(*right, T_D_B, light.p_D, pixel_sigma, rng);
        if (uv_left && uv_right) {
          const TriangulatedPoint p =
              TriangulateLinear(*uv_left + offset[0] + bias(0, *left, light.id, *uv_left),
                                *uv_right + offset[1] + bias(1, *right, light.id, *uv_right),
                                *left, *right, pixel_sigma);
          if (p.ok) frame.stereo.push_back({light.id, p.p_S, p.covariance});
        }
      }
    }
    if (frame.mono.size() >= 3 || frame.stereo.size() >= 3) {
      const Eigen::Vector3d dp = 0.05 * StandardNormal3(rng);
      const Eigen::Vector3d dtheta = 0.02 * StandardNormal3(rng);
      const Eigen::Quaterniond dq(Eigen::AngleAxisd(dtheta.norm(), dtheta.normalized()));
      frame.T_D_B_initial = Pose3(dq * T_D_B.q, T_D_B.p + dp);
    }
    run.frames.push_back(frame);
    run.truth.push_back({t, T_D_B});
  }
  return run;
}

std::vector<AcousticFix> MakeAcousticFixes(const SyntheticRun& run, uint64_t seed,
                                           double max_latency_s) {
  const AcousticCalibration& acoustic = *run.calibration.acoustic;
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> unit(0.0, 1.0);
  std::uniform_real_distribution<double> latency(0.0, max_latency_s);
  std::vector<AcousticFix> fixes;
  for (size_t k = 3; k < run.truth.size(); k += 10) {
    AcousticFix fix;
    fix.t_ns = run.truth[k].t_ns;
    const Eigen::Vector3d p_T = run.truth[k].T_D_B * acoustic.T_B_S.p;
    fix.sigma_m = acoustic.sigma_min_m + acoustic.sigma_range_fraction * p_T.norm();
    fix.p_D = p_T + fix.sigma_m * Eigen::Vector3d(unit(rng), unit(rng), unit(rng));
    fix.latency_ns = static_cast<int64_t>(latency(rng) * 1e9);
    fixes.push_back(fix);
  }
  return fixes;
}

std::map<size_t, EstimatorOutput> RunWindow(const SyntheticRun& run,
                                            SlidingWindowEstimator* estimator,
                                            bool with_sensors) {
  std::map<size_t, EstimatorOutput> outputs;
  size_t next_imu = 0, next_depth = 0, next_dvl = 0;
  for (size_t k = 0; k < run.frames.size(); ++k) {
    const int64_t t = run.frames[k].t_ns;
    while (next_imu < run.imu.size() && run.imu[next_imu].t_ns <= t) {
      estimator->AddImu(run.imu[next_imu++]);
    }
    while (with_sensors && next_depth < run.depth.size() && run.depth[next_depth].t_ns <= t) {
      estimator->AddDepth(run.depth[next_depth++]);
    }
    while (with_sensors && next_dvl < run.dvl.size() && run.dvl[next_dvl].t_ns <= t) {
      estimator->AddDvl(run.dvl[next_dvl++]);
    }
    if (auto out = estimator->AddVisionFrame(run.frames[k])) outputs[k] = *out;
  }
  return outputs;
}

}  // namespace auvdock::test
