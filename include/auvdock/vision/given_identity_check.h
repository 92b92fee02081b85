// Identities that come with the detections (`run` / `smooth --detections FILE`: a front-end of
// the user's, a learned detector, or our own `frontend` output) are a claim about the image,
// checked against the dock model before the estimator sees them. A wrong identity moves a
// light by tens of pixels, which a pose through the other lights exposes.
//
// Method, for one image:
//   1. the claims: detections whose light_id is a light of the dock (a light claimed twice is
//      kept for the detection with the higher score; the other claim is dropped);
//   2. PnP on them (SolvePnp; from predicted_T_C_D when known, which also lets 3 lights do):
//      at least min_lights (4 without a prediction), else kFailed;
//   3. while the fit is not consistent with the camera's pixel noise (PoseFitConsistentWithNoise
//      at alpha: the chi-square of the residuals with 2n - 6 dof) and more than min_lights
//      claims remain: leave out the claim whose removal fits the rest best, solve again;
//   4. kOk with the kept claims (MatchResult::matches, cost = RMS residual px) and T_C_D, or
//      kFailed with the reason ("the given identities do not fit the dock: ..."): the caller
//      then identifies the image itself, ignoring the claims.
// A planar layout seen nearly head-on has two PnP minima that fit about equally (SolvePnp step
// 2b): the better one still tests the claims, but no T_C_D is returned (the pose is not known
// from these pixels). With 3 claims and a prediction the fit has no redundancy (6 residuals,
// 6 unknowns): such claims pass unchecked here, and the estimator's chi-square gate against
// its prediction is their test.
// Frames: D dock, C camera (OpenCV); pixels in the raw (distorted) image.
#pragma once

#include <optional>
#include <vector>

#include "auvdock/camera/pinhole_radtan_camera.h"
#include "auvdock/geometry/dock_model.h"
#include "auvdock/geometry/pose3.h"
#include "auvdock/vision/light_detection.h"

namespace auvdock {

struct GivenIdentityCheckOptions {
  double pixel_noise_px = 0.3;  // 1 sigma per axis (CameraCalibration::pixel_noise_px)
  double alpha = 1e-4;          // false-alarm rate of the consistency test
  int min_lights = 4;           // without a prediction; 3 with one
};

struct GivenIdentityCheck {
  MatchResult match;   // kOk: the claims kept; kFailed: none, with the reason
  // The PnP pose on the kept claims (kOk only; none when two minima fit them equally well).
  std::optional<Pose3> T_C_D;
  int dropped = 0;     // claims left out (a light claimed twice, or not fitting)
};

GivenIdentityCheck CheckGivenIdentities(const std::vector<LightDetection>& detections,
                                        const std::vector<int>& claimed_ids,
                                        const DockModel& dock, const PinholeRadtanCamera& camera,
                                        const GivenIdentityCheckOptions& options,
                                        const std::optional<Pose3>& predicted_T_C_D);

}  // namespace auvdock
