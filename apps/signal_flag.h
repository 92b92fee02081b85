// SIGINT/SIGTERM -> a cancellation flag that long-running commands poll. A signal handler can
// only touch a lock-free atomic, so this one flag is process-wide by necessity.
#pragma once

#include "auvdock/io/cancellation.h"

namespace auvdock::cli {

// Installs the handlers (idempotent) and returns a token observing the flag.
CancellationToken InstallSignalCancellation();

}  // namespace auvdock::cli
