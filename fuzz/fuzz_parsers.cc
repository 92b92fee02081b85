#include "fuzz/fuzz_parsers.h"

#include <cstdlib>
#include <fstream>
#include <functional>
#include <map>
#include <stdexcept>

#include <unistd.h>

#include "auvdock/estimator/estimator_config.h"
#include "auvdock/io/calibration.h"
#include "auvdock/io/camera_file.h"
#include "auvdock/io/dataset.h"
#include "auvdock/io/decisions_csv.h"
#include "auvdock/io/detections_csv.h"
#include "auvdock/io/dock_io.h"
#include "auvdock/io/light_labels_csv.h"
#include "auvdock/io/pose_covariance_csv.h"
#include "auvdock/io/rejections_csv.h"
#include "auvdock/io/sensor_csv.h"
#include "auvdock/io/tum_io.h"
#include "auvdock/sim/scenario.h"

namespace auvdock::fuzz {
namespace {

// Writes the bytes to ScratchFolder()/relative_path (creating its folders); returns the path.
std::string WriteInput(const uint8_t* data, size_t size, const std::string& relative_path) {
  const std::filesystem::path path = ScratchFolder() / relative_path;
  std::filesystem::create_directories(path.parent_path());
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  return path.string();
}

void ReadSensorCsv(const uint8_t* data, size_t size) {
  if (size < 1) return;
  std::vector<std::string> skipped_rows;
  std::vector<std::string>* skipped = (data[0] & 8) != 0 ? &skipped_rows : nullptr;
  const std::string path = WriteInput(data + 1, size - 1, "data.csv");
  if ((data[0] & 32) != 0) {  // a later reader: its own bit, so the corpus keeps its meaning
    ReadHeadingCsv(path, skipped);
    return;
  }
  if ((data[0] & 16) != 0) {
    ReadSblCsv(path, /*num_transducers=*/4, skipped);
    return;
  }
  switch (data[0] % 8) {
    case 0: ReadImuCsv(path, skipped); break;
    case 1: ReadCameraCsv(path, "data", skipped); break;
    case 2: ReadDepthCsv(path, skipped); break;
    case 3: ReadDvlCsv(path, skipped); break;
    case 4: ReadAcousticCsv(path, skipped); break;
    case 5: ReadGroundTruthCsv(path); break;
    case 6: ReadVisibilityCsv(path); break;
    default: ReadFaultsCsv(path); break;
  }
}

void ReadEurocSensorYaml(const uint8_t* data, size_t size) {
  if (size < 1) return;
  const bool camera = data[0] % 2 == 0;
  const std::filesystem::path root = ScratchFolder() / "euroc";
  std::filesystem::remove_all(root);
  WriteInput(data + 1, size - 1, camera ? "euroc/mav0/cam0/sensor.yaml" : "euroc/mav0/imu0/sensor.yaml");
  static const char kCameraRows[] =
      "#timestamp [ns],filename\n1403636579763555584,1403636579763555584.png\n";
  static const char kImuRows[] =
      "#timestamp [ns],w_x,w_y,w_z,a_x,a_y,a_z\n1403636579758555392,-0.1,0.14,0.02,8.1,-0.4,-2.4\n";
  const std::string rows = camera ? kCameraRows : kImuRows;
  WriteInput(reinterpret_cast<const uint8_t*>(rows.data()), rows.size(),
             camera ? "euroc/mav0/cam0/data.csv" : "euroc/mav0/imu0/data.csv");
  LoadDataset(root.string());
}

// A scenario names its dock relative to its own folder (`dock: ../docks/t_shape.yaml`): the
// scratch folder holds it in scenarios/ beside a link to the shipped docks, so that the fuzzer
// gets past the dock into the rest of the file.
void ReadScenario(const uint8_t* data, size_t size) {
  const std::filesystem::path docks = ScratchFolder() / "docks";
  if (!std::filesystem::exists(std::filesystem::symlink_status(docks))) {
    std::filesystem::create_directory_symlink(
        std::filesystem::path(AUVDOCK_SOURCE_DIR) / "data" / "docks", docks);
  }
  LoadScenario(WriteInput(data, size, "scenarios/scenario.yaml"));
}

using Parser = std::function<void(const uint8_t*, size_t)>;

// A parser of one whole file called `name`.
template <typename Read>
Parser WholeFile(const std::string& name, Read read) {
  return [name, read](const uint8_t* data, size_t size) { read(WriteInput(data, size, name)); };
}

const std::map<std::string, Parser>& Parsers() {
  static const std::map<std::string, Parser> parsers{
      {"scenario", ReadScenario},
      {"run_config", WholeFile("estimator.yaml", [](const std::string& p) { LoadRunConfig(p); })},
      {"calibration",
       WholeFile("calibration.yaml", [](const std::string& p) { LoadCalibration(p); })},
      {"camera_file",
       WholeFile("camera.yaml", [](const std::string& p) { LoadCameraCalibration(p, ""); })},
      {"dock", WholeFile("dock.yaml", [](const std::string& p) { LoadDockModel(p); })},
      {"tum", WholeFile("trajectory.tum", [](const std::string& p) { ReadTumTrajectory(p); })},
      {"detections",
       WholeFile("detections.csv", [](const std::string& p) { ReadDetectionsCsv(p); })},
      {"pose_covariance",
       WholeFile("covariance.csv", [](const std::string& p) { ReadPoseCovarianceCsv(p); })},
      {"decisions", WholeFile("decisions.csv", [](const std::string& p) { ReadDecisionsCsv(p); })},
      {"rejections",
       WholeFile("rejections.csv", [](const std::string& p) { ReadRejectionsCsv(p); })},
      {"light_labels", WholeFile("labels.csv", [](const std::string& p) { LoadLightLabels(p); })},
      {"sensor_csv", ReadSensorCsv},
      {"euroc_sensor_yaml", ReadEurocSensorYaml},
  };
  return parsers;
}

}  // namespace

const std::vector<std::string>& ParserNames() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n;
    for (const auto& [name, parser] : Parsers()) n.push_back(name);
    return n;
  }();
  return names;
}

void RunParser(const std::string& parser, const uint8_t* data, size_t size) {
  const auto it = Parsers().find(parser);
  if (it == Parsers().end()) throw std::invalid_argument("no parser named '" + parser + "'");
  it->second(data, size);
}

std::filesystem::path ScratchFolder() {
  static const std::filesystem::path folder = [] {
    const char* tmp = std::getenv("TMPDIR");
    std::filesystem::path p = std::filesystem::path(tmp != nullptr ? tmp : "/tmp") /
                              ("auvdock_fuzz_" + std::to_string(::getpid()));
    std::filesystem::create_directories(p);
    return p;
  }();
  return folder;
}

}  // namespace auvdock::fuzz
