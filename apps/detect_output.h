// What `auvdock detect` writes per image, kept in memory so that the walks of the end of the run
// (two_way_light_bridge.h) can revise it:
//   detections.csv  frame,image,light_id,u,v,radius,score,cov_uu,cov_uv,cov_vv,at_border
//   frames.csv      frame,image,detections,identified,status,tracked,rms_px,sigma_px,
//                   tx,ty,tz,qx,qy,qz,qw (T_C_D, empty without a pose),symmetry,reason
//   camera_poses.tum  T_D_C per frame with a pose, time = frame / rate_hz
//   camera_pose_covariance.csv  that pose's covariance (io/pose_covariance_csv.h)
//   rejected.csv    (with the overlay) frame,image,u,v,sigma,reason of every rejected candidate
// Each frame is written as it is processed (flushed: a stopped run keeps it), and all of them are
// written anew by Rewrite, each file to a temporary that is then renamed over the old one.
#pragma once

#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "auvdock/geometry/pose3.h"
#include "auvdock/io/csv.h"
#include "auvdock/vision/blob_light_detector.h"
#include "auvdock/vision/light_detection.h"

namespace auvdock::cli {

struct FrameRecord {
  int index = 0;
  double time_s = 0.0;  // frame / rate_hz
  std::string path, name;
  std::vector<LightDetection> detections;
  std::vector<int> light_ids;  // per detection
  std::string status;          // "ok" with a pose, else the match status or "refuted"
  bool tracked = false;
  std::optional<Pose3> T_C_D;
  Eigen::Matrix<double, 6, 6> covariance_local = Eigen::Matrix<double, 6, 6>::Zero();
  double rms_px = 0.0, pixel_sigma_px = 0.0;
  double residual_sigma_px = 0.0;  // the pose's residual per axis, a posteriori
  std::string symmetry, reason;    // without commas
  std::vector<RejectedLightCandidate> rejected;  // kept with the overlay only
  // The candidates rejected on appearance alone (RejectedLightCandidate::overrulable) and the
  // image's saturated discs (FindSaturatedDiscs), as detections with their covariance: a walk may
  // find a light there (two_way_light_bridge.h).
  std::vector<LightDetection> doubtful;
  std::string no_pose_class;  // why a frame has no pose, as counted: ReasonClass, or refuted
};

class DetectOutput {
 public:
  // Creates the files in out (which must exist); rejected.csv with overlay only.
  DetectOutput(const std::string& out, bool overlay);

  void Write(const FrameRecord& record);
  void Rewrite(const std::vector<FrameRecord>& records);

 private:
  struct Files {
    CsvWriter detections, frames, rejected, pose_covariance;
    std::ofstream poses;
  };
  void Open(const std::string& suffix, Files* files) const;
  void Write(const FrameRecord& record, Files* files) const;

  std::string out_;
  bool overlay_;
  Files files_;
};

}  // namespace auvdock::cli
