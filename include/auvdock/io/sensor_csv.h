// The CSV layouts of the dataset's sensor files, for reading and for writing, in one place
// (docs/dataset_format.md). IMU, camera and ground-truth files use EuRoC's exact columns, so
// the same readers serve auvdock datasets and real EuRoC sequences.
//
// Every reader checks that timestamps strictly increase and that numbers are finite; errors
// name the file and line (InputError).
#pragma once

#include <string>
#include <vector>

#include "auvdock/io/measurements.h"

namespace auvdock {

// Header lines (written verbatim; readers skip any line that starts with '#').
extern const char kImuCsvHeader[];
extern const char kCameraCsvHeader[];
extern const char kDepthCsvHeader[];
extern const char kDvlCsvHeader[];
extern const char kHeadingCsvHeader[];
extern const char kAcousticCsvHeader[];
extern const char kSblCsvHeader[];
extern const char kGroundTruthCsvHeader[];
extern const char kVisibilityCsvHeader[];
extern const char kFaultsCsvHeader[];

// Sensor readers. Strict by default: a row with NaN/Inf or a timestamp that does not increase
// is an InputError naming the file and line. With `skipped` given, such a row is left out and
// described there instead ("imu0/data.csv: line 17: NaN/Inf: row skipped"), so that a run can
// go on past a bad measurement; malformed text is an error either way.
// The IMU's clock jumping back by more than 0.1 s ends its file in lenient mode: that row and
// every later one are skipped, in one line (their times are not those of the motion).
std::vector<ImuSample> ReadImuCsv(const std::string& path,
                                  std::vector<std::string>* skipped = nullptr);
// Camera frames; each path is made absolute as <image_dir>/<filename>.
std::vector<CameraFrame> ReadCameraCsv(const std::string& path, const std::string& image_dir,
                                       std::vector<std::string>* skipped = nullptr);
std::vector<DepthMeasurement> ReadDepthCsv(const std::string& path,
                                           std::vector<std::string>* skipped = nullptr);
std::vector<DvlMeasurement> ReadDvlCsv(const std::string& path,
                                       std::vector<std::string>* skipped = nullptr);
std::vector<HeadingMeasurement> ReadHeadingCsv(const std::string& path,
                                               std::vector<std::string>* skipped = nullptr);
std::vector<AcousticFix> ReadAcousticCsv(const std::string& path,
                                         std::vector<std::string>* skipped = nullptr);
// SBL ranges, one row per transducer and ping: rows in strictly increasing (timestamp,
// transducer) order (a ping's ranges share its timestamp); transducer in [0, num_transducers).
std::vector<SblRange> ReadSblCsv(const std::string& path, int num_transducers,
                                 std::vector<std::string>* skipped = nullptr);
std::vector<GroundTruthState> ReadGroundTruthCsv(const std::string& path);
std::vector<VisibilityRecord> ReadVisibilityCsv(const std::string& path);
std::vector<FaultRecord> ReadFaultsCsv(const std::string& path);

// One formatted row (without newline) of each file, matching the readers above.
std::string ImuCsvRow(const ImuSample& s);
std::string DepthCsvRow(const DepthMeasurement& m);
std::string DvlCsvRow(const DvlMeasurement& m);
std::string HeadingCsvRow(const HeadingMeasurement& m);
std::string AcousticCsvRow(const AcousticFix& m);
std::string SblCsvRow(const SblRange& m);
std::string GroundTruthCsvRow(const GroundTruthState& s);
std::string VisibilityCsvRow(const VisibilityRecord& r);
std::string FaultCsvRow(const FaultRecord& f);

}  // namespace auvdock
