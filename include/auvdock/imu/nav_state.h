// Navigation state of the body (= IMU) frame B in the dock frame D: attitude q_D_B, position
// p_D_B (m) and velocity v_D (m/s).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace auvdock {

struct NavState {
  Eigen::Quaterniond q_D_B = Eigen::Quaterniond::Identity();
  Eigen::Vector3d p_D = Eigen::Vector3d::Zero();
  Eigen::Vector3d v_D = Eigen::Vector3d::Zero();
};

}  // namespace auvdock
