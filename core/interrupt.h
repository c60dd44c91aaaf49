// Ctrl-C (SIGINT) and SIGTERM for work whose outputs must appear complete or
// not at all.
//
// While an InterruptScope lives, the first of these signals only records
// itself; the work calls ThrowIfInterrupted() where stopping leaves nothing
// half-written (between bake phases, before a staged set of files is
// committed), which throws InterruptedError (exit 130). A second signal ends
// the process at once, as without a scope. A signal recorded but never thrown
// arrived after the outputs were complete: main() reports it and exits 0.
// Outside any scope the signals keep their default action.
#pragma once

#include <string>

namespace skybake {

class InterruptScope {
 public:
  InterruptScope();
  ~InterruptScope();
  InterruptScope(const InterruptScope&) = delete;
  InterruptScope& operator=(const InterruptScope&) = delete;
};

// The signal recorded and not yet thrown or taken (SIGINT, SIGTERM), or 0.
int PendingInterrupt();

// Throws InterruptedError "interrupted by SIGINT: WHAT" if a signal is pending
// (and clears it).
void ThrowIfInterrupted(const std::string& what);

// Clears and returns the pending signal (0 if none).
int TakeInterrupt();

}  // namespace skybake
