#include "auvdock/io/detections_csv.h"

#include <map>
#include <utility>

#include "auvdock/io/input_error.h"

namespace auvdock {

namespace {

constexpr int kFirstCovarianceColumn = 7;

bool IsNothingSeenRow(const CsvReader& csv) {
  for (int c = 3; c < csv.size(); ++c) {
    if (!csv.String(c).empty()) return false;
  }
  return true;
}

LightDetection ParseDetection(const CsvReader& csv) {
  LightDetection d;
  d.uv = Eigen::Vector2d(csv.Double(3), csv.Double(4));
  d.radius_px = csv.Double(5);
  if (d.radius_px < 0.0) csv.FailColumn(5, "must not be negative");
  d.score = csv.Double(6);
  if (d.score < 0.0 || d.score > 1.0) csv.FailColumn(6, "must lie in [0, 1]");
  int given = 0;
  for (int c = kFirstCovarianceColumn; c < csv.size(); ++c) given += csv.String(c).empty() ? 0 : 1;
  if (given > 0) {
    if (given != 3) csv.Fail("the covariance needs all three columns cov_uu, cov_uv, cov_vv");
    const double uu = csv.Double(7), uv = csv.Double(8), vv = csv.Double(9);
    if (uu < 0.0 || vv < 0.0 || uv * uv > uu * vv * (1.0 + 1e-9) + 1e-18) {  // rounding
      csv.Fail("the covariance (cov_uu, cov_uv, cov_vv) is not positive semi-definite");
    }
    d.covariance << uu, uv, uv, vv;
  }
  return d;
}

}  // namespace

std::vector<ImageDetections> ReadDetectionsCsv(const std::string& path) {
  CsvReader csv(path,
                {"timestamp_ns", "camera", "light_id", "u", "v", "radius", "score", "cov_uu",
                 "cov_uv", "cov_vv"},
                /*allow_extra=*/false, /*optional_last=*/3);
  std::map<std::pair<std::string, int64_t>, ImageDetections> images;
  std::map<std::pair<std::string, int64_t>, bool> nothing_seen;
  while (csv.Next()) {
    const int64_t t = csv.Int64(0);
    const std::string& camera = csv.String(1);
    if (camera.empty()) csv.FailColumn(1, "empty camera name");
    const int64_t id = csv.Int64(2);
    if (id < -1 || id > 1000000) csv.FailColumn(2, "expected a light id >= 0, or -1");
    const auto key = std::make_pair(camera, t);
    const bool empty_row = IsNothingSeenRow(csv);
    if (empty_row && id != -1) csv.Fail("a row without a centroid must have light_id -1");
    auto [it, inserted] = images.try_emplace(key);
    ImageDetections& image = it->second;
    if (inserted) {
      image.t_ns = t;
      image.camera = camera;
      image.line = csv.line();
      nothing_seen[key] = empty_row;
    } else if (empty_row || nothing_seen[key]) {
      csv.Fail("camera '" + camera + "' at " + std::to_string(t) +
               " ns: an image that saw nothing (empty row) also has other rows");
    }
    if (empty_row) continue;
    image.detections.push_back(ParseDetection(csv));
    image.light_ids.push_back(static_cast<int>(id));
  }
  std::vector<ImageDetections> out;
  out.reserve(images.size());
  for (auto& [key, image] : images) out.push_back(std::move(image));
  return out;
}

DetectionsCsvWriter::DetectionsCsvWriter(const std::string& path)
    : csv_(path,
           "#timestamp [ns],camera,light_id,u [px],v [px],radius [px],score,cov_uu [px^2],"
           "cov_uv [px^2],cov_vv [px^2]") {}

void DetectionsCsvWriter::Append(int64_t t_ns, const std::string& camera,
                                 const std::vector<LightDetection>& detections,
                                 const std::vector<int>& light_ids) {
  const std::string prefix = std::to_string(t_ns) + "," + camera + ",";
  if (detections.empty()) {
    csv_.Line(prefix + "-1,,,,,,,");
    return;
  }
  for (std::size_t i = 0; i < detections.size(); ++i) {
    const LightDetection& d = detections[i];
    const int id = i < light_ids.size() ? light_ids[i] : -1;
    csv_.Line(prefix + std::to_string(id) + "," + FormatDouble(d.uv.x()) + "," +
              FormatDouble(d.uv.y()) + "," + FormatDouble(d.radius_px) + "," +
              FormatDouble(d.score) + "," + FormatDouble(d.covariance(0, 0)) + "," +
              FormatDouble(d.covariance(0, 1)) + "," + FormatDouble(d.covariance(1, 1)));
  }
}

}  // namespace auvdock
