#include "apps/estimate_writer.h"

#include <filesystem>
#include <fstream>

#include "auvdock/io/decisions_csv.h"
#include "auvdock/io/input_error.h"
#include "auvdock/io/pose_covariance_csv.h"
#include "auvdock/io/rejections_csv.h"
#include "auvdock/io/sensor_csv.h"
#include "auvdock/io/staged_directory.h"

namespace fs = std::filesystem;

namespace auvdock::cli {
namespace {

std::string PrepareDirectory(const std::string& out_dir) {
  RequireAbsentOrEmptyDirectory(out_dir);
  fs::create_directories(out_dir);
  return out_dir;
}

}  // namespace

EstimateWriter::EstimateWriter(const std::string& out_dir, bool euroc_csv)
    : out_dir_(PrepareDirectory(out_dir)),
      trajectory_(std::make_unique<TumWriter>(out_dir + "/trajectory.tum")),
      covariance_(out_dir + "/covariance.csv", PoseCovarianceCsvHeader()),
      decisions_(out_dir + "/decisions.csv", DecisionsCsvHeader()),
      rejections_(out_dir + "/rejections.csv", RejectionsCsvHeader()) {
  if (euroc_csv) {
    estimate_csv_ = std::make_unique<CsvWriter>(out_dir + "/estimate.csv", kGroundTruthCsvHeader);
  }
}

void EstimateWriter::Write(const EstimatorOutput& output, const GoNoGoDecision& decision) {
  trajectory_->Append({output.t_ns, output.T_D_B});
  if (estimate_csv_) {
    estimate_csv_->Line(GroundTruthCsvRow(
        {output.t_ns, output.T_D_B, output.v_D, output.bias.gyro, output.bias.accel}));
  }
  if (output.covariance_ok) covariance_.Row(output.t_ns, PoseCovarianceCsvValues(output.covariance));
  WriteNoEstimate(output.t_ns, decision);
}

void EstimateWriter::WriteNoEstimate(int64_t t_ns, const GoNoGoDecision& decision) {
  decisions_.Line(DecisionsCsvRow({t_ns, decision.go, decision.reason}));
}

void EstimateWriter::WriteRejections(const std::vector<Rejection>& rejections) {
  for (const Rejection& r : rejections) rejections_.Line(RejectionsCsvRow(r));
}

void EstimateWriter::WriteSummary(const nlohmann::json& summary) const {
  const std::string path = out_dir_ + "/summary.json";
  const std::string tmp = path + ".partial";
  {
    std::ofstream out(tmp);
    out << summary.dump(2) << "\n";
    if (!out) throw InputError(path + ": cannot write");
  }
  fs::rename(tmp, path);
}

}  // namespace auvdock::cli
