// Feeds a dataset's sensor streams into the sliding window in time order, as `run` and `smooth`
// both do: the IMU up to the time a prediction is asked for (causal: samples at or before it),
// and before each frame every stream (IMU, depth, DVL, heading, acoustic fixes, SBL ranges) up to the frame's last
// image (an acoustic fix by its arrival time, AcousticFix::arrival_t_ns).
#pragma once

#include <cstddef>
#include <cstdint>

#include "auvdock/estimator/sliding_window_estimator.h"
#include "auvdock/io/dataset.h"

namespace auvdock {

class SensorFeed {
 public:
  SensorFeed(const Dataset& dataset, SlidingWindowEstimator* estimator)
      : dataset_(dataset), estimator_(estimator) {}

  // The IMU samples at or before t_ns not yet fed.
  void FeedImuUpTo(int64_t t_ns) {
    while (next_imu_ < dataset_.imu.size() && dataset_.imu[next_imu_].t_ns <= t_ns) {
      estimator_->AddImu(dataset_.imu[next_imu_++]);
    }
  }

  // Every stream's samples at or before t_ns not yet fed.
  void FeedAllUpTo(int64_t t_ns) {
    FeedImuUpTo(t_ns);
    while (next_depth_ < dataset_.depth.size() && dataset_.depth[next_depth_].t_ns <= t_ns) {
      estimator_->AddDepth(dataset_.depth[next_depth_++]);
    }
    while (next_dvl_ < dataset_.dvl.size() && dataset_.dvl[next_dvl_].t_ns <= t_ns) {
      estimator_->AddDvl(dataset_.dvl[next_dvl_++]);
    }
    while (next_heading_ < dataset_.heading.size() &&
           dataset_.heading[next_heading_].t_ns <= t_ns) {
      estimator_->AddHeading(dataset_.heading[next_heading_++]);
    }
    // A fix is fed when it has arrived (its measurement time is earlier; the window attaches it
    // there), in measurement order: one that overtook an earlier fix waits for it.
    while (next_usbl_ < dataset_.acoustic.size() &&
           dataset_.acoustic[next_usbl_].arrival_t_ns() <= t_ns) {
      estimator_->AddUsbl(dataset_.acoustic[next_usbl_++]);
    }
    while (next_sbl_ < dataset_.sbl.size() && dataset_.sbl[next_sbl_].t_ns <= t_ns) {
      estimator_->AddSblRange(dataset_.sbl[next_sbl_++]);
    }
  }

 private:
  const Dataset& dataset_;
  SlidingWindowEstimator* estimator_;
  size_t next_imu_ = 0;
  size_t next_depth_ = 0;
  size_t next_dvl_ = 0;
  size_t next_heading_ = 0;
  size_t next_usbl_ = 0;
  size_t next_sbl_ = 0;
};

}  // namespace auvdock
