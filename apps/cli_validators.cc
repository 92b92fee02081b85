#include "apps/cli_validators.h"

#include <cmath>
#include <cstdlib>

namespace auvdock::cli {
namespace {

CLI::Validator Bounded(const std::string& unit, bool zero_allowed) {
  return CLI::Validator(
      [unit, zero_allowed](std::string& text) {
        char* end = nullptr;
        const double value = std::strtod(text.c_str(), &end);
        const bool ok = !text.empty() && *end == '\0' && std::isfinite(value) &&
                        (zero_allowed ? value >= 0.0 : value > 0.0);
        if (!ok) {
          return std::string("must be a ") + (zero_allowed ? "non-negative" : "positive") +
                 " number of " + unit + " (got '" + text + "')";
        }
        return std::string();
      },
      zero_allowed ? "NON-NEGATIVE" : "POSITIVE");
}

}  // namespace

CLI::Validator Positive(const std::string& unit) { return Bounded(unit, false); }
CLI::Validator NonNegative(const std::string& unit) { return Bounded(unit, true); }

}  // namespace auvdock::cli
