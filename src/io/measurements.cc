#include "auvdock/io/measurements.h"

namespace auvdock {

const char* VisibilityStageName(VisibilityStage stage) {
  switch (stage) {
    case VisibilityStage::kStereoOnly:
      return "stereo_only";
    case VisibilityStage::kBoth:
      return "both";
    case VisibilityStage::kMonoOnly:
      return "mono_only";
    case VisibilityStage::kNeither:
      return "neither";
    case VisibilityStage::kUnknown:
      break;
  }
  return "unknown";
}

bool ParseVisibilityStage(const std::string& text, VisibilityStage* stage) {
  for (VisibilityStage s : {VisibilityStage::kStereoOnly, VisibilityStage::kBoth,
                            VisibilityStage::kMonoOnly, VisibilityStage::kNeither,
                            VisibilityStage::kUnknown}) {
    if (text == VisibilityStageName(s)) {
      *stage = s;
      return true;
    }
  }
  return false;
}

VisibilityStage StageFromLightCounts(int n_stereo_left, int n_stereo_right, int n_mono) {
  const bool stereo = n_stereo_left >= kMinLightsForPose && n_stereo_right >= kMinLightsForPose;
  const bool mono = n_mono >= kMinLightsForPose;
  if (stereo && mono) return VisibilityStage::kBoth;
  if (stereo) return VisibilityStage::kStereoOnly;
  if (mono) return VisibilityStage::kMonoOnly;
  return VisibilityStage::kNeither;
}

}  // namespace auvdock
