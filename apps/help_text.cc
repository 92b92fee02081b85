#include "apps/help_text.h"

#include <algorithm>
#include <filesystem>
#include <vector>

#include "apps/data_files.h"

namespace auvdock::cli {
namespace {

// "a.yaml, b.yaml" for the YAML files of a shipped folder ("" when it is not found).
std::string ListYaml(const std::string& folder) {
  const std::filesystem::path dir = DataDir();
  std::vector<std::string> names;
  std::error_code error;
  if (!dir.empty()) {
    for (const auto& entry : std::filesystem::directory_iterator(dir / folder, error)) {
      if (entry.path().extension() == ".yaml") names.push_back(entry.path().filename().string());
    }
  }
  std::sort(names.begin(), names.end());
  std::string list;
  for (const std::string& name : names) list += (list.empty() ? "" : ", ") + name;
  return list;
}

std::string Shipped(const std::string& what, const std::string& folder) {
  const std::string list = ListYaml(folder);
  return what + ": " + DataPath(folder) + "/" + (list.empty() ? "" : " (" + list + ")") + "\n";
}

const char* kEstimateFiles =
    "  trajectory.tum   T_D_B per frame with an estimate (TUM: t x y z qx qy qz qw)\n"
    "  covariance.csv   timestamp_ns + the 6x6 pose covariance, row-major, order dp_D (m),\n"
    "                   dtheta_D (rad): perturbations in the dock frame\n"
    "  decisions.csv    timestamp_ns, GO or NO-GO, reason (every frame)\n"
    "  rejections.csv   every measurement left out: timestamp_ns, sensor, statistic, reason\n"
    "  summary.json     counts, why frames had no vision, timing (written last)\n"
    "  estimate.csv     (--euroc-csv) the state in EuRoC's ground-truth columns\n";

}  // namespace

std::string SimulateHelp() {
  return "\nNeeds: a scenario (YAML: trajectory, dock, cameras, water, sensors, faults).\n" +
         Shipped("Shipped scenarios", "scenarios") +
         "Writes into --out a dataset folder (docs/dataset_format.md):\n"
         "  calibration.yaml, dock.yaml, imu0/ depth0/ dvl0/ usbl0/ (data.csv),\n"
         "  cam0/ cam1/ cam2/ (data.csv + data/*.png; with --detections-only: detections.csv),\n"
         "  groundtruth/ (data.csv, visibility.csv, faults.csv, <camera>_lights.csv),\n"
         "  groundtruth.tum\n"
         "Example: auvdock simulate --scenario " +
         DataPath("scenarios/default.yaml") + " --out out/sim\n";
}

std::string RunHelp() {
  return "\nNeeds: a dataset folder (from simulate, your log in that layout, or a EuRoC sequence)\n"
         "whose calibration has an IMU; its images, or --detections; a dock (the folder's\n"
         "dock.yaml, or --dock). Each output uses only data up to its own time. A log without\n"
         "cameras (IMU with DVL, depth, fixes, heading) gets a state at --state-rate-hz; the\n"
         "window starts from the lights, the fixes, or a state of yours (--start FILE).\n"
         "Writes into --out, flushed frame by frame (an interrupted run keeps what it wrote):\n" +
         std::string(kEstimateFiles) + Shipped("Estimator options (--config)", "estimator") +
         "Example: auvdock run --dataset out/sim --out out/run\n";
}

std::string SmoothHelp() {
  return "\nNeeds: what run needs (it runs first, as the warm start). Then every state of the\n"
         "log in one batch problem: each pose uses the data before and after it.\n"
         "Writes into --out the files of run, from the batch result:\n" +
         std::string(kEstimateFiles) + Shipped("Estimator options (--config)", "estimator") +
         "Example: auvdock smooth --dataset out/sim --out out/smooth\n";
}

std::string CrlbHelp() {
  return "\nNeeds: what smooth needs, and the ground truth (groundtruth/data.csv): the bound is\n"
         "the batch problem's information at the true states, with the configured noise\n"
         "models (--config), marginalised per pose. No unbiased estimator does better on\n"
         "average under those models.\n"
         "Writes --out FILE: the bound in the covariance.csv format (timestamp_ns + the 6x6\n"
         "covariance, row-major, dp_D (m), dtheta_D (rad)); evaluate --bound FILE sets an\n"
         "estimate's errors beside it.\n" +
         Shipped("Estimator options (--config)", "estimator") +
         "Example: auvdock crlb --dataset out/sim --out out/crlb.csv\n";
}

std::string FrontendHelp() {
  return "\nNeeds: a dataset folder with camera images and a dock (dock.yaml, or --dock).\n"
         "The paper's per-frame baseline: no IMU, no filter, each frame on its own.\n"
         "Writes into --out, frame by frame:\n"
         "  detections.csv       every light found (id -1: not identified); run --detections\n"
         "                       replays it\n"
         "  per_frame.tum        the fused body pose T_D_B; per_frame_stereo.tum (SVD) and\n"
         "                       per_frame_mono.tum (PnP) alone\n"
         "  stages.csv           visibility stage and lights per camera, and why there is no pose\n"
         "Example: auvdock frontend --dataset out/sim --out out/frontend\n";
}

std::string EvaluateHelp() {
  return "\nNeeds: a dataset with ground truth (groundtruth/data.csv) and an estimate (TUM);\n"
         "optionally its covariance.csv (NEES) and decisions.csv (the go/no-go audit).\n"
         "Prints a table (or --json): ATE/RPE, errors by visibility stage, NEES, unsafe GOs;\n"
         "with --plots DIR also trajectory.png, errors.png, stages.png, nees.png, go_no_go.png.\n"
         "Example: auvdock evaluate --dataset out/sim --estimate out/run/trajectory.tum "
         "--covariance out/run/covariance.csv --decisions out/run/decisions.csv\n";
}

std::string PnpHelp() {
  return "\nNeeds: a calibration and a CSV of correspondences (header X,Y,Z,u,v: model metres,\n"
         "raw distorted pixels; add cov_uu,cov_uv,cov_vv for each pixel's own covariance).\n"
         "Prints one JSON object: R, t, rvec, the 6x6 covariance (rvec then t; widened by the\n"
         "a-posteriori variance factor when the pixels fit worse than claimed), rms_px, chi2,\n"
         "dof, variance_factor, n_points, iterations (x_cam = R X + t).\n"
         "Example: auvdock pnp --calib out/sim/calibration.yaml --camera cam2 --points pts.csv\n";
}

std::string DetectHelp() {
  return "\nNeeds: your images (a glob) or a video file, a camera calibration (ours or OpenCV\n"
         "FileStorage) and a dock.yaml (the light layout, and its colour). " +
         Shipped("Shipped docks", "docks") +
         "Writes into --out: detections.csv (with identities), frames.csv (per image: status,\n"
         "pose, reason), camera_poses.tum (T_D_C), summary.json; with --overlay overlay/*.png\n"
         "and rejected.csv; with --labels, recall, precision and centroid RMS in summary.json.\n"
         "Images with too few lights for a pose are identified at the end from the posed images\n"
         "before and after them (--bridge; the files are then written anew).\n"
         "A video's frames are named frame_000000, frame_000001, ... (in the outputs and the\n"
         "labels) and timed by the file's time stamps.\n"
         "Example: auvdock detect --images \"frames/*.jpg\" --calib calib.yaml --dock dock.yaml "
         "--out out/detect --overlay\n"
         "         auvdock detect --video dive.mp4 --calib calib.yaml --dock dock.yaml --out "
         "out/detect\n";
}

std::string DemoHelp() {
  return "\nNeeds: nothing but this binary (the shipped default scenario), or --scenario.\n"
         "Runs simulate, then frontend, run, smooth and crlb on the result, evaluates the three\n"
         "against the truth and the bound and prints them side by side. Writes into --out:\n"
         "dataset/, frontend/, run/, smooth/ (each subcommand's own files), crlb.csv, plots/\n"
         "(run's), evaluation.json, demo.log (every step's messages).\n"
         "Example: auvdock demo --out out/demo\n";
}

}  // namespace auvdock::cli
