#include "core/file_io.h"

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <random>

#include "core/errors.h"

namespace fs = std::filesystem;

namespace skybake {

namespace {

constexpr char kTemporaryMarker[] = ".tmp-";

fs::path TemporarySibling(const fs::path& path) {
  std::random_device device;
  char suffix[32];
  std::snprintf(suffix, sizeof(suffix), "%s%d-%08x", kTemporaryMarker, static_cast<int>(::getpid()),
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

}  // namespace

void WriteFileAtomically(const fs::path& path,
                         const std::function<void(const fs::path& temp_path)>& write) {
  const fs::path temp = TemporarySibling(path);
  const RegisteredTemporary registration(temp);
  try {
    write(temp);
    std::error_code ec;
    const CommitSection commit(path);
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
  Write(path, [&](const fs::path& temp) { WriteWholeFile(temp, path, bytes); });
}

void StagedFiles::Write(const fs::path& path, const std::function<void(const fs::path& temp_path)>& write) {
  fs::path temp = TemporarySibling(path);
  {
    // Listed before it exists, so that the destructor (or an interrupt)
    // removes a partial file.
    std::lock_guard<std::mutex> lock(mutex_);
    staged_.push_back({temp, path, RegisteredTemporary(temp)});
  }
  write(temp);
}

void StagedFiles::Commit() {
  if (staged_.empty()) return;
  const CommitSection commit(staged_.front().path);
  for (const Staged& file : staged_) {
    if (fs::is_directory(file.path)) throw IoError(file.path.string() + ": cannot write: is a directory");
  }
  // Renamed directly over an earlier file, ext4 starts writing the new one
  // to disk within the rename (its auto_da_alloc), which for a table of
  // megabytes costs more than the rest of the file's writing; so every file
  // but the last (the header says why) moves its predecessor aside instead.
  std::vector<fs::path> replaced;
  auto remove_replaced = [&replaced] {
    for (const fs::path& old : replaced) {
      std::error_code ignored;
      fs::remove(old, ignored);
    }
  };
  for (std::size_t i = 0; i < staged_.size(); ++i) {
    const Staged& file = staged_[i];
    std::error_code ec;
    fs::path aside;
    if (i + 1 < staged_.size() && fs::is_regular_file(file.path, ec)) {
      aside = TemporarySibling(file.path);
      fs::rename(file.path, aside, ec);
      if (ec) aside.clear();  // replaced directly below
    }
    fs::rename(file.temp, file.path, ec);
    if (ec) {
      std::error_code ignored;
      if (!aside.empty()) fs::rename(aside, file.path, ignored);
      remove_replaced();
      throw IoError(file.path.string() + ": cannot write: " + ec.message());
    }
    if (!aside.empty()) replaced.push_back(aside);
  }
  staged_.clear();
  remove_replaced();
}

namespace {

// The rest of `in` appended to `out` (a std::string or a byte vector).
template <class Buffer>
void AppendStream(std::istream& in, Buffer& out) {
  char chunk[1 << 16];
  while (in.read(chunk, sizeof chunk) || in.gcount() > 0) out.insert(out.end(), chunk, chunk + in.gcount());
}

// The whole file at `path` (or standard input for kStandardStream) as a
// Buffer; `kind` names what was expected in the error for a folder.
template <class Buffer>
Buffer ReadWhole(const fs::path& path, const std::string& kind) {
  Buffer contents;
  if (path == kStandardStream) {
    AppendStream(std::cin, contents);
    if (std::cin.bad()) throw IoError("standard input: read failed (" + std::string(std::strerror(errno)) + ")");
    return contents;
  }
  const ErrorLocation location{path.string()};
  std::error_code error;
  if (fs::is_directory(path, error)) throw IoError(path.string() + ": is a directory, not " + kind, location);
  if (!fs::exists(path, error)) throw IoError(path.string() + ": no such file", location);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(path.string() + ": cannot open (" + std::strerror(errno) + ")", location);
  const std::uintmax_t size = fs::file_size(path, error);
  if (!error) contents.reserve(size);
  AppendStream(in, contents);
  if (in.bad()) throw IoError(path.string() + ": read failed (" + std::strerror(errno) + ")", location);
  return contents;
}

}  // namespace

std::vector<std::uint8_t> ReadFileBytes(const fs::path& path, const std::string& kind) {
  return ReadWhole<std::vector<std::uint8_t>>(path, kind);
}

std::string ReadFileText(const fs::path& path, const std::string& kind) { return ReadWhole<std::string>(path, kind); }

std::vector<std::string> EntriesNotIn(const fs::path& dir, const std::vector<std::string>& names) {
  std::vector<std::string> entries;
  std::error_code ec;
  for (const fs::directory_entry& entry : fs::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    if (std::find(names.begin(), names.end(), name) != names.end()) continue;
    std::error_code type_error;
    entries.push_back(entry.is_directory(type_error) ? name + "/" : name);
  }
  if (ec) throw IoError(dir.string() + ": cannot list: " + ec.message());
  std::sort(entries.begin(), entries.end());
  return entries;
}

bool IsTemporaryFileName(const std::string& file_name) {
  // NAME.tmp-PID-XXXXXXXX
  const std::size_t marker = file_name.rfind(kTemporaryMarker);
  if (marker == std::string::npos || marker == 0) return false;
  const std::string tail = file_name.substr(marker + sizeof(kTemporaryMarker) - 1);
  const std::size_t dash = tail.find('-');
  if (dash == std::string::npos || dash == 0 || tail.size() - dash - 1 != 8) return false;
  auto digit = [](unsigned char c) { return std::isdigit(c) != 0; };
  auto hex_digit = [](unsigned char c) { return std::isxdigit(c) != 0; };
  return std::all_of(tail.begin(), tail.begin() + dash, digit) &&
         std::all_of(tail.begin() + dash + 1, tail.end(), hex_digit);
}

void CheckOutputDirectory(const fs::path& dir) {
  std::error_code ec;
  fs::path existing = dir.empty() ? fs::path(".") : dir;
  while (!fs::exists(existing, ec)) {
    if (!existing.has_relative_path() || existing.parent_path() == existing) break;
    existing = existing.parent_path().empty() ? fs::path(".") : existing.parent_path();
  }
  if (!fs::is_directory(existing, ec)) {
    throw IoError(dir.string() + ": cannot create output directory: " + existing.string() + " is not a directory");
  }
  if (::access(existing.c_str(), W_OK) != 0) {
    throw IoError(dir.string() + (existing == dir ? ": output directory is not writable"
                                                  : ": cannot create output directory: " + existing.string() +
                                                        " is not writable"));
  }
}

void EnsureWritableDirectory(const fs::path& dir) {
  std::error_code ec;
  // The folders this creates, outermost first, for the interrupt rule.
  std::vector<fs::path> created;
  for (fs::path missing = dir; !missing.empty() && !fs::exists(missing, ec); missing = missing.parent_path()) {
    created.insert(created.begin(), missing);
    if (missing.parent_path() == missing) break;
  }
  for (const fs::path& folder : created) RegisterCreatedDirectory(folder);
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir)) {
    throw IoError(dir.string() + ": cannot create output directory" + (ec ? ": " + ec.message() : ""));
  }
  if (::access(dir.c_str(), W_OK) != 0) {
    throw IoError(dir.string() + ": output directory is not writable");
  }
}

ScratchDirectory::ScratchDirectory(const std::string& prefix)
    : path_(fs::temp_directory_path() / (prefix + std::to_string(::getpid()))) {
  RegisterScratchDirectory(path_);
  EnsureWritableDirectory(path_);
}

ScratchDirectory::~ScratchDirectory() {
  std::error_code ignored;
  fs::remove_all(path_, ignored);
}

}  // namespace skybake
