#include "auvdock/vision/two_way_light_bridge.h"

#include <algorithm>
#include <cstdlib>
#include <utility>

namespace auvdock {
namespace {

// Walks from the posed frames [first, last] (in walking order: step = +1 forward from last,
// -1 backward from first) until the next run of posed frames that a walk could start from
// (anchor), through the frames of shorter runs, whose own labels stay, and records each reached
// frame without a pose when it is nearer to its anchor than what another walk recorded there
// (distance[k]).
void Walk(FewLightTracker* tracker, int first, int last, int step, const std::vector<bool>& anchor,
          std::vector<BridgedFrame>* frames, std::vector<int>* distance) {
  std::vector<Pose3> poses;
  std::vector<FewLightTracker::Matrix6> covariances;
  std::vector<double> sigmas;
  const int from = step > 0 ? first : last, to = step > 0 ? last : first;
  for (int k = from;; k += step) {
    poses.push_back(*(*frames)[k].T_C_D);
    covariances.push_back((*frames)[k].covariance_local);
    sigmas.push_back((*frames)[k].residual_sigma_px);
    if (k == to) break;
  }
  std::nth_element(sigmas.begin(), sigmas.begin() + sigmas.size() / 2, sigmas.end());
  if (!tracker->Start(poses, covariances, sigmas[sigmas.size() / 2])) return;
  const int n = static_cast<int>(frames->size());
  for (int k = to + step; k >= 0 && k < n && !anchor[k]; k += step) {
    BridgedFrame& frame = (*frames)[k];
    const std::optional<FewLightStep> result = tracker->Step(frame.detections);
    if (!result) return;
    if (frame.T_C_D) continue;
    const int walked = std::abs(k - to);
    if (walked >= (*distance)[k]) continue;
    (*distance)[k] = walked;
    frame.bridged = true;
    frame.anchor_frame = to;
    frame.light_ids = result->light_ids;
    frame.unexplained = result->unexplained;
  }
}

}  // namespace

int BridgeFramesWithoutPose(const PinholeRadtanCamera& camera, const DockModel& dock,
                            double frame_interval_s, const TwoWayLightBridgeOptions& options,
                            std::vector<BridgedFrame>* frames) {
  FewLightTracker tracker(camera, dock, frame_interval_s, options.tracker);
  const int n = static_cast<int>(frames->size());
  std::vector<int> distance(n, n + 1);
  std::vector<std::pair<int, int>> runs;  // [first, last] of the posed runs a walk starts from
  std::vector<bool> anchor(n, false);
  for (int k = 0; k < n;) {
    if (!(*frames)[k].T_C_D) {
      ++k;
      continue;
    }
    int end = k;
    while (end + 1 < n && (*frames)[end + 1].T_C_D) ++end;
    if (end - k + 1 >= options.tracker.min_start_poses) {
      runs.emplace_back(k, end);
      std::fill(anchor.begin() + k, anchor.begin() + end + 1, true);
    }
    k = end + 1;
  }
  for (const auto& [first, last] : runs) {
    Walk(&tracker, first, last, +1, anchor, frames, &distance);
    if (options.backward) Walk(&tracker, first, last, -1, anchor, frames, &distance);
  }
  int bridged = 0;
  for (const BridgedFrame& f : *frames) bridged += f.bridged;
  return bridged;
}

}  // namespace auvdock
