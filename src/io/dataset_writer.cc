#include "auvdock/io/dataset_writer.h"

#include <cstdio>
#include <filesystem>

#include <opencv2/imgcodecs.hpp>

#include "auvdock/io/dock_io.h"
#include "auvdock/io/input_error.h"
#include "auvdock/io/sensor_csv.h"

namespace fs = std::filesystem;

namespace auvdock {

namespace {

std::unique_ptr<CsvWriter> OpenSensor(const fs::path& root, const std::string& name,
                                      const char* header) {
  fs::create_directories(root / name);
  return std::make_unique<CsvWriter>((root / name / "data.csv").string(), header);
}

// TUM line: "t tx ty tz qx qy qz qw", t in seconds with exactly 9 decimals (exact from ns).
std::string TumLine(int64_t t_ns, const Pose3& T) {
  char time[48];
  const int64_t sec = t_ns / 1000000000;
  const int64_t frac = t_ns % 1000000000;
  if (t_ns < 0 && frac != 0) {
    std::snprintf(time, sizeof(time), "-%lld.%09lld", static_cast<long long>(-(sec)),
                  static_cast<long long>(-frac));
  } else {
    std::snprintf(time, sizeof(time), "%lld.%09lld", static_cast<long long>(sec),
                  static_cast<long long>(frac));
  }
  std::string line = time;
  for (double v : {T.p.x(), T.p.y(), T.p.z(), T.q.x(), T.q.y(), T.q.z(), T.q.w()}) {
    line += ' ';
    line += FormatDouble(v);
  }
  return line;
}

}  // namespace

DatasetWriter::DatasetWriter(const std::string& root, const Calibration& calibration,
                             const DockModel& dock)
    : root_(root) {
  const fs::path r(root);
  if (!fs::is_directory(r)) throw InputError(root + ": output folder does not exist");
  SaveCalibration(calibration, (r / "calibration.yaml").string());
  SaveDockModel(dock, (r / "dock.yaml").string());
  for (const auto& cam : calibration.cameras) {
    cameras_[cam.name] = OpenSensor(r, cam.name, kCameraCsvHeader);
    fs::create_directories(r / cam.name / "data");
  }
  if (calibration.imu) imu_ = OpenSensor(r, calibration.imu->name, kImuCsvHeader);
  if (calibration.depth) depth_ = OpenSensor(r, calibration.depth->name, kDepthCsvHeader);
  if (calibration.dvl) dvl_ = OpenSensor(r, calibration.dvl->name, kDvlCsvHeader);
  if (calibration.acoustic) {
    acoustic_ = OpenSensor(r, calibration.acoustic->name, kAcousticCsvHeader);
  }
  groundtruth_ = OpenSensor(r, "groundtruth", kGroundTruthCsvHeader);
  visibility_ = std::make_unique<CsvWriter>((r / "groundtruth" / "visibility.csv").string(),
                                            kVisibilityCsvHeader);
  faults_ =
      std::make_unique<CsvWriter>((r / "groundtruth" / "faults.csv").string(), kFaultsCsvHeader);
  tum_ = std::make_unique<CsvWriter>((r / "groundtruth.tum").string(),
                                     "# timestamp[s] tx ty tz qx qy qz qw  (T_D_B: body in dock)");
}

void DatasetWriter::AddImu(const ImuSample& s) { imu_->Line(ImuCsvRow(s)); }
void DatasetWriter::AddDepth(const DepthMeasurement& m) { depth_->Line(DepthCsvRow(m)); }
void DatasetWriter::AddDvl(const DvlMeasurement& m) { dvl_->Line(DvlCsvRow(m)); }
void DatasetWriter::AddAcoustic(const AcousticFix& m) { acoustic_->Line(AcousticCsvRow(m)); }
void DatasetWriter::AddVisibility(const VisibilityRecord& r) {
  visibility_->Line(VisibilityCsvRow(r));
}
void DatasetWriter::AddFault(const FaultRecord& f) { faults_->Line(FaultCsvRow(f)); }

void DatasetWriter::AddGroundTruth(const GroundTruthState& s) {
  groundtruth_->Line(GroundTruthCsvRow(s));
  tum_->Line(TumLine(s.t_ns, s.T_D_B));
}

void DatasetWriter::AddImage(const std::string& camera, int64_t t_ns, const cv::Mat& image) {
  auto it = cameras_.find(camera);
  if (it == cameras_.end()) throw InputError("no camera named '" + camera + "' in calibration");
  const std::string file = std::to_string(t_ns) + ".png";
  const fs::path path = fs::path(root_) / camera / "data" / file;
  if (!cv::imwrite(path.string(), image, {cv::IMWRITE_PNG_COMPRESSION, png_compression_})) {
    throw InputError(path.string() + ": cannot write image");
  }
  it->second->Line(std::to_string(t_ns) + "," + file);
}

void DatasetWriter::Close() {
  for (auto* w : {&imu_, &depth_, &dvl_, &acoustic_, &groundtruth_, &visibility_, &faults_, &tum_}) {
    if (*w) (*w)->Close();
  }
  for (auto& [name, w] : cameras_) w->Close();
}

}  // namespace auvdock
