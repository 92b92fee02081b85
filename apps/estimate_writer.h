// The output files of `auvdock run` and `auvdock smooth`, written one flushed line per frame
// (a stopped run keeps every line before the stop) into an output folder that must be absent
// or empty:
//   trajectory.tum   T_D_B (TUM: t x y z qx qy qz qw), frames with an estimate only
//   covariance.csv   timestamp_ns and the 36 values of the 6 x 6 pose covariance, row-major;
//                    tangent [dp_D x y z (m), dtheta_D x y z (rad)] with T_D_B = (p + dp,
//                    Exp(dtheta) q): position and rotation perturbed in the dock frame. No row
//                    when the covariance is unavailable (the decision then says so).
//   decisions.csv    timestamp_ns, GO or NO-GO, reason (every frame)
//   rejections.csv   timestamp_ns, sensor, statistic, reason: every measurement the estimator
//                    left out (io/rejections_csv.h)
//   summary.json     written last, atomically (see WriteSummary)
//   estimate.csv     (--euroc-csv) the estimated state in EuRoC's state_groundtruth_estimate0
//                    columns (io/sensor_csv.h, the dataset's groundtruth/data.csv format):
//                    timestamp_ns, p_D_B, q_D_B (w x y z), v_D, gyro bias, accelerometer bias;
//                    the format of `evo_traj euroc`; our own ground-truth reader reads it back
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "auvdock/estimator/go_no_go.h"
#include "auvdock/estimator/rejection.h"
#include "auvdock/io/csv.h"
#include "auvdock/io/tum_io.h"

namespace auvdock::cli {

class EstimateWriter {
 public:
  // euroc_csv: also write estimate.csv (above).
  explicit EstimateWriter(const std::string& out_dir, bool euroc_csv = false);

  void Write(const EstimatorOutput& output, const GoNoGoDecision& decision);
  void WriteNoEstimate(int64_t t_ns, const GoNoGoDecision& decision);
  void WriteRejections(const std::vector<Rejection>& rejections);

  // summary.json via a temporary file and a rename: never half-written.
  void WriteSummary(const nlohmann::json& summary) const;

 private:
  std::string out_dir_;
  std::unique_ptr<TumWriter> trajectory_;
  CsvWriter covariance_;
  CsvWriter decisions_;
  CsvWriter rejections_;
  std::unique_ptr<CsvWriter> estimate_csv_;  // null without --euroc-csv
};

}  // namespace auvdock::cli
