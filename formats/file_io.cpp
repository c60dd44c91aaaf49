#include "formats/file_io.h"

#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <random>
#include <sstream>

#include "bake/errors.h"

namespace fs = std::filesystem;

namespace skybake {

namespace {

fs::path TemporarySibling(const fs::path& path) {
  std::random_device device;
  char suffix[32];
  std::snprintf(suffix, sizeof(suffix), ".tmp-%d-%08x", static_cast<int>(::getpid()),
                static_cast<unsigned>(device()));
  fs::path temp = path;
  temp += suffix;
  return temp;
}

// Writes `bytes` to `temp`; errors name `path`, the file the user asked for.
void WriteWholeFile(const fs::path& temp, const fs::path& path, std::string_view bytes) {
  std::FILE* file = std::fopen(temp.c_str(), "wb");
  if (!file) throw IoError(path.string() + ": cannot write: " + std::strerror(errno));
  bool ok = std::fwrite(bytes.data(), 1, bytes.size(), file) == bytes.size();
  // fflush + fclose report a full disk that a buffered fwrite hid.
  ok = (std::fflush(file) == 0) && ok;
  int saved_errno = errno;
  ok = (std::fclose(file) == 0) && ok;
  if (!ok) throw IoError(path.string() + ": cannot write: " + std::strerror(saved_errno));
}

constexpr int kDeferredSignals[] = {SIGINT, SIGTERM};
volatile std::sig_atomic_t deferred_signal = 0;
struct sigaction previous_actions[2];

extern "C" void RememberSignal(int signal) { deferred_signal = signal; }

}  // namespace

DeferInterrupts::DeferInterrupts() {
  deferred_signal = 0;
  struct sigaction action {};
  action.sa_handler = RememberSignal;
  sigemptyset(&action.sa_mask);
  for (int i = 0; i < 2; ++i) sigaction(kDeferredSignals[i], &action, &previous_actions[i]);
}

DeferInterrupts::~DeferInterrupts() {
  for (int i = 0; i < 2; ++i) sigaction(kDeferredSignals[i], &previous_actions[i], nullptr);
  if (deferred_signal != 0) std::raise(deferred_signal);
}

void WriteFileAtomically(const fs::path& path,
                         const std::function<void(const fs::path& temp_path)>& write) {
  fs::path temp = TemporarySibling(path);
  try {
    write(temp);
    std::error_code ec;
    fs::rename(temp, path, ec);
    if (ec) throw IoError(path.string() + ": cannot write: " + ec.message());
  } catch (...) {
    std::error_code ignored;
    fs::remove(temp, ignored);
    throw;
  }
}

void WriteFileAtomically(const fs::path& path, std::string_view bytes) {
  WriteFileAtomically(path, [&](const fs::path& temp) { WriteWholeFile(temp, path, bytes); });
}

StagedFiles::~StagedFiles() {
  for (const Staged& file : staged_) {
    std::error_code ignored;
    fs::remove(file.temp, ignored);
  }
}

void StagedFiles::Write(const fs::path& path, std::string_view bytes) {
  staged_.push_back({TemporarySibling(path), path});
  WriteWholeFile(staged_.back().temp, path, bytes);
}

void StagedFiles::Commit() {
  for (const Staged& file : staged_) {
    if (fs::is_directory(file.path)) throw IoError(file.path.string() + ": cannot write: is a directory");
  }
  for (const Staged& file : staged_) {
    std::error_code ec;
    fs::rename(file.temp, file.path, ec);
    if (ec) throw IoError(file.path.string() + ": cannot write: " + ec.message());
  }
  staged_.clear();
}

std::vector<std::uint8_t> ReadFileBytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(path.string() + ": cannot read: " + std::strerror(errno));
  std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw IoError(path.string() + ": read error");
  return bytes;
}

std::string ReadFileText(const fs::path& path) {
  std::vector<std::uint8_t> bytes = ReadFileBytes(path);
  return std::string(bytes.begin(), bytes.end());
}

void EnsureWritableDirectory(const fs::path& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir)) {
    throw IoError(dir.string() + ": cannot create output directory" + (ec ? ": " + ec.message() : ""));
  }
  if (::access(dir.c_str(), W_OK) != 0) {
    throw IoError(dir.string() + ": output directory is not writable");
  }
}

}  // namespace skybake
