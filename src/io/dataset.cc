#include "auvdock/io/dataset.h"

#include <filesystem>

#include "auvdock/io/dock_io.h"
#include "auvdock/io/imu_time_base.h"
#include "auvdock/io/input_error.h"
#include "auvdock/io/sensor_csv.h"
#include "euroc_dataset.h"

namespace fs = std::filesystem;

namespace auvdock {

namespace {

// The data.csv of a sensor folder, or "" when the sensor has no folder.
std::string SensorCsv(const fs::path& root, const std::string& name) {
  const fs::path p = root / name / "data.csv";
  return fs::exists(p) ? p.string() : std::string();
}

Dataset LoadAuvdockDataset(const fs::path& root, std::vector<std::string>* skipped) {
  Dataset ds;
  ds.root = root.string();
  ds.layout = DatasetLayout::kAuvdock;
  ds.calibration = LoadCalibration((root / "calibration.yaml").string());
  if (fs::exists(root / "dock.yaml")) ds.dock = LoadDockModel((root / "dock.yaml").string());

  for (const auto& cam : ds.calibration.cameras) {
    const std::string csv = SensorCsv(root, cam.name);
    if (csv.empty()) throw InputError((root / cam.name / "data.csv").string() + ": missing");
    ds.camera_frames[cam.name] = ReadCameraCsv(csv, (root / cam.name / "data").string(), skipped);
  }
  if (ds.calibration.imu) {
    const std::string csv = SensorCsv(root, ds.calibration.imu->name);
    if (!csv.empty()) ds.imu = ReadImuCsv(csv, skipped);
    if (const std::string problem = ImuTimeBaseProblem(ds.imu, *ds.calibration.imu, csv);
        !problem.empty()) {
      throw InputError(problem);
    }
  }
  if (ds.calibration.depth) {
    const std::string csv = SensorCsv(root, ds.calibration.depth->name);
    if (!csv.empty()) ds.depth = ReadDepthCsv(csv, skipped);
  }
  if (ds.calibration.dvl) {
    const std::string csv = SensorCsv(root, ds.calibration.dvl->name);
    if (!csv.empty()) ds.dvl = ReadDvlCsv(csv, skipped);
  }
  if (ds.calibration.heading) {
    const std::string csv = SensorCsv(root, ds.calibration.heading->name);
    if (!csv.empty()) ds.heading = ReadHeadingCsv(csv, skipped);
  }
  if (ds.calibration.acoustic) {
    const std::string csv = SensorCsv(root, ds.calibration.acoustic->name);
    if (!csv.empty()) ds.acoustic = ReadAcousticCsv(csv, skipped);
  }
  if (ds.calibration.sbl) {
    const std::string csv = SensorCsv(root, ds.calibration.sbl->name);
    const int n = static_cast<int>(ds.calibration.sbl->p_B_transducers.size());
    if (!csv.empty()) ds.sbl = ReadSblCsv(csv, n, skipped);
  }
  const fs::path gt = root / "groundtruth";
  if (fs::exists(gt / "data.csv")) ds.groundtruth = ReadGroundTruthCsv((gt / "data.csv").string());
  if (fs::exists(gt / "visibility.csv")) {
    ds.visibility = ReadVisibilityCsv((gt / "visibility.csv").string());
  }
  if (fs::exists(gt / "faults.csv")) ds.faults = ReadFaultsCsv((gt / "faults.csv").string());
  return ds;
}

}  // namespace

Dataset LoadDataset(const std::string& dir) { return LoadDataset(dir, nullptr); }

Dataset LoadDataset(const std::string& dir, std::vector<std::string>* skipped_rows) {
  const fs::path root(dir);
  std::error_code ec;
  if (!fs::is_directory(root, ec)) throw InputError(dir + ": not a dataset folder");
  if (fs::exists(root / "calibration.yaml")) return LoadAuvdockDataset(root, skipped_rows);
  // A EuRoC sequence has no dock: a dock.yaml beside its mav0/ (or inside it) is the user's.
  auto with_dock = [](Dataset ds, const std::vector<fs::path>& places) {
    for (const fs::path& p : places) {
      if (fs::exists(p)) {
        ds.dock = LoadDockModel(p.string());
        break;
      }
    }
    return ds;
  };
  if (fs::is_directory(root / "mav0")) {
    return with_dock(internal::LoadEurocDataset((root / "mav0").string(), skipped_rows),
                     {root / "dock.yaml", root / "mav0" / "dock.yaml"});
  }
  if (fs::exists(root / "imu0" / "sensor.yaml") || fs::exists(root / "cam0" / "sensor.yaml")) {
    return with_dock(internal::LoadEurocDataset(root.string(), skipped_rows),
                     {root / "dock.yaml", root.parent_path() / "dock.yaml"});
  }
  throw InputError(dir + ": not a dataset folder (no calibration.yaml, and no EuRoC mav0/)");
}

}  // namespace auvdock
