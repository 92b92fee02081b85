#include "auvdock/io/sensor_csv.h"

#include <cmath>
#include <limits>

#include "auvdock/io/csv.h"

namespace auvdock {

const char kImuCsvHeader[] =
    "#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],"
    "a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]";
const char kCameraCsvHeader[] = "#timestamp [ns],filename";
const char kDepthCsvHeader[] = "#timestamp [ns],depth [m]";
const char kHeadingCsvHeader[] = "#timestamp [ns],heading [rad]";
const char kDvlCsvHeader[] = "#timestamp [ns],v_S_x [m s^-1],v_S_y [m s^-1],v_S_z [m s^-1]";
const char kAcousticCsvHeader[] =
    "#timestamp [ns],p_D_x [m],p_D_y [m],p_D_z [m],sigma [m],latency [ns]";
const char kSblCsvHeader[] = "#timestamp [ns],transducer,range [m],sigma [m]";
const char kGroundTruthCsvHeader[] =
    "#timestamp,p_RS_R_x [m],p_RS_R_y [m],p_RS_R_z [m],q_RS_w [],q_RS_x [],q_RS_y [],q_RS_z [],"
    "v_RS_R_x [m s^-1],v_RS_R_y [m s^-1],v_RS_R_z [m s^-1],"
    "b_w_RS_S_x [rad s^-1],b_w_RS_S_y [rad s^-1],b_w_RS_S_z [rad s^-1],"
    "b_a_RS_S_x [m s^-2],b_a_RS_S_y [m s^-2],b_a_RS_S_z [m s^-2]";
const char kVisibilityCsvHeader[] = "#timestamp [ns],n_stereo_left,n_stereo_right,n_mono,stage";
const char kFaultsCsvHeader[] = "#timestamp [ns],sensor,kind,detail";

namespace {

constexpr int64_t kNoTime = std::numeric_limits<int64_t>::min();
// An IMU time stamp this much before the previous one is a clock jump, not jitter.
constexpr int64_t kImuClockJumpBackNs = 100'000'000;

std::string Join(int64_t t_ns, std::initializer_list<double> values) {
  std::string line = std::to_string(t_ns);
  for (double v : values) {
    line += ',';
    line += FormatDouble(v);
  }
  return line;
}

// Reads the timestamp column and checks it strictly increases.
int64_t ReadTime(const CsvReader& reader, int64_t* previous) {
  const int64_t t = reader.Int64(0);
  if (*previous != kNoTime) CheckIncreasingTime(reader, *previous, t);
  *previous = t;
  return t;
}

// In lenient mode (skipped != null): true when the row must be left out (a non-finite number
// in columns [1, last_numeric] or a timestamp that does not increase), with the reason logged.
bool SkipRow(const CsvReader& reader, int last_numeric, const int64_t* previous,
             std::vector<std::string>* skipped) {
  if (skipped == nullptr) return false;
  std::string why;
  if (reader.HasNonFiniteNumber(1, last_numeric)) {
    why = "NaN/Inf";
  } else if (*previous != kNoTime && reader.Int64(0) <= *previous) {
    why = "timestamp not increasing";
  }
  if (why.empty()) return false;
  skipped->push_back(reader.path() + ": line " + std::to_string(reader.line()) + ": " + why +
                     ": row skipped");
  return true;
}

Eigen::Vector3d Read3(const CsvReader& reader, int first) {
  return Eigen::Vector3d(reader.Double(first), reader.Double(first + 1), reader.Double(first + 2));
}

}  // namespace

std::vector<ImuSample> ReadImuCsv(const std::string& path, std::vector<std::string>* skipped) {
  CsvReader reader(path, {"timestamp", "w_RS_S_x", "w_RS_S_y", "w_RS_S_z", "a_RS_S_x",
                          "a_RS_S_y", "a_RS_S_z"});
  std::vector<ImuSample> samples;
  int64_t previous = kNoTime;
  while (reader.Next()) {
    // A clock that jumps back (more than jitter): the rows after it carry times that are not
    // the times of the motion they measured, and integrating them as if they were drags the
    // estimate away while it looks sure of itself. Lenient mode skips the rest of the file (an
    // IMU outage: the estimator resets and goes on from vision).
    if (skipped != nullptr && previous != kNoTime &&
        previous - reader.Int64(0) > kImuClockJumpBackNs) {
      const double jump_s = static_cast<double>(previous - reader.Int64(0)) * 1e-9;
      const int line = reader.line();
      int rest = 0;
      while (reader.Next()) ++rest;
      skipped->push_back(reader.path() + ": line " + std::to_string(line) +
                         ": the clock jumped back by " + FormatDouble(jump_s) +
                         " s: this and the " + std::to_string(rest) +
                         " rows after it skipped (their times are not those of the motion)");
      break;
    }
    if (SkipRow(reader, 6, &previous, skipped)) continue;
    ImuSample s;
    s.t_ns = ReadTime(reader, &previous);
    s.gyro = Read3(reader, 1);
    s.accel = Read3(reader, 4);
    samples.push_back(s);
  }
  return samples;
}

std::vector<CameraFrame> ReadCameraCsv(const std::string& path, const std::string& image_dir,
                                       std::vector<std::string>* skipped) {
  CsvReader reader(path, {"timestamp", "filename"});
  std::vector<CameraFrame> frames;
  int64_t previous = kNoTime;
  while (reader.Next()) {
    if (SkipRow(reader, 0, &previous, skipped)) continue;
    CameraFrame f;
    f.t_ns = ReadTime(reader, &previous);
    const std::string& name = reader.String(1);
    if (name.empty() || name.find("..") != std::string::npos || name[0] == '/') {
      reader.FailColumn(1, "expected a file name inside the data/ folder ('" + name + "')");
    }
    f.path = image_dir + "/" + name;
    frames.push_back(f);
  }
  return frames;
}

std::vector<DepthMeasurement> ReadDepthCsv(const std::string& path,
                                           std::vector<std::string>* skipped) {
  CsvReader reader(path, {"timestamp", "depth"});
  std::vector<DepthMeasurement> out;
  int64_t previous = kNoTime;
  while (reader.Next()) {
    if (SkipRow(reader, 1, &previous, skipped)) continue;
    DepthMeasurement m;
    m.t_ns = ReadTime(reader, &previous);
    m.depth_m = reader.Double(1);
    out.push_back(m);
  }
  return out;
}

std::vector<HeadingMeasurement> ReadHeadingCsv(const std::string& path,
                                               std::vector<std::string>* skipped) {
  CsvReader reader(path, {"timestamp", "heading"});
  std::vector<HeadingMeasurement> out;
  int64_t previous = kNoTime;
  while (reader.Next()) {
    if (SkipRow(reader, 1, &previous, skipped)) continue;
    HeadingMeasurement m;
    m.t_ns = ReadTime(reader, &previous);
    m.heading_rad = reader.Double(1);
    out.push_back(m);
  }
  return out;
}

std::vector<DvlMeasurement> ReadDvlCsv(const std::string& path,
                                       std::vector<std::string>* skipped) {
  CsvReader reader(path, {"timestamp", "v_S_x", "v_S_y", "v_S_z"});
  std::vector<DvlMeasurement> out;
  int64_t previous = kNoTime;
  while (reader.Next()) {
    if (SkipRow(reader, 3, &previous, skipped)) continue;
    DvlMeasurement m;
    m.t_ns = ReadTime(reader, &previous);
    m.v_S = Read3(reader, 1);
    out.push_back(m);
  }
  return out;
}

std::vector<AcousticFix> ReadAcousticCsv(const std::string& path,
                                         std::vector<std::string>* skipped) {
  // The latency column is optional (a log without it: the fixes arrived at once).
  CsvReader reader(path, {"timestamp", "p_D_x", "p_D_y", "p_D_z", "sigma", "latency"},
                   /*allow_extra=*/false, /*optional_last=*/1);
  std::vector<AcousticFix> out;
  int64_t previous = kNoTime;
  while (reader.Next()) {
    if (SkipRow(reader, 4, &previous, skipped)) continue;
    AcousticFix m;
    m.t_ns = ReadTime(reader, &previous);
    m.p_D = Read3(reader, 1);
    m.sigma_m = reader.Double(4);
    if (!(m.sigma_m > 0.0)) reader.FailColumn(4, "must be positive");
    if (reader.size() > 5) {
      m.latency_ns = reader.Int64(5);
      if (m.latency_ns < 0) {
        reader.FailColumn(5, "must not be negative (a fix cannot arrive before it is measured)");
      }
    }
    out.push_back(m);
  }
  return out;
}

std::vector<SblRange> ReadSblCsv(const std::string& path, int num_transducers,
                                 std::vector<std::string>* skipped) {
  CsvReader reader(path, {"timestamp", "transducer", "range", "sigma"});
  std::vector<SblRange> out;
  int64_t previous_t = kNoTime;
  int previous_transducer = -1;
  while (reader.Next()) {
    const int64_t t = reader.Int64(0);
    const int64_t transducer = reader.Int64(1);
    if (transducer < 0 || transducer >= num_transducers) {
      reader.FailColumn(1, "expected a transducer index from 0 to " +
                               std::to_string(num_transducers - 1) + " (the calibration's)");
    }
    const bool in_order =
        previous_t == kNoTime || t > previous_t ||
        (t == previous_t && transducer > previous_transducer);
    std::string why;
    if (reader.HasNonFiniteNumber(2, 3)) {
      why = "NaN/Inf";
    } else if (!in_order) {
      why = "not after the previous row (timestamp, then transducer, must increase)";
    }
    if (!why.empty()) {
      if (skipped == nullptr) reader.Fail(why);
      skipped->push_back(path + ": line " + std::to_string(reader.line()) + ": " + why +
                         ": row skipped");
      continue;
    }
    SblRange m;
    m.t_ns = t;
    m.transducer = static_cast<int>(transducer);
    m.range_m = reader.Double(2);
    if (m.range_m < 0.0) reader.FailColumn(2, "a range cannot be negative");
    m.sigma_m = reader.Double(3);
    if (!(m.sigma_m > 0.0)) reader.FailColumn(3, "must be positive");
    previous_t = t;
    previous_transducer = m.transducer;
    out.push_back(m);
  }
  return out;
}

std::vector<GroundTruthState> ReadGroundTruthCsv(const std::string& path) {
  CsvReader reader(path, {"timestamp", "p_RS_R_x", "p_RS_R_y", "p_RS_R_z", "q_RS_w", "q_RS_x",
                          "q_RS_y", "q_RS_z", "v_RS_R_x", "v_RS_R_y", "v_RS_R_z", "b_w_RS_S_x",
                          "b_w_RS_S_y", "b_w_RS_S_z", "b_a_RS_S_x", "b_a_RS_S_y", "b_a_RS_S_z"});
  std::vector<GroundTruthState> out;
  int64_t previous = kNoTime;
  while (reader.Next()) {
    GroundTruthState s;
    s.t_ns = ReadTime(reader, &previous);
    const Eigen::Vector3d p = Read3(reader, 1);
    const Eigen::Quaterniond q(reader.Double(4), reader.Double(5), reader.Double(6),
                               reader.Double(7));
    if (std::abs(q.norm() - 1.0) > 1e-3) reader.Fail("quaternion is not unit length");
    s.T_D_B = Pose3(q, p);
    s.v_D = Read3(reader, 8);
    s.gyro_bias = Read3(reader, 11);
    s.accel_bias = Read3(reader, 14);
    out.push_back(s);
  }
  return out;
}

std::vector<VisibilityRecord> ReadVisibilityCsv(const std::string& path) {
  CsvReader reader(path, {"timestamp", "n_stereo_left", "n_stereo_right", "n_mono", "stage"});
  std::vector<VisibilityRecord> out;
  int64_t previous = kNoTime;
  while (reader.Next()) {
    VisibilityRecord r;
    r.t_ns = ReadTime(reader, &previous);
    r.n_stereo_left = static_cast<int>(reader.Int64(1));
    r.n_stereo_right = static_cast<int>(reader.Int64(2));
    r.n_mono = static_cast<int>(reader.Int64(3));
    if (!ParseVisibilityStage(reader.String(4), &r.stage)) {
      reader.FailColumn(4, "unknown stage '" + reader.String(4) + "'");
    }
    out.push_back(r);
  }
  return out;
}

std::vector<FaultRecord> ReadFaultsCsv(const std::string& path) {
  CsvReader reader(path, {"timestamp", "sensor", "kind", "detail"});
  std::vector<FaultRecord> out;
  while (reader.Next()) {
    FaultRecord f;
    f.t_ns = reader.Int64(0);
    f.sensor = reader.String(1);
    f.kind = reader.String(2);
    f.detail = reader.String(3);
    out.push_back(f);
  }
  return out;
}

std::string ImuCsvRow(const ImuSample& s) {
  return Join(s.t_ns, {s.gyro.x(), s.gyro.y(), s.gyro.z(), s.accel.x(), s.accel.y(), s.accel.z()});
}

std::string DepthCsvRow(const DepthMeasurement& m) { return Join(m.t_ns, {m.depth_m}); }

std::string HeadingCsvRow(const HeadingMeasurement& m) { return Join(m.t_ns, {m.heading_rad}); }

std::string DvlCsvRow(const DvlMeasurement& m) {
  return Join(m.t_ns, {m.v_S.x(), m.v_S.y(), m.v_S.z()});
}

std::string AcousticCsvRow(const AcousticFix& m) {
  return Join(m.t_ns, {m.p_D.x(), m.p_D.y(), m.p_D.z(), m.sigma_m}) + "," +
         std::to_string(m.latency_ns);
}

std::string SblCsvRow(const SblRange& m) {
  return std::to_string(m.t_ns) + "," + std::to_string(m.transducer) + "," +
         FormatDouble(m.range_m) + "," + FormatDouble(m.sigma_m);
}

std::string GroundTruthCsvRow(const GroundTruthState& s) {
  const Eigen::Vector3d& p = s.T_D_B.p;
  const Eigen::Quaterniond& q = s.T_D_B.q;
  return Join(s.t_ns, {p.x(), p.y(), p.z(), q.w(), q.x(), q.y(), q.z(), s.v_D.x(), s.v_D.y(),
                       s.v_D.z(), s.gyro_bias.x(), s.gyro_bias.y(), s.gyro_bias.z(),
                       s.accel_bias.x(), s.accel_bias.y(), s.accel_bias.z()});
}

std::string VisibilityCsvRow(const VisibilityRecord& r) {
  return std::to_string(r.t_ns) + "," + std::to_string(r.n_stereo_left) + "," +
         std::to_string(r.n_stereo_right) + "," + std::to_string(r.n_mono) + "," +
         VisibilityStageName(r.stage);
}

std::string FaultCsvRow(const FaultRecord& f) {
  return std::to_string(f.t_ns) + "," + f.sensor + "," + f.kind + "," + f.detail;
}

}  // namespace auvdock
