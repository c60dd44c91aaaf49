#include "core/interrupt.h"

#include <pthread.h>

#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <mutex>
#include <set>
#include <thread>
#include <utility>
#include <vector>

#include "core/errors.h"

namespace fs = std::filesystem;

namespace skybake {

namespace {

using JsonDocument = std::function<std::string(const std::string& message)>;

// The signals are blocked in every thread (threads inherit the mask of the
// thread that starts them, and HandleInterrupts runs before any other) and
// taken by one thread with sigwait(), so that acting on one is ordinary
// code: it can wait for a commit to end, remove files and print.
struct InterruptState {
  // Held for the whole of a commit; the signal thread takes it first, so a
  // signal waits for a commit in progress to end.
  std::recursive_mutex commit_mutex;
  // Guards everything below; never held while taking commit_mutex.
  std::mutex mutex;
  bool installed = false;
  bool act_at_once = true;  // false from the start of a commit until SetInterruptNote
  int pending_signal = 0;
  std::string note = "the outputs were left as they were";
  JsonDocument json_document;
  std::multiset<fs::path> temporaries;
  std::vector<fs::path> created_directories;
  std::vector<fs::path> scratch_directories;
};

InterruptState& State() {
  static InterruptState* state = new InterruptState;  // never destroyed: the signal thread outlives main()
  return *state;
}

const char* SignalName(int signal) { return signal == SIGTERM ? "SIGTERM" : "SIGINT"; }

std::string InterruptedMessage(int signal, const std::string& note) {
  return std::string("interrupted by ") + SignalName(signal) + ": " + note;
}

// What a signal does once no commit is in progress.
void ActOn(int signal) {
  InterruptState& s = State();
  std::lock_guard<std::recursive_mutex> commit(s.commit_mutex);
  std::lock_guard<std::mutex> lock(s.mutex);
  if (!s.act_at_once) {
    s.pending_signal = signal;
    return;
  }
  for (const fs::path& temporary : s.temporaries) {
    std::error_code ignored;
    fs::remove(temporary, ignored);
  }
  for (auto dir = s.created_directories.rbegin(); dir != s.created_directories.rend(); ++dir) {
    std::error_code ignored;
    if (fs::is_empty(*dir, ignored)) fs::remove(*dir, ignored);
  }
  for (const fs::path& dir : s.scratch_directories) {
    std::error_code ignored;
    fs::remove_all(dir, ignored);
  }
  const std::string message = InterruptedMessage(signal, s.note);
  std::fflush(stdout);
  if (s.json_document) std::printf("%s\n", s.json_document(message).c_str());
  std::fflush(stdout);
  std::fprintf(stderr, "skybake: %s\n", message.c_str());
  std::_Exit(static_cast<int>(ExitCode::kInterrupted));
}

sigset_t InterruptSignals() {
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  return signals;
}

}  // namespace

void HandleInterrupts(JsonDocument json_document) {
  InterruptState& s = State();
  {
    std::lock_guard<std::mutex> lock(s.mutex);
    if (s.installed) return;
    s.installed = true;
    s.json_document = std::move(json_document);
  }
  const sigset_t signals = InterruptSignals();
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  std::thread([signals] {
    for (;;) {
      int signal = 0;
      if (sigwait(&signals, &signal) == 0) ActOn(signal);
    }
  }).detach();
}

void SetInterruptNote(const std::string& note, JsonDocument json_document) {
  InterruptState& s = State();
  std::lock_guard<std::mutex> lock(s.mutex);
  if (s.pending_signal != 0) {
    const int signal = std::exchange(s.pending_signal, 0);
    throw InterruptedError(InterruptedMessage(signal, note));
  }
  s.note = note;
  if (json_document) s.json_document = std::move(json_document);
  s.act_at_once = true;
}

CommitSection::CommitSection(const fs::path& file) : scratch_(false) {
  InterruptState& s = State();
  s.commit_mutex.lock();
  std::lock_guard<std::mutex> lock(s.mutex);
  const std::string path = file.lexically_normal().string();
  for (const fs::path& dir : s.scratch_directories) {
    const std::string prefix = (dir.lexically_normal() / "").string();
    scratch_ = scratch_ || path.compare(0, prefix.size(), prefix) == 0;
  }
  s.act_at_once = false;
}

CommitSection::~CommitSection() {
  InterruptState& s = State();
  int pending = 0;
  if (scratch_) {
    std::lock_guard<std::mutex> lock(s.mutex);
    s.act_at_once = true;
    pending = std::exchange(s.pending_signal, 0);
  }
  s.commit_mutex.unlock();
  if (pending != 0) ActOn(pending);
}

std::string TakeInterruptAfterCommit() {
  InterruptState& s = State();
  std::lock_guard<std::mutex> lock(s.mutex);
  const int signal = std::exchange(s.pending_signal, 0);
  if (signal == 0) return {};
  return std::string("interrupted by ") + SignalName(signal) + " after the outputs were complete; nothing was lost";
}

RegisteredTemporary::RegisteredTemporary(const fs::path& path) : path_(path) {
  InterruptState& s = State();
  std::lock_guard<std::mutex> lock(s.mutex);
  s.temporaries.insert(path_);
}

RegisteredTemporary::RegisteredTemporary(RegisteredTemporary&& other) noexcept : path_(std::move(other.path_)) {
  other.path_.clear();
}

RegisteredTemporary::~RegisteredTemporary() {
  if (path_.empty()) return;
  InterruptState& s = State();
  std::lock_guard<std::mutex> lock(s.mutex);
  s.temporaries.erase(s.temporaries.find(path_));
}

void RegisterCreatedDirectory(const fs::path& dir) {
  InterruptState& s = State();
  std::lock_guard<std::mutex> lock(s.mutex);
  s.created_directories.push_back(dir);
}

void RegisterScratchDirectory(const fs::path& dir) {
  InterruptState& s = State();
  std::lock_guard<std::mutex> lock(s.mutex);
  s.scratch_directories.push_back(dir);
}

}  // namespace skybake
