// The exception for bad input from files and users (never for programmer errors, which assert).
//
// The message is one line that names the file and, where there is one, the key or line:
//   "scenario.yaml: key 'imu.rate_hz': must be positive (got -200)".
// The CLI catches it, prints "auvdock: error: <message>" and exits with status 2.
#pragma once

#include <stdexcept>
#include <string>

namespace auvdock {

class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& message) : std::runtime_error(message) {}
};

}  // namespace auvdock
