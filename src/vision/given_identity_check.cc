#include "auvdock/vision/given_identity_check.h"

#include <cmath>
#include <limits>
#include <map>
#include <string>

#include "auvdock/vision/pnp_solver.h"
#include "auvdock/vision/tracking_matcher.h"

namespace auvdock {

namespace {

struct Claim {
  int detection = -1;
  int light_id = -1;
  Eigen::Vector3d p_D;
};

// A fit of the claims. An ambiguous PnP (two minima that fit about equally, a planar layout
// seen nearly head-on) still tests the identities: both minima fit the claimed pixels, only the
// pose is unknown, so the best minimum gives the error and pose_known is false.
struct Fit {
  bool ok = false;
  std::string reason;
  Pose3 T_C_D;
  bool pose_known = false;
  double rms_px = 0.0;
  double squared_error_px2 = 0.0;
};

double SquaredError(const Pose3& T_C_D, const std::vector<Eigen::Vector3d>& points,
                    const std::vector<Eigen::Vector2d>& pixels, const PinholeRadtanCamera& camera) {
  double sum = 0.0;
  for (size_t i = 0; i < points.size(); ++i) {
    const std::optional<Eigen::Vector2d> uv = camera.Project(T_C_D * points[i]);
    if (!uv) return std::numeric_limits<double>::infinity();
    sum += (*uv - pixels[i]).squaredNorm();
  }
  return sum;
}

Fit SolveClaims(const std::vector<Claim>& claims, const std::vector<LightDetection>& detections,
                const PinholeRadtanCamera& camera, const PnpOptions& options,
                const std::optional<Pose3>& start) {
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector2d> pixels;
  for (const Claim& c : claims) {
    points.push_back(c.p_D);
    pixels.push_back(detections[c.detection].uv);
  }
  const PnpResult pnp = SolvePnp(points, pixels, camera, options, start);
  Fit fit;
  if (pnp.ok) {
    fit.ok = true;
    fit.pose_known = true;
    fit.T_C_D = pnp.T_C_D;
  } else if (!pnp.ambiguous_T_C_D.empty()) {
    fit.ok = true;
    fit.T_C_D = pnp.ambiguous_T_C_D.front();
  } else {
    fit.reason = pnp.reason;
    return fit;
  }
  fit.squared_error_px2 = SquaredError(fit.T_C_D, points, pixels, camera);
  fit.rms_px = std::sqrt(fit.squared_error_px2 / static_cast<double>(claims.size()));
  return fit;
}

GivenIdentityCheck Failed(const std::string& reason, int dropped) {
  GivenIdentityCheck check;
  check.match.status = MatchStatus::kFailed;
  check.match.reason = "the given identities do not fit the dock: " + reason;
  check.dropped = dropped;
  return check;
}

}  // namespace

GivenIdentityCheck CheckGivenIdentities(const std::vector<LightDetection>& detections,
                                        const std::vector<int>& claimed_ids,
                                        const DockModel& dock, const PinholeRadtanCamera& camera,
                                        const GivenIdentityCheckOptions& options,
                                        const std::optional<Pose3>& predicted_T_C_D) {
  // 1. One claim per light: the higher score keeps it.
  std::map<int, int> by_light;  // light id -> detection
  int dropped = 0;
  for (size_t i = 0; i < detections.size() && i < claimed_ids.size(); ++i) {
    const int id = claimed_ids[i];
    if (id < 0 || dock.FindLight(id) == nullptr) continue;
    auto [it, inserted] = by_light.try_emplace(id, static_cast<int>(i));
    if (!inserted) {
      ++dropped;
      if (detections[i].score > detections[it->second].score) it->second = static_cast<int>(i);
    }
  }
  std::vector<Claim> claims;
  for (const auto& [id, detection] : by_light) {
    claims.push_back({detection, id, dock.FindLight(id)->p_D});
  }
  // 2. PnP on the claims.
  const int min_lights = predicted_T_C_D ? std::min(3, options.min_lights) : options.min_lights;
  if (static_cast<int>(claims.size()) < min_lights) {
    return Failed("too few claimed lights: " + std::to_string(claims.size()) + ", " +
                      std::to_string(min_lights) + " needed",
                  dropped);
  }
  PnpOptions pnp_options;
  pnp_options.pixel_sigma = options.pixel_noise_px;
  Fit fit = SolveClaims(claims, detections, camera, pnp_options, predicted_T_C_D);
  if (!fit.ok) return Failed(fit.reason, dropped);
  // 3. Leave out the worst claim while the fit is not consistent with the noise.
  while (!PoseFitConsistentWithNoise(fit.squared_error_px2, static_cast<int>(claims.size()),
                                     options.pixel_noise_px, options.alpha)) {
    if (static_cast<int>(claims.size()) <= min_lights) {
      return Failed("RMS residual " + std::to_string(fit.rms_px) + " px on " +
                        std::to_string(claims.size()) + " lights",
                    dropped);
    }
    std::optional<Fit> best;
    size_t best_left_out = 0;
    for (size_t k = 0; k < claims.size(); ++k) {
      std::vector<Claim> rest = claims;
      rest.erase(rest.begin() + static_cast<std::ptrdiff_t>(k));
      // From the current pose and afresh: a wrong claim can have pulled the current pose into
      // a basin the right subset's solution is not in.
      for (const std::optional<Pose3>& start : {std::optional<Pose3>(fit.T_C_D), predicted_T_C_D}) {
        Fit candidate = SolveClaims(rest, detections, camera, pnp_options, start);
        if (!candidate.ok) continue;
        if (!best || candidate.squared_error_px2 < best->squared_error_px2) {
          best = candidate;
          best_left_out = k;
        }
      }
    }
    if (!best) return Failed("no subset of the claims gives a pose", dropped);
    claims.erase(claims.begin() + static_cast<std::ptrdiff_t>(best_left_out));
    ++dropped;
    fit = *best;
  }
  GivenIdentityCheck check;
  check.match.status = MatchStatus::kOk;
  check.match.cost = fit.rms_px;
  for (const Claim& c : claims) check.match.matches.push_back({c.detection, c.light_id});
  if (fit.pose_known) check.T_C_D = fit.T_C_D;
  check.dropped = dropped;
  return check;
}

}  // namespace auvdock
