// Counting "why not" reasons: the class of a reason is its text with every figure written as N
// and the details after it dropped (a parenthesis, a brace, a second sentence), so that
// "only 2 detections (need 4)" and "only 3 detections (need 4)" are both "only N detections" and
// the counts in summary.json and on stdout group alike reasons under a sentence that still reads.
#pragma once

#include <cctype>
#include <string>

namespace auvdock::cli {

inline std::string ReasonClass(const std::string& reason) {
  const auto is = [&](std::size_t j, char what) { return j < reason.size() && reason[j] == what; };
  const auto digit_at = [&](std::size_t j) {
    return j < reason.size() && std::isdigit(static_cast<unsigned char>(reason[j]));
  };
  std::string key;
  for (std::size_t i = 0; i < reason.size(); ++i) {
    const char c = reason[i];
    if (c == '(' || c == '{' || c == '[' || c == ';') break;
    if (digit_at(i)) {
      // A figure (123, 1.5, 1.5e-3) becomes one N; "4-fold" stays "N-fold".
      while (digit_at(i + 1) || (is(i + 1, '.') && digit_at(i + 2))) ++i;
      if (is(i + 1, 'e') && (digit_at(i + 2) || (is(i + 2, '-') && digit_at(i + 3)))) {
        i += is(i + 2, '-') ? 3 : 2;
        while (digit_at(i + 1)) ++i;
      }
      key += 'N';
      continue;
    }
    key += c;
  }
  while (!key.empty() && (key.back() == ' ' || key.back() == ',' || key.back() == ':' ||
                          key.back() == '.'))
    key.pop_back();
  return key.empty() ? reason : key;
}

}  // namespace auvdock::cli
