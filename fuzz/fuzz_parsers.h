// The parsers of outside input, by name, on bytes: what the libFuzzer targets (fuzz_target.cc)
// and the regression test of their findings (tests/io/fuzz_regressions_test.cc) run.
//
// Each parser reads a file: the bytes are written to a file of the usual name in a folder
// private to the process (ScratchFolder; some readers look at the extension). Parsers:
//   scenario (in a folder beside the shipped docks: `dock: ../docks/NAME.yaml` resolves),
//   run_config (estimator options), calibration (a dataset's calibration.yaml),
//   camera_file (that or an OpenCV FileStorage calibration), dock, tum, detections,
//   pose_covariance, decisions, rejections, light_labels: the file is the bytes;
//   sensor_csv: the first byte chooses the reader (modulo 8: IMU, camera, depth, DVL, acoustic,
//     ground truth, visibility, faults) and, for the sensors, whether bad rows are skipped
//     (bit 3) or fatal; with bit 4 set, the SBL reader (4 transducers) instead, with bit 5
//     set the heading (AHRS) reader; the rest is the file;
//   euroc_sensor_yaml: the first byte chooses a EuRoC sequence's cam0/sensor.yaml (even) or
//     imu0/sensor.yaml (odd), beside a one-row data.csv, read through LoadDataset on a mav0/
//     folder; the rest is its text.
// The contract for bad input is an InputError naming the file (the CLI prints that one line and
// exits 2); any other exception escaping would reach the user as an "internal error".
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace auvdock::fuzz {

const std::vector<std::string>& ParserNames();

// Runs the named parser on the bytes; throws what it throws, std::invalid_argument for an
// unknown name.
void RunParser(const std::string& parser, const uint8_t* data, size_t size);

// The process's own scratch folder ($TMPDIR or /tmp, auvdock_fuzz_<pid>).
std::filesystem::path ScratchFolder();

}  // namespace auvdock::fuzz
