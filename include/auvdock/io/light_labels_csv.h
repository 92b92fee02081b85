// Hand labels of light centres in a user's own frames, for measuring a detector on them.
//
// Format: CSV with a first row naming the columns; required `frame_file` (the image's file name,
// without folder), `u`, `v` (pixels in the raw image, (0, 0) the centre of the top-left pixel);
// optional `status`, `quality` and `range_m` (the light's distance from the camera, when known:
// the simulator's ground truth has it); other columns are ignored. Fields may be double-quoted (a
// quote inside is doubled). A row with empty u and v, or status `none`, says the frame was
// labelled and shows no light.
//   status:  ok (required: the light and its glow are inside the image; the default),
//            border (centre inside, glow cut: not required, a detection of it is a hit),
//            edge (centre on or past the border: never required; detections near it are
//            neither hits nor false), none (no light in view).
//   quality: good (the centre is good to ~1.5 px; the default) or anything else (counted for
//            recall and precision, left out of the centroid RMS).
// Errors name the file, the line and the column (InputError).
#pragma once

#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace auvdock {

enum class LabelStatus { kOk, kBorder, kEdge };

struct LightLabel {
  Eigen::Vector2d uv = Eigen::Vector2d::Zero();
  LabelStatus status = LabelStatus::kOk;
  bool good = true;  // quality "good"
  double range_m = -1.0;  // < 0: not known
};

// Every labelled frame (by file name), with its lights (possibly none).
using LightLabels = std::map<std::string, std::vector<LightLabel>>;

LightLabels LoadLightLabels(const std::string& path);

// Splits one CSV line into fields (RFC 4180 quoting). Throws std::invalid_argument on an
// unterminated quote.
std::vector<std::string> SplitCsvLine(const std::string& line);

}  // namespace auvdock
