// File primitives every writer uses: outputs appear complete or not at all.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

#include "core/interrupt.h"

namespace skybake {

// Every temporary file below is registered with the interrupt rule
// (core/interrupt.h) while it exists, and every rename into place happens
// in a CommitSection: an interrupt leaves the earlier files or the new ones.

// Calls `write` with a temporary path in the same directory as `path`, then
// renames the temporary file over `path`. If `write` throws (or the rename
// fails) the temporary file is removed and any earlier `path` is left intact.
// Errors from the filesystem are thrown as IoError naming `path`.
void WriteFileAtomically(const std::filesystem::path& path,
                         const std::function<void(const std::filesystem::path& temp_path)>& write);
void WriteFileAtomically(const std::filesystem::path& path, std::string_view bytes);

// A set of files that appears complete or not at all: Write() puts each under
// a temporary name beside its final one, Commit() renames them all in the
// order written, once every one is complete. Destroyed without Commit() (a
// write failed), it removes its temporary files and every earlier file of the
// same names is left intact. Commit() refuses up front a final name it could
// not replace (a directory), so that no rename of the set has happened yet.
// Each file but the last written moves the file it replaces aside and
// removes it once the set is in place; the last (a manifest, which readers
// open first) replaces its predecessor in one rename, so that a reader
// always finds one. A rename that fails part-way leaves the files renamed
// before it new and the rest as they were.
// Write() may run on several threads at once; the order written is then the
// order the writes began.
class StagedFiles {
 public:
  StagedFiles() = default;
  StagedFiles(const StagedFiles&) = delete;
  StagedFiles& operator=(const StagedFiles&) = delete;
  ~StagedFiles();
  void Write(const std::filesystem::path& path, std::string_view bytes);
  // `write` makes the file at the temporary path it is given (an image
  // library's writer, told the format: the temporary name ends in
  // ".tmp-PID-XXXXXXXX", not in `path`'s extension).
  void Write(const std::filesystem::path& path,
             const std::function<void(const std::filesystem::path& temp_path)>& write);
  void Commit();

 private:
  struct Staged {
    std::filesystem::path temp, path;
    RegisteredTemporary registration;
  };
  std::mutex mutex_;  // guards staged_
  std::vector<Staged> staged_;
};

// The path that names standard input for every file a command reads.
inline constexpr const char kStandardStream[] = "-";

// Whole-file read (standard input for kStandardStream). IoError naming the
// file (as an ErrorLocation) if it is missing, a directory (`kind` says what
// was expected there, e.g. "an atmosphere file") or unreadable.
std::vector<std::uint8_t> ReadFileBytes(const std::filesystem::path& path, const std::string& kind = "a file");
std::string ReadFileText(const std::filesystem::path& path, const std::string& kind = "a file");

// The entries of `dir` whose names are not in `names`, sorted; a folder's
// name ends in '/'. IoError if `dir` cannot be listed.
std::vector<std::string> EntriesNotIn(const std::filesystem::path& dir, const std::vector<std::string>& names);

// Whether `file_name` is one of the temporary names WriteFileAtomically and
// StagedFiles use (left behind only by a process that was killed).
bool IsTemporaryFileName(const std::string& file_name);

// IoError unless `dir` is a writable directory or could be created as one
// (its nearest existing ancestor is a writable directory); creates nothing.
void CheckOutputDirectory(const std::filesystem::path& dir);

// Creates `dir` (and parents) if needed; IoError if it cannot be created or is
// not a writable directory.
void EnsureWritableDirectory(const std::filesystem::path& dir);

// A scratch folder, PREFIX followed by this process's id under the system's
// temporary directory: created (EnsureWritableDirectory) on construction and
// removed with everything in it on destruction, on success and on error alike
// (a failure to remove it is ignored: nothing of it is an output).
class ScratchDirectory {
 public:
  explicit ScratchDirectory(const std::string& prefix);
  ~ScratchDirectory();
  ScratchDirectory(const ScratchDirectory&) = delete;
  ScratchDirectory& operator=(const ScratchDirectory&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

}  // namespace skybake
