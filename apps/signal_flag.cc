#include "apps/signal_flag.h"

#include <atomic>
#include <csignal>

namespace auvdock::cli {

namespace {

std::atomic<bool> g_cancel_requested{false};
static_assert(std::atomic<bool>::is_always_lock_free);

extern "C" void OnSignal(int) { g_cancel_requested.store(true); }

}  // namespace

CancellationToken InstallSignalCancellation() {
  std::signal(SIGINT, OnSignal);
  std::signal(SIGTERM, OnSignal);
  return CancellationToken(&g_cancel_requested);
}

}  // namespace auvdock::cli
