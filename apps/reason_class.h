// Counting "why not" reasons: the class of a reason is its text up to the first figure or detail
// ("only 2 detections (need 4)" and "only 3 detections (need 4)" are both "only"), so that the
// counts in summary.json and on stdout group alike reasons.
#pragma once

#include <string>

namespace auvdock::cli {

inline std::string ReasonClass(const std::string& reason) {
  std::string key = reason.substr(0, reason.find_first_of("0123456789({"));
  while (!key.empty() && (key.back() == ' ' || key.back() == ',' || key.back() == ':')) key.pop_back();
  return key.empty() ? reason : key;
}

}  // namespace auvdock::cli
