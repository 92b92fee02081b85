#include "auvdock/vision/light_detection.h"

namespace auvdock {

const char* MatchStatusName(MatchStatus status) {
  switch (status) {
    case MatchStatus::kOk:
      return "ok";
    case MatchStatus::kAmbiguous:
      return "ambiguous";
    case MatchStatus::kFailed:
      break;
  }
  return "failed";
}

}  // namespace auvdock
