// Light detections per camera image, as a front-end reports them: the file that `auvdock
// frontend` writes, that `auvdock simulate` writes with `cameras.render_images: false` (synthetic
// detections, sim/synthetic_detections.h) and that `run` / `smooth --detections FILE` replay
// through the estimator instead of decoding images (a user's own detector, a learned one).
//
// Format (CSV, one header line starting with '#'):
//   timestamp_ns,camera,light_id,u,v,radius,score[,cov_uu,cov_uv,cov_vv]
// - timestamp_ns: the image's time stamp; camera: the camera's name in calibration.yaml;
// - light_id: the dock light the front-end says this is, or -1 (not identified: the replay
//   identifies it as the image path does);
// - u, v: the centroid in the raw (distorted) image, pixels, (0, 0) the centre of the top-left
//   pixel; radius (px, >= 0) and score (in [0, 1]) as in vision/light_detection.h;
// - cov_uu, cov_uv, cov_vv (optional, all three or none): the centroid's own covariance, px^2;
//   all zero or absent: the camera's pixel_noise_px applies.
// An image in which the front-end found nothing is one row with light_id -1 and u, v, radius,
// score (and the covariance) empty: "this camera took an image at this time and saw no light".
// A camera with no row at a time took no image then. Rows of one image need not be adjacent;
// each camera's images are returned in time order.
// Errors name the file, the line and the column (InputError).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "auvdock/io/csv.h"
#include "auvdock/vision/light_detection.h"

namespace auvdock {

// What one camera's front-end reported for one image.
struct ImageDetections {
  int64_t t_ns = 0;
  std::string camera;
  std::vector<LightDetection> detections;
  std::vector<int> light_ids;  // per detection: the reported dock light id, or -1
  int line = 0;                // the file's line of the image's first row (for messages)
};

// Every image of the file, ordered by camera name, then time. Throws InputError for a
// malformed row, a non-finite or out-of-range value, a light_id below -1, a half-given
// covariance or an image given twice with and without detections.
std::vector<ImageDetections> ReadDetectionsCsv(const std::string& path);

// Writes the file row by row, flushed (an interrupted run keeps what it wrote).
class DetectionsCsvWriter {
 public:
  explicit DetectionsCsvWriter(const std::string& path);
  // One image: a row per detection (light_ids may be shorter: missing ids are -1), or the
  // "saw nothing" row when there is none.
  void Append(int64_t t_ns, const std::string& camera,
              const std::vector<LightDetection>& detections, const std::vector<int>& light_ids);
  void Close() { csv_.Close(); }

 private:
  CsvWriter csv_;
};

}  // namespace auvdock
