#include "core/interrupt.h"

#include <csignal>

#include "core/errors.h"

namespace skybake {

namespace {

constexpr int kSignals[] = {SIGINT, SIGTERM};
volatile std::sig_atomic_t pending_signal = 0;
int scope_depth = 0;
struct sigaction previous_actions[2];

extern "C" void RecordSignal(int signal) {
  if (pending_signal != 0) {  // asked twice: stop now
    std::signal(signal, SIG_DFL);
    std::raise(signal);
  }
  pending_signal = signal;
}

const char* SignalName(int signal) { return signal == SIGTERM ? "SIGTERM" : "SIGINT"; }

}  // namespace

InterruptScope::InterruptScope() {
  if (scope_depth++ > 0) return;
  struct sigaction action {};
  action.sa_handler = RecordSignal;
  sigemptyset(&action.sa_mask);
  for (int i = 0; i < 2; ++i) sigaction(kSignals[i], &action, &previous_actions[i]);
}

InterruptScope::~InterruptScope() {
  if (--scope_depth > 0) return;
  for (int i = 0; i < 2; ++i) sigaction(kSignals[i], &previous_actions[i], nullptr);
}

int PendingInterrupt() { return pending_signal; }

int TakeInterrupt() {
  const int signal = pending_signal;
  pending_signal = 0;
  return signal;
}

void ThrowIfInterrupted(const std::string& what) {
  if (const int signal = TakeInterrupt()) {
    throw InterruptedError(std::string("interrupted by ") + SignalName(signal) + ": " + what);
  }
}

}  // namespace skybake
