// A docking run without images: the scenario's trajectory, its simulated IMU (noise and bias
// walk on) and, at every camera frame, the identified lights a perfect front-end would report
// with Gaussian pixel noise: mono pixels of the lights the mono camera sees, and stereo lights
// seen by both stereo cameras, triangulated from noisy pixels (with their covariance). The
// per-frame initial pose is the truth perturbed by a few centimetres / degrees when a camera
// system sees at least 3 lights. For estimator tests and NEES runs (fast: no rendering).
// With cameras.mono_time_offset_s, the mono pixels are those of the body pose that much later
// (VisionFrame::mono_dt_ns); the frame, the truth and the stereo points stay at the pair's time.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <vector>

#include "auvdock/estimator/sliding_window_estimator.h"
#include "auvdock/estimator/vision_frame.h"
#include "auvdock/geometry/stamped_pose.h"
#include "auvdock/io/calibration.h"
#include "auvdock/io/measurements.h"
#include "auvdock/sim/scenario.h"

namespace auvdock::test {

struct SyntheticRun {
  Calibration calibration;
  DockModel dock;
  std::vector<ImuSample> imu;
  std::vector<VisionFrame> frames;
  std::vector<StampedPose> truth;  // body pose at each frame
  std::vector<GroundTruthState> states;  // the whole state (biases too) at every IMU sample
  std::vector<DepthMeasurement> depth;  // the scenario's depth sensor (sim/depth_simulator.h)
  std::vector<DvlMeasurement> dvl;      // the scenario's DVL, gross errors included
  std::vector<FaultRecord> dvl_faults;  // its faults (sim/dvl_simulator.h)
  std::vector<HeadingMeasurement> heading;  // the scenario's AHRS, if it has one
};

SyntheticRun MakeSyntheticRun(const Scenario& scenario, uint64_t seed, double pixel_sigma = 0.3);

// Pixel errors that are not white, like the image pipeline's (README, "Vision noise"): white
// noise per light and frame plus a slowly varying offset common to all lights of one camera,
// a stationary AR(1) process per camera and pixel coordinate with 1-sigma correlated_px and
// autocorrelation exp(-|t| / correlation_time_s) (drawn from its own random stream, so the
// white draws are those of the overload above). The cameras' pixel_noise_px is white_px.
// light_bias_px: in addition, an offset per light and camera (1-sigma per pixel coordinate), as
// a light's asymmetric lobe gives, drawn from a third stream: constant, or, with
// view_dependent_bias, turned with the light's direction from the principal point (the offset's
// angle is its own plus that of (u - c_x, v - c_y)), so that it changes as the view does.
struct SyntheticPixelNoise {
  double white_px = 0.3;
  double correlated_px = 0.0;
  double correlation_time_s = 1.0;
  double light_bias_px = 0.0;
  bool view_dependent_bias = false;
};
SyntheticRun MakeSyntheticRun(const Scenario& scenario, uint64_t seed,
                              const SyntheticPixelNoise& noise);

// One acoustic fix of the transponder a second (the first 0.3 s in), with the calibration's
// range-dependent sigma as its Gaussian error and a latency drawn from [0, max_latency_s].
std::vector<AcousticFix> MakeAcousticFixes(const SyntheticRun& run, uint64_t seed,
                                           double max_latency_s = 0.0);

// Runs the sliding window over a run, frame by frame, feeding the IMU samples up to each frame
// (with_sensors: the depth and DVL samples too); returns the outputs by frame index.
std::map<size_t, EstimatorOutput> RunWindow(const SyntheticRun& run,
                                            SlidingWindowEstimator* estimator,
                                            bool with_sensors = false);

}  // namespace auvdock::test
