#include "interrupt.hpp"

#include <csignal>
#include <unistd.h>

namespace scfloam::cli {
namespace {

std::atomic<bool> g_stop{false};
std::atomic<int> g_signal{0};
static_assert(std::atomic<bool>::is_always_lock_free && std::atomic<int>::is_always_lock_free,
              "the handler may only touch lock-free atomics");

extern "C" void on_interrupt(int sig) {
  if (g_stop.load()) {
    // Second signal: the user does not want to wait for the outputs. Only async-signal-safe
    // calls here; outputs are renamed into place whole, so nothing half-written is left.
    static const char msg[] = "\ninterrupted again: exiting without writing results\n";
    ssize_t ignored = write(STDERR_FILENO, msg, sizeof msg - 1);
    (void)ignored;
    _exit(128 + sig);
  }
  g_signal.store(sig);
  g_stop.store(true);
  static const char msg[] = "\ninterrupted: finishing the current frame and writing results "
                            "(interrupt again to quit at once)\n";
  ssize_t ignored = write(STDERR_FILENO, msg, sizeof msg - 1);
  (void)ignored;
}

}  // namespace

const std::atomic<bool>& install_interrupt_handlers() {
  struct sigaction action {};
  action.sa_handler = on_interrupt;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESTART;  // reads of the input continue undisturbed
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
  return g_stop;
}

int interrupt_signal() { return g_signal.load(); }

}  // namespace scfloam::cli
