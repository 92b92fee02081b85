// auvdock pnp --calib CALIB.yaml [--camera NAME] --points CORR.csv
//
// Solves a camera pose from given 3-D/2-D correspondences and prints one JSON object:
//   R (3x3 row-major), t, rvec, covariance_6x6 (36 values row-major, order rvec_x rvec_y rvec_z
//   t_x t_y t_z), rms_px, n_points, iterations
// for the camera-from-model transform in OpenCV's convention: x_cam = R X + t.
// CORR.csv: a header row "X,Y,Z,u,v", then one correspondence per row (model metres, raw
// distorted pixels).
#include <iostream>
#include <memory>

#include <nlohmann/json.hpp>

#include "apps/cli_validators.h"
#include "apps/commands.h"
#include "apps/help_text.h"
#include "auvdock/geometry/so3.h"
#include "auvdock/io/camera_file.h"
#include "auvdock/io/csv.h"
#include "auvdock/io/input_error.h"
#include "auvdock/vision/pnp_solver.h"

namespace auvdock::cli {

namespace {

struct PnpCommandOptions {
  std::string calib;
  std::string camera;
  std::string points;
  double pixel_sigma = -1.0;  // default: the calibration's pixel_noise_px
};

void ReadCorrespondences(const std::string& path, std::vector<Eigen::Vector3d>* points,
                         std::vector<Eigen::Vector2d>* pixels) {
  CsvReader reader(path, {"X", "Y", "Z", "u", "v"});
  reader.ExpectNamedHeaderRow();
  while (reader.Next()) {
    points->emplace_back(reader.Double(0), reader.Double(1), reader.Double(2));
    pixels->emplace_back(reader.Double(3), reader.Double(4));
  }
  if (points->size() < 3) {
    throw InputError(path + ": " + std::to_string(points->size()) +
                     " correspondences; PnP needs at least 3 (4 for a unique pose)");
  }
}

void RunPnp(const PnpCommandOptions& options) {
  const CameraCalibration camera = LoadCameraCalibration(options.calib, options.camera);
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector2d> pixels;
  ReadCorrespondences(options.points, &points, &pixels);
  PnpOptions pnp;
  pnp.pixel_sigma = options.pixel_sigma > 0 ? options.pixel_sigma : camera.pixel_noise_px;
  const PnpResult result = SolvePnp(points, pixels, camera.intrinsics, pnp);
  if (!result.ok) throw InputError(options.points + ": no pose: " + result.reason);

  const Eigen::Matrix3d R = result.T_C_D.R();
  const Eigen::Vector3d rvec = LogQuaternion(result.T_C_D.q);
  nlohmann::ordered_json j;
  j["R"] = std::vector<double>{R(0, 0), R(0, 1), R(0, 2), R(1, 0), R(1, 1),
                               R(1, 2), R(2, 0), R(2, 1), R(2, 2)};
  j["t"] = {result.T_C_D.p.x(), result.T_C_D.p.y(), result.T_C_D.p.z()};
  j["rvec"] = {rvec.x(), rvec.y(), rvec.z()};
  std::vector<double> cov;
  for (int r = 0; r < 6; ++r) {
    for (int c = 0; c < 6; ++c) cov.push_back(result.covariance(r, c));
  }
  j["covariance_6x6"] = cov;
  j["covariance_order"] = "rvec_x rvec_y rvec_z t_x t_y t_z (row-major)";
  j["pixel_sigma_px"] = pnp.pixel_sigma;
  j["rms_px"] = result.rms_px;
  j["n_points"] = points.size();
  j["iterations"] = result.iterations;
  std::cout << j.dump(2) << std::endl;
}

}  // namespace

void AddPnpCommand(CLI::App& root) {
  auto options = std::make_shared<PnpCommandOptions>();
  CLI::App* sub = root.add_subcommand(
      "pnp", "Solve a camera pose from 3-D/2-D correspondences (x_cam = R X + t), as JSON");
  sub->footer(PnpHelp());
  sub->add_option("--calib", options->calib,
                  "calibration.yaml of a dataset, or an OpenCV FileStorage calibration")
      ->required();
  sub->add_option("--camera", options->camera,
                  "Camera name in calibration.yaml (not needed for an OpenCV file)");
  sub->add_option("--points", options->points, "CSV with header X,Y,Z,u,v")->required();
  sub->add_option("--pixel-sigma", options->pixel_sigma,
                  "1-sigma pixel noise for the covariance (default: the calibration's)")
      ->check(Positive("pixels"));
  sub->callback([options] { RunPnp(*options); });
}

}  // namespace auvdock::cli
