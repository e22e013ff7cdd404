// SIGINT / SIGTERM during a long command: the first signal asks the work to stop at the next
// safe point (the caller then writes what it has), a second one exits at once.
#pragma once

#include <atomic>

namespace scfloam::cli {

// Installs the handlers (idempotent) and returns the flag they set. Exit code after a second
// signal: 128 + the signal number (130 for Ctrl-C).
const std::atomic<bool>& install_interrupt_handlers();

// The signal that set the flag (SIGINT or SIGTERM), 0 when none arrived.
int interrupt_signal();

}  // namespace scfloam::cli
