#include "cli/progress.h"

#include <unistd.h>

#include <algorithm>

namespace skybake::cli {

namespace {
constexpr int kBarWidth = 30;
}

bool ProgressBar::ShouldShow(bool quiet, std::FILE* stream) {
  return !quiet && stream && ::isatty(::fileno(stream));
}

ProgressBar::ProgressBar(std::string label, std::size_t total, bool quiet, std::FILE* stream)
    : label_(std::move(label)),
      total_(std::max<std::size_t>(total, 1)),
      stream_(stream),
      enabled_(ShouldShow(quiet, stream)),
      start_(std::chrono::steady_clock::now()) {
  if (enabled_) {
    std::lock_guard<std::mutex> lock(mutex_);
    Draw(0);
  }
}

ProgressBar::~ProgressBar() { Finish(); }

void ProgressBar::Advance(std::size_t units) {
  if (!enabled_) return;
  std::lock_guard<std::mutex> lock(mutex_);
  if (finished_) return;
  done_ = std::min(total_, done_ + units);
  Draw(done_);
}

void ProgressBar::Draw(std::size_t done) {
  int permille = static_cast<int>(1000 * done / total_);
  if (permille == drawn_permille_) return;  // redraw only when the figure changes
  const auto now = std::chrono::steady_clock::now();
  const auto interval = std::chrono::milliseconds(1000 / kMaxRedrawsPerSecond);
  if (drawn_permille_ >= 0 && now - drawn_at_ < interval) return;  // the first draw is immediate
  drawn_permille_ = permille;
  drawn_at_ = now;
  int filled = permille * kBarWidth / 1000;
  double seconds = std::chrono::duration<double>(now - start_).count();
  std::fprintf(stream_, "\r%s [%s%s] %5.1f%% %6.1f s", label_.c_str(), std::string(filled, '#').c_str(),
               std::string(kBarWidth - filled, '.').c_str(), permille / 10.0, seconds);
  std::fflush(stream_);
}

void ProgressBar::Finish() {
  if (!enabled_) return;
  std::lock_guard<std::mutex> lock(mutex_);
  if (finished_) return;
  finished_ = true;
  // Blank the line so the next message starts clean.
  std::fprintf(stream_, "\r%*s\r", static_cast<int>(label_.size()) + kBarWidth + 20, "");
  std::fflush(stream_);
}

}  // namespace skybake::cli
