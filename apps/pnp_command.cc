// auvdock pnp --calib CALIB.yaml [--camera NAME] --points CORR.csv
//
// Solves a camera pose from given 3-D/2-D correspondences and prints one JSON object:
//   R (3x3 row-major), t, rvec, covariance_6x6 (36 values row-major, order rvec_x rvec_y rvec_z
//   t_x t_y t_z), rms_px, chi2, dof, variance_factor, n_points, iterations
// for the camera-from-model transform in OpenCV's convention: x_cam = R X + t.
// CORR.csv: a header row "X,Y,Z,u,v", then one correspondence per row (model metres, raw
// distorted pixels); or "X,Y,Z,u,v,cov_uu,cov_uv,cov_vv" with each pixel's own covariance
// (pixels^2, e.g. `detect`'s detections.csv columns), which weighs it (SolvePnp). The
// covariance grows by the a-posteriori variance factor when the pixels fit worse than claimed.
#include <fstream>
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
  bool no_variance_factor = false;
};

// True when the file's first non-empty line names the covariance columns after "X,Y,Z,u,v".
bool HasCovarianceColumns(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    return line.find("cov_uu") != std::string::npos;
  }
  return false;
}

void ReadCorrespondences(const std::string& path, std::vector<Eigen::Vector3d>* points,
                         std::vector<Eigen::Vector2d>* pixels,
                         std::vector<Eigen::Matrix2d>* covariances) {
  std::vector<std::string> columns = {"X", "Y", "Z", "u", "v"};
  const bool with_covariance = HasCovarianceColumns(path);
  if (with_covariance) columns.insert(columns.end(), {"cov_uu", "cov_uv", "cov_vv"});
  CsvReader reader(path, columns);
  reader.ExpectNamedHeaderRow();
  while (reader.Next()) {
    points->emplace_back(reader.Double(0), reader.Double(1), reader.Double(2));
    pixels->emplace_back(reader.Double(3), reader.Double(4));
    if (!with_covariance) continue;
    Eigen::Matrix2d covariance;
    covariance << reader.Double(5), reader.Double(6), reader.Double(6), reader.Double(7);
    if (!(covariance(0, 0) > 0.0) ||
        !(covariance(0, 0) * covariance(1, 1) - covariance(0, 1) * covariance(0, 1) > 0.0)) {
      reader.Fail("the pixel covariance (cov_uu, cov_uv, cov_vv) is not positive definite");
    }
    covariances->push_back(covariance);
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
  std::vector<Eigen::Matrix2d> covariances;
  ReadCorrespondences(options.points, &points, &pixels, &covariances);
  PnpOptions pnp;
  pnp.pixel_sigma = options.pixel_sigma > 0 ? options.pixel_sigma : camera.pixel_noise_px;
  pnp.inflate_by_variance_factor = !options.no_variance_factor;
  const PnpResult result =
      SolvePnp(points, pixels, camera.intrinsics, pnp, std::nullopt, covariances);
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
  if (covariances.empty()) {
    j["pixel_sigma_px"] = pnp.pixel_sigma;
  } else {
    j["pixel_sigma_px"] = "per point (cov_uu, cov_uv, cov_vv)";
  }
  j["rms_px"] = result.rms_px;
  j["chi2"] = result.chi2;
  j["dof"] = result.dof;
  j["variance_factor"] = result.variance_factor;
  j["covariance_scaled_by_variance_factor"] =
      pnp.inflate_by_variance_factor && result.variance_factor > 1.0;
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
  sub->add_option("--points", options->points,
                  "CSV with header X,Y,Z,u,v (or X,Y,Z,u,v,cov_uu,cov_uv,cov_vv: each pixel's "
                  "own covariance, px^2)")
      ->required();
  sub->add_option("--pixel-sigma", options->pixel_sigma,
                  "1-sigma pixel noise for the weights and covariance when the CSV has no "
                  "covariance columns (default: the calibration's)")
      ->check(Positive("pixels"));
  sub->add_flag("--no-variance-factor", options->no_variance_factor,
                "Do not widen the covariance by the a-posteriori variance factor");
  sub->callback([options] { RunPnp(*options); });
}

}  // namespace auvdock::cli
