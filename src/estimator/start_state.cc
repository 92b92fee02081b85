#include "auvdock/estimator/start_state.h"

#include <cmath>

#include <Eigen/Geometry>

#include "auvdock/io/yaml_config.h"

namespace auvdock {
namespace {

constexpr double kDegree = M_PI / 180.0;

double PositiveSigma(const ConfigNode& root, const std::string& key) {
  const double sigma = root.GetPositive(key);
  if (!std::isfinite(sigma)) root.Fail(key, "must be finite");
  return sigma;
}

}  // namespace

InitialState LoadStartState(const std::string& path) {
  const ConfigNode root = ConfigNode::LoadFile(path);
  InitialState start;
  start.t_ns = root.GetInt64("t_ns", 0);
  if (start.t_ns < 0) root.Fail("t_ns", "must not be negative");
  const Eigen::Vector3d p_D = root.GetVector<3>("p_D");
  const Eigen::Vector3d rpy = root.GetVector<3>("rpy_deg") * kDegree;
  start.v_D = root.GetVector<3>("v_D", Eigen::Vector3d::Zero());
  if (!p_D.allFinite()) root.Fail("p_D", "must be finite");
  if (!rpy.allFinite()) root.Fail("rpy_deg", "must be finite");
  if (!start.v_D.allFinite()) root.Fail("v_D", "must be finite");
  const Eigen::Quaterniond q_D_B = Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) *
                                   Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) *
                                   Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX());
  start.T_D_B = Pose3(q_D_B.normalized(), p_D);
  const double position = PositiveSigma(root, "position_sigma_m");
  const double tilt = PositiveSigma(root, "tilt_sigma_deg") * kDegree;
  const double heading = PositiveSigma(root, "heading_sigma_deg") * kDegree;
  const double velocity = PositiveSigma(root, "velocity_sigma_mps");
  start.pose_covariance.setZero();
  start.pose_covariance.diagonal() << position * position, position * position, position * position,
      tilt * tilt, tilt * tilt, heading * heading;
  start.velocity_covariance = Eigen::Matrix3d::Identity() * velocity * velocity;
  start.heading_sigma_rad = heading;
  start.heading_measured = true;
  root.CheckNoUnknownKeys();
  return start;
}

}  // namespace auvdock
