// Writes a dataset folder in auvdock's layout (docs/dataset_format.md), sensor by sensor, as
// the data is produced: every CSV row is flushed when added and every image is written when
// added, so memory stays flat for long runs.
#pragma once

#include <map>
#include <memory>
#include <vector>
#include <string>

#include <opencv2/core.hpp>

#include "auvdock/geometry/dock_model.h"
#include "auvdock/io/calibration.h"
#include "auvdock/io/csv.h"
#include "auvdock/io/detections_csv.h"
#include "auvdock/io/measurements.h"
#include "auvdock/io/tum_io.h"

namespace auvdock {

class DatasetWriter {
 public:
  // Writes calibration.yaml and dock.yaml into root (which must exist) and opens the sensor
  // files of every sensor the calibration has.
  DatasetWriter(const std::string& root, const Calibration& calibration, const DockModel& dock);

  void AddImu(const ImuSample& s);
  void AddDepth(const DepthMeasurement& m);
  void AddDvl(const DvlMeasurement& m);
  void AddHeading(const HeadingMeasurement& m);
  void AddAcoustic(const AcousticFix& m);
  void AddSbl(const SblRange& m);
  // Writes <camera>/data/<t_ns>.png (lossless, 8-bit) and its data.csv row.
  void AddImage(const std::string& camera, int64_t t_ns, const cv::Mat& image);
  // The two halves of AddImage: WriteImageFile is const and may run on several threads at once
  // (for different images); AddImageRow appends the data.csv row, in time order.
  void WriteImageFile(const std::string& camera, int64_t t_ns, const cv::Mat& image) const;
  void AddImageRow(const std::string& camera, int64_t t_ns);
  // Appends the lights drawn in one rendered image to groundtruth/<camera>_lights.csv, in the
  // hand-label format (io/light_labels_csv.h) that `auvdock detect --labels` reads: status `ok`
  // when the blob lies 3 sigma + 1 px inside the image, `border` otherwise; a frame without a
  // light gets one row with status `none`.
  void AddLightTruth(const std::string& camera, int64_t t_ns,
                         const std::vector<LightTruth>& lights, int width, int height);
  void AddGroundTruth(const GroundTruthState& s);  // also appends to groundtruth.tum
  void AddVisibility(const VisibilityRecord& r);
  void AddFault(const FaultRecord& f);
  // Appends one image's detections to detections.csv (io/detections_csv.h), created on the
  // first call: the synthetic front-end's output (`cameras.render_images: false`).
  void AddDetections(const ImageDetections& image);
  void Close();

  const std::string& root() const { return root_; }

 private:
  std::string root_;
  std::unique_ptr<CsvWriter> imu_, depth_, dvl_, heading_, acoustic_, sbl_, groundtruth_, visibility_, faults_;
  std::unique_ptr<TumWriter> tum_;
  std::map<std::string, std::unique_ptr<CsvWriter>> cameras_;
  std::map<std::string, std::unique_ptr<CsvWriter>> rendered_lights_;
  std::unique_ptr<DetectionsCsvWriter> detections_;
};

}  // namespace auvdock
