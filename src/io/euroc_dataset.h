// Loading of a real EuRoC/ASL sequence folder (mav0/): cam*/sensor.yaml, imu0/sensor.yaml,
// state_groundtruth_estimate0/. Private to src/io; LoadDataset() dispatches here.
//
// EuRoC's sensor.yaml gives T_BS as {rows: 4, cols: 4, data: [16 values]}, intrinsics
// [fu, fv, cu, cv], distortion [k1, k2, p1, p2], and the IMU noise densities under the same
// names auvdock uses. EuRoC's body frame is its IMU frame, as in auvdock. EuRoC cameras get the
// role stereo_left (cam0) and stereo_right (cam1), as in the MAV's VI-sensor.
#pragma once

#include <string>
#include <vector>

#include "auvdock/io/dataset.h"

namespace auvdock::internal {

// mav_dir is the ".../mav0" folder.
Dataset LoadEurocDataset(const std::string& mav_dir, std::vector<std::string>* skipped_rows);

}  // namespace auvdock::internal
