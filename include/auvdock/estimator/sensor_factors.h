// Adds the navigation sensors' samples (pressure depth, DVL) to a Ceres problem and gates them:
// shared by the sliding window and the batch smoother, as vision_factors.h is for the lights.
//
// A sample at time t attaches to the latest state at or before t (t_k): at t = t_k directly on
// the state's blocks; later, through the IMU's motion over t - t_k (ImuPoseShift,
// factors/time_shifted_factor.h), so every sample is used at its own time whatever the
// sensor's rate and clock, without a state of its own. A residual beyond its chi-square gate
// after a solve is removed, and counted; the sliding window also gives each a Huber loss
// (EstimatorOptions::sensor_huber_sigmas, wider than its lights'), so that one absurd sample (a
// depth of 1e9 m) cannot drag the window so far before its gate that every light is gated with
// it. The batch smoother, which gates with every measurement in, uses none (+infinity).
//   depth  factors/depth_factor.h  1 residual, on the pose (and the velocity when shifted)
//   DVL    factors/dvl_factor.h    3 residuals, on the pose and the velocity; the body rate from
//                                  the gyro held at t minus the state's gyro bias
//   USBL   factors/usbl_fix_factor.h  3 residuals, on the pose (and the velocity when shifted);
//                                  the fix's own sigma (range-dependent, from the sensor)
//   SBL    factors/sbl_range_factor.h  1 residual per range, on the pose (and the velocity
//                                  when shifted); the range's own sigma
//   heading factors/heading_factor.h  1 residual, on the pose's rotation (an AHRS or compass)
#pragma once

#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <ceres/problem.h>

#include "auvdock/estimator/rejection.h"
#include "auvdock/estimator/vision_factors.h"
#include "auvdock/geometry/dock_model.h"
#include "auvdock/io/calibration.h"
#include "auvdock/io/measurements.h"

namespace auvdock {

// huber_sigmas of a factor without a robust loss.
inline constexpr double kNoRobustLoss = std::numeric_limits<double>::infinity();

// The sample's residual on `state` (whose time is t_state_ns <= sample.t_ns); nothing when the
// sample is not finite or the IMU does not reach its time.
// variance_factor multiplies the configured variance (the adaptive estimate of the sensor's
// effective noise, adaptive_noise_scale.h). With the state's depth-offset block
// (StateBlocks::depth_offset) the residual carries the offset (factors/depth_offset_factor.h, on
// the pose, velocity and offset blocks; nothing without a velocity block).
std::optional<ceres::ResidualBlockId> AddDepthFactor(ceres::Problem* problem,
                                                     const DepthMeasurement& sample,
                                                     const DepthCalibration& calibration,
                                                     const DockModel& dock,
                                                     const StateBlocks& state, int64_t t_state_ns,
                                                     double variance_factor = 1.0,
                                                     double huber_sigmas = kNoRobustLoss);

// The same for a heading sample (an AHRS or compass; the dock's heading_rad as its reference).
std::optional<ceres::ResidualBlockId> AddHeadingFactor(ceres::Problem* problem,
                                                       const HeadingMeasurement& sample,
                                                       const HeadingCalibration& calibration,
                                                       const DockModel& dock,
                                                       const StateBlocks& state,
                                                       int64_t t_state_ns,
                                                       double huber_sigmas = kNoRobustLoss);

// The same for a DVL sample; nothing also when the IMU has no gyro sample at its time. A sample
// that is not finite (bottom lock lost) is no measurement.
// shift: the IMU's motion from the state to the sample when the caller has it already
// (ImuShiftFromState), else it is computed here. variance_factor multiplies the configured
// variance (the adaptive estimate of the DVL's effective noise, adaptive_noise_scale.h). With the
// state's DVL-bias block (StateBlocks::dvl_bias) the residual carries the bias (on the pose,
// velocity and bias blocks).
std::optional<ceres::ResidualBlockId> AddDvlFactor(ceres::Problem* problem,
                                                   const DvlMeasurement& sample,
                                                   const DvlCalibration& calibration,
                                                   const DockModel& dock,
                                                   const StateBlocks& state, int64_t t_state_ns,
                                                   const ImuPoseShift* shift = nullptr,
                                                   double variance_factor = 1.0,
                                                   double huber_sigmas = kNoRobustLoss);

// The same for an acoustic (USBL) fix of the transponder; nothing also when its sigma is not
// positive and finite. A fix may also be earlier than the state (it arrived after its time left
// the window): the IMU's motion is then applied backward (factors/time_shifted_factor.h).
std::optional<ceres::ResidualBlockId> AddUsblFactor(ceres::Problem* problem,
                                                    const AcousticFix& fix,
                                                    const AcousticCalibration& calibration,
                                                    const DockModel& dock,
                                                    const StateBlocks& state, int64_t t_state_ns,
                                                    double huber_sigmas = kNoRobustLoss);

// The same for one SBL range (the beacon at dock.p_D_beacon); nothing also when its transducer
// is not in the calibration or its sigma is not positive and finite. variance_factor multiplies
// the range's own variance (the adaptive estimate of the array's effective noise).
std::optional<ceres::ResidualBlockId> AddSblFactor(ceres::Problem* problem,
                                                   const SblRange& range,
                                                   const SblCalibration& calibration,
                                                   const DockModel& dock,
                                                   const StateBlocks& state, int64_t t_state_ns,
                                                   double variance_factor = 1.0,
                                                   double huber_sigmas = kNoRobustLoss);

// Why a sample cannot be a measurement whatever the state (empty when it can): a depth above
// the surface by more than 0.5 m (a pressure sensor reads slightly negative at the surface, a
// wave or a drifting zero; beyond that the sensor or its conversion is broken).
std::string ImplausibleDepth(const DepthMeasurement& sample);

// A DVL that repeats its previous reading exactly is stuck or holding a value (a real reading
// carries noise; a driver that holds the last ping while the DVL has no lock repeats it): the
// repeat is no new measurement. Check returns why a sample is rejected, or empty.
class HeldDvlReadingCheck {
 public:
  std::string Check(const DvlMeasurement& sample) {
    const bool repeat = has_previous_ && sample.v_S == previous_;
    previous_ = sample.v_S;
    has_previous_ = true;
    return repeat ? "identical to the previous sample (stuck or held reading)" : "";
  }

 private:
  bool has_previous_ = false;
  Eigen::Vector3d previous_ = Eigen::Vector3d::Zero();
};

// A sample's residual in the problem, with the sample's time (for rejections.csv).
struct SensorResidual {
  ceres::ResidualBlockId id = nullptr;
  int64_t t_ns = 0;
};

// Removes the residuals whose squared whitened norm exceeds gate_chi2 (0 = no gate) from the
// problem and from *residuals; returns how many, each also appended to *rejections (sensor:
// the sensor's name) when given.
int GateSensorResiduals(ceres::Problem* problem, double gate_chi2, const std::string& sensor,
                        std::vector<SensorResidual>* residuals,
                        std::vector<Rejection>* rejections = nullptr);

}  // namespace auvdock
