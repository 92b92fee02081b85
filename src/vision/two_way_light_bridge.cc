#include "auvdock/vision/two_way_light_bridge.h"

#include <algorithm>
#include <cstdlib>
#include <numeric>

namespace auvdock {
namespace {

// A tracking chain: posed frames each tracked from the one before (frames without a pose may lie
// between them); one labelling hypothesis carried along.
struct Chain {
  std::vector<int> frames;  // posed, in time order
  bool refuted = false;
  int refuted_by = -1;
  int contradicted = 0;  // refuted as a lone pose for this many lights judged none
};

class Bridge {
 public:
  Bridge(FewLightTracker* tracker, const TwoWayLightBridgeOptions& options,
         std::vector<BridgedFrame>* frames)
      : tracker_(tracker), options_(options), frames_(*frames) {
    const int n = static_cast<int>(frames_.size());
    chain_of_.assign(n, -1);
    distance_.assign(n, n + 1);
    for (int k = 0; k < n; ++k) {
      if (!frames_[k].T_C_D) continue;
      if (!frames_[k].tracked || chains_.empty()) chains_.emplace_back();
      chains_.back().frames.push_back(k);
      chain_of_[k] = static_cast<int>(chains_.size()) - 1;
    }
  }

  // Pass 1: the longest chains first walk into their neighbours and refute a chain whose own
  // labels explain decisively fewer detections than the walk labels in the frame where they meet.
  void Refute() {
    std::vector<int> order(chains_.size());
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
      return chains_[a].frames.size() > chains_[b].frames.size();
    });
    for (int c : order) {
      if (chains_[c].refuted) continue;
      Walk(c, +1, /*record=*/false);
      if (options_.backward) Walk(c, -1, /*record=*/false);
    }
  }

  // Pass 2: every chain that stands walks into the frames without a pose beside it (and through
  // the refuted chains), recording the labels.
  void Record() {
    for (size_t c = 0; c < chains_.size(); ++c) {
      if (chains_[c].refuted) continue;
      Walk(static_cast<int>(c), +1, /*record=*/true);
      if (options_.backward) Walk(static_cast<int>(c), -1, /*record=*/true);
    }
    for (const Chain& chain : chains_) {
      if (!chain.refuted) continue;
      for (int k : chain.frames) {
        frames_[k].refuted = true;
        frames_[k].refuted_by = chain.refuted_by;
        frames_[k].contradicted = chain.contradicted;
      }
    }
  }

 private:
  bool Stands(int k) const { return chain_of_[k] >= 0 && !chains_[chain_of_[k]].refuted; }

  // The frame's detections that its own pose took for lights and the walk's step judges no
  // light of the dock.
  static int Contradicted(const BridgedFrame& frame, const FewLightStep& step) {
    int contradicted = 0;
    for (size_t i = 0; i < frame.own_light_ids.size() && i < step.unexplained.size(); ++i) {
      contradicted += frame.own_light_ids[i] >= 0 && step.unexplained[i];
    }
    return contradicted;
  }

  // Walks from chain c's end (step +1: forward from its last frame; -1: backward from its first)
  // while frames without a standing pose follow; a chain too short to start a walk is walked
  // through (its own labels stay unless refuted).
  void Walk(int c, int step, bool record) {
    const std::vector<int>& own = chains_[c].frames;
    // The consecutive posed frames at that end, in walking order.
    std::vector<int> start;
    const int end = step > 0 ? own.back() : own.front();
    for (int k = end; k >= 0 && k < static_cast<int>(frames_.size()) && chain_of_[k] == c;
         k -= step) {
      start.insert(start.begin(), k);
    }
    std::vector<Pose3> poses;
    std::vector<FewLightTracker::Matrix6> covariances;
    std::vector<double> sigmas;
    for (int k : start) {
      poses.push_back(*frames_[k].T_C_D);
      covariances.push_back(frames_[k].covariance_local);
      sigmas.push_back(frames_[k].residual_sigma_px);
    }
    std::nth_element(sigmas.begin(), sigmas.begin() + sigmas.size() / 2, sigmas.end());
    if (!tracker_->Start(poses, covariances, sigmas[sigmas.size() / 2])) return;
    const int n = static_cast<int>(frames_.size());
    for (int k = end + step; k >= 0 && k < n; k += step) {
      const int other = chain_of_[k];
      if (other == c) return;
      BridgedFrame& frame = frames_[k];
      const std::optional<FewLightStep> result = tracker_->Step(frame.detections, frame.doubtful);
      if (!result) return;
      if (Stands(k)) {
        Chain& chain = chains_[other];
        const bool decisive = result->labelled >= frame.identified() + options_.refute_margin;
        if (!record && decisive && own.size() > chain.frames.size()) {
          chain.refuted = true;
          chain.refuted_by = end;
        } else if (static_cast<int>(chain.frames.size()) < options_.tracker.min_start_poses) {
          // A lone pose among frames without one: walked through, and refuted when the walk
          // finds what it took for lights to be none.
          const int contradicted = Contradicted(frame, *result);
          if (!record && options_.lone_refute_contradicted > 0 &&
              contradicted >= options_.lone_refute_contradicted) {
            chain.refuted = true;
            chain.refuted_by = end;
            chain.contradicted = contradicted;
          }
          continue;
        } else {
          return;
        }
      }
      if (!record) continue;
      const int walked = std::abs(k - end);
      if (walked >= distance_[k]) continue;
      distance_[k] = walked;
      frame.bridged = true;
      frame.anchor_frame = end;
      frame.light_ids = result->light_ids;
      frame.unexplained = result->unexplained;
      frame.doubtful_light_ids = result->doubtful_light_ids;
      frame.walk_T_C_D = result->T_C_D;
    }
  }

  FewLightTracker* tracker_;
  const TwoWayLightBridgeOptions& options_;
  std::vector<BridgedFrame>& frames_;
  std::vector<Chain> chains_;
  std::vector<int> chain_of_;
  std::vector<int> distance_;
};

}  // namespace

int BridgeFramesWithoutPose(const PinholeRadtanCamera& camera, const DockModel& dock,
                            double frame_interval_s, const TwoWayLightBridgeOptions& options,
                            std::vector<BridgedFrame>* frames) {
  FewLightTracker tracker(camera, dock, frame_interval_s, options.tracker);
  Bridge bridge(&tracker, options, frames);
  if (options.refute_margin > 0) bridge.Refute();
  bridge.Record();
  int bridged = 0;
  for (const BridgedFrame& f : *frames) bridged += f.bridged;
  return bridged;
}

}  // namespace auvdock
