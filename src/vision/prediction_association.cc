#include "auvdock/vision/prediction_association.h"

#include <limits>

namespace auvdock {

std::vector<int> AssociateByPrediction(const std::vector<LightDetection>& detections,
                                       const std::vector<PredictedLight>& predicted,
                                       const PredictionAssociationOptions& options) {
  std::vector<int> ids(detections.size(), -1);
  for (size_t j = 0; j < detections.size(); ++j) {
    const double gate = options.gate_px + options.radius_fraction * detections[j].radius_px;
    // The nearest light and the distance of the second nearest.
    int nearest = -1;
    double d_nearest = std::numeric_limits<double>::infinity();
    double d_second = std::numeric_limits<double>::infinity();
    for (size_t l = 0; l < predicted.size(); ++l) {
      const double d = (detections[j].uv - predicted[l].uv).norm();
      if (d < d_nearest) {
        d_second = d_nearest;
        d_nearest = d;
        nearest = static_cast<int>(l);
      } else if (d < d_second) {
        d_second = d;
      }
    }
    if (nearest < 0 || d_nearest > gate || d_second <= d_nearest + gate ||
        d_second < options.isolation_radii * detections[j].radius_px) {
      continue;
    }
    bool unique = true;
    for (size_t k = 0; k < detections.size() && unique; ++k) {
      if (k == j) continue;
      unique = (detections[k].uv - predicted[nearest].uv).norm() > d_nearest + gate;
    }
    if (unique) ids[j] = predicted[nearest].light_id;
  }
  return ids;
}

}  // namespace auvdock
