// Cooperative cancellation for long-running commands (simulate, run, smooth).
//
// The CLI owns an std::atomic<bool> that its SIGINT/SIGTERM handler sets; library code that
// loops over frames receives a CancellationToken and calls ThrowIfCancelled() between units of
// work, so it can stop cleanly (remove a staging folder, keep flushed output).
#pragma once

#include <atomic>
#include <stdexcept>

namespace auvdock {

class Cancelled : public std::runtime_error {
 public:
  Cancelled() : std::runtime_error("cancelled by signal") {}
};

class CancellationToken {
 public:
  CancellationToken() = default;  // never cancelled
  explicit CancellationToken(const std::atomic<bool>* flag) : flag_(flag) {}
  bool IsCancelled() const { return flag_ != nullptr && flag_->load(std::memory_order_relaxed); }
  void ThrowIfCancelled() const {
    if (IsCancelled()) throw Cancelled();
  }

 private:
  const std::atomic<bool>* flag_ = nullptr;
};

}  // namespace auvdock
