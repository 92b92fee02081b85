// A dataset folder in auvdock's EuRoC/ASL-style layout (docs/dataset_format.md), or a real
// EuRoC sequence (mav0/cam0, cam1, imu0, state_groundtruth_estimate0).
//
// Loading validates as it goes: a malformed row raises InputError naming the file and line.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "auvdock/geometry/dock_model.h"
#include "auvdock/io/calibration.h"
#include "auvdock/io/measurements.h"

namespace auvdock {

enum class DatasetLayout { kAuvdock, kEuroc };

struct Dataset {
  std::string root;  // the folder the sensor folders live in (".../mav0" for EuRoC)
  DatasetLayout layout = DatasetLayout::kAuvdock;
  Calibration calibration;
  // dock.yaml; in a EuRoC sequence, a dock.yaml beside mav0/ or inside it, else absent.
  std::optional<DockModel> dock;
  std::vector<ImuSample> imu;
  std::vector<DepthMeasurement> depth;
  std::vector<DvlMeasurement> dvl;
  std::vector<HeadingMeasurement> heading;  // calibration.heading (an AHRS or compass)
  std::vector<AcousticFix> acoustic;
  std::vector<SblRange> sbl;  // SBL ranges (calibration.sbl)
  std::map<std::string, std::vector<CameraFrame>> camera_frames;  // by camera name; absolute paths
  std::vector<GroundTruthState> groundtruth;                      // empty if none
  std::vector<VisibilityRecord> visibility;                       // empty if unknown
  std::vector<FaultRecord> faults;
};

// Loads a dataset folder. `dir` may be an auvdock dataset, a EuRoC sequence folder (containing
// mav0/) or its mav0/ folder itself. Throws InputError on anything missing or malformed.
Dataset LoadDataset(const std::string& dir);
// The same, but sensor rows (IMU, cameras, depth, DVL, acoustic) with NaN/Inf or a timestamp
// that does not increase are left out and described in `skipped_rows` instead of failing the
// load (for `auvdock run`, which goes on past a bad measurement). Malformed files still throw.
Dataset LoadDataset(const std::string& dir, std::vector<std::string>* skipped_rows);

}  // namespace auvdock
