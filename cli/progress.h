// A progress bar on stderr for work that takes more than a second.
//
// Shown only when the stream is a terminal (isatty) and the command was not
// given --quiet; otherwise every call is a no-op, so logs and pipes keep only
// the command's own final summary line. It never writes to stdout, which
// carries reports and --json. Advance() may be called from worker threads.
// The bar is redrawn only when its figure (0.1%) changes and at most
// kMaxRedrawsPerSecond times a second, so fast work does not flood the
// terminal.
//
//   ProgressBar bar("bake: scattering", total_units, quiet);
//   ... bar.Advance(n) from any thread ...
//   bar.Finish();  // or let the destructor clear the line
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdio>
#include <mutex>
#include <string>

namespace skybake::cli {

class ProgressBar {
 public:
  static constexpr int kMaxRedrawsPerSecond = 10;

  ProgressBar(std::string label, std::size_t total, bool quiet, std::FILE* stream = stderr);
  ~ProgressBar();
  ProgressBar(const ProgressBar&) = delete;
  ProgressBar& operator=(const ProgressBar&) = delete;

  void Advance(std::size_t units = 1);
  // Clears the bar's line (idempotent).
  void Finish();
  bool enabled() const { return enabled_; }

  // Whether a bar would be shown on `stream`: not quiet and a terminal.
  static bool ShouldShow(bool quiet, std::FILE* stream = stderr);

 private:
  void Draw(std::size_t done);  // with mutex_ held

  std::string label_;
  std::size_t total_;
  std::FILE* stream_;
  bool enabled_;
  std::mutex mutex_;
  std::size_t done_ = 0;
  int drawn_permille_ = -1;
  bool finished_ = false;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point drawn_at_;  // the last redraw
};

}  // namespace skybake::cli
