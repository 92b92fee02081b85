#include "apps/detect_output.h"

#include <cmath>
#include <cstdio>
#include <filesystem>

#include "auvdock/io/pose_covariance_csv.h"
#include "auvdock/vision/pnp_solver.h"

namespace fs = std::filesystem;

namespace auvdock::cli {
namespace {

constexpr const char* kFiles[] = {"/detections.csv", "/frames.csv", "/rejected.csv",
                                  "/camera_poses.tum", "/camera_pose_covariance.csv"};

}  // namespace

DetectOutput::DetectOutput(const std::string& out, bool overlay) : out_(out), overlay_(overlay) {
  Open("", &files_);
}

void DetectOutput::Open(const std::string& suffix, Files* files) const {
  files->detections =
      CsvWriter(out_ + "/detections.csv" + suffix,
                "frame,image,light_id,u,v,radius,score,cov_uu,cov_uv,cov_vv,at_border");
  files->frames = CsvWriter(out_ + "/frames.csv" + suffix,
                            "frame,image,detections,identified,status,tracked,rms_px,sigma_px,tx,"
                            "ty,tz,qx,qy,qz,qw,symmetry,reason");
  if (overlay_) {
    files->rejected = CsvWriter(out_ + "/rejected.csv" + suffix, "frame,image,u,v,sigma,reason");
  }
  files->pose_covariance =
      CsvWriter(out_ + "/camera_pose_covariance.csv" + suffix, PoseCovarianceCsvHeader());
  files->poses.open(out_ + "/camera_poses.tum" + suffix);
  files->poses << "# timestamp tx ty tz qx qy qz qw (T_D_C: the camera in the dock frame)\n";
}

void DetectOutput::Write(const FrameRecord& record) { Write(record, &files_); }

void DetectOutput::Write(const FrameRecord& r, Files* files) const {
  const std::string head = std::to_string(r.index) + "," + r.name + ",";
  int identified = 0;
  for (size_t i = 0; i < r.detections.size(); ++i) {
    const LightDetection& d = r.detections[i];
    identified += r.light_ids[i] >= 0;
    files->detections.Line(head + std::to_string(r.light_ids[i]) + "," + FormatDouble(d.uv.x()) +
                           "," + FormatDouble(d.uv.y()) + "," + FormatDouble(d.radius_px) + "," +
                           FormatDouble(d.score) + "," + FormatDouble(d.covariance(0, 0)) + "," +
                           FormatDouble(d.covariance(0, 1)) + "," +
                           FormatDouble(d.covariance(1, 1)) + "," + (d.at_border ? "1" : "0"));
  }
  std::string row = head + std::to_string(r.detections.size()) + "," +
                    std::to_string(identified) + "," + r.status + "," + (r.tracked ? "1" : "0") +
                    ",";
  if (r.T_C_D) {
    const Pose3& T = *r.T_C_D;
    row += FormatDouble(r.rms_px) + "," + FormatDouble(r.pixel_sigma_px) + "," +
           FormatDouble(T.p.x()) + "," + FormatDouble(T.p.y()) + "," + FormatDouble(T.p.z()) + "," +
           FormatDouble(T.q.x()) + "," + FormatDouble(T.q.y()) + "," + FormatDouble(T.q.z()) + "," +
           FormatDouble(T.q.w());
    const Pose3 T_D_C = T.Inverse();
    char line[256];
    std::snprintf(line, sizeof(line), "%.6f %.9g %.9g %.9g %.9g %.9g %.9g %.9g\n", r.time_s,
                  T_D_C.p.x(), T_D_C.p.y(), T_D_C.p.z(), T_D_C.q.x(), T_D_C.q.y(), T_D_C.q.z(),
                  T_D_C.q.w());
    files->poses << line << std::flush;
    files->pose_covariance.Row(
        std::llround(1e9 * r.time_s),
        PoseCovarianceCsvValues(CameraInDockCovariance(T, r.covariance_local)));
  } else {
    row += ",,,,,,,,";
  }
  files->frames.Line(row + "," + r.symmetry + "," + r.reason);
  if (!overlay_) return;
  for (const RejectedLightCandidate& c : r.rejected) {
    files->rejected.Line(head + FormatDouble(c.uv.x()) + "," + FormatDouble(c.uv.y()) + "," +
                         FormatDouble(c.sigma_px) + "," + c.reason);
  }
}

void DetectOutput::Rewrite(const std::vector<FrameRecord>& records) {
  Files fresh;
  Open(".tmp", &fresh);
  for (const FrameRecord& r : records) Write(r, &fresh);
  for (Files* files : {&fresh, &files_}) {
    files->detections.Close();
    files->frames.Close();
    files->rejected.Close();
    files->pose_covariance.Close();
    files->poses.close();
  }
  for (const char* name : kFiles) {
    const std::string tmp = out_ + name + ".tmp";
    if (fs::exists(tmp)) fs::rename(tmp, out_ + name);
  }
}

}  // namespace auvdock::cli
