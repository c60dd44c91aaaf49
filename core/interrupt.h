// One interrupt rule for every command (SIGINT and SIGTERM): an interrupt
// either leaves the command's outputs as they were before it ran, or lets
// them complete, and the exit code and message say which.
//
// Every output file is written under a temporary name beside its final one
// (core/file_io.h: WriteFileAtomically, StagedFiles), which is registered
// here while it exists, and renamed into place in a CommitSection. With the
// handler that main() installs (HandleInterrupts):
//  - a signal outside a commit removes every registered temporary file,
//    every directory the command created that is then empty and its scratch
//    directories, prints
//    "skybake: interrupted by SIGINT: NOTE" (the note of SetInterruptNote:
//    what was left as it was), and exits 130 at once, whatever the command's
//    threads are doing;
//  - a signal during a commit is recorded and the commit completes. From the
//    end of a commit on, signals are only recorded: the outputs are
//    complete, and main() says so and exits 0. Work that goes on after a
//    commit (the next atmosphere of a batch, the next run of a benchmark)
//    calls SetInterruptNote again, which throws InterruptedError (exit 130)
//    if a signal was recorded meanwhile and makes signals act at once again.
// Without HandleInterrupts (a test binary) the signals keep their default
// action and the registry only serves the handler that is not there.
#pragma once

#include <filesystem>
#include <functional>
#include <string>

namespace skybake {

// Installs the handler for the rest of the process. `json_document`, if
// given, makes the document an interrupted command prints on stdout from an
// error message ("interrupted by SIGINT: NOTE").
void HandleInterrupts(std::function<std::string(const std::string& message)> json_document = nullptr);

// Makes signals act at once again, with `note` (e.g. "nothing was written
// to DIR") completing the message; `json_document` replaces the one on
// stdout (a batch's report of what it finished) where --json asked for one.
// Throws InterruptedError with `note` if a signal was recorded since the
// last commit.
void SetInterruptNote(const std::string& note,
                      std::function<std::string(const std::string& message)> json_document = nullptr);

// While one lives, signals are recorded, not acted on; the command's
// outputs are complete from its end on (see above). A commit of `file` into
// a scratch directory (RegisterScratchDirectory) commits no output: after
// it, signals act at once again, and one recorded during it acts then.
class CommitSection {
 public:
  explicit CommitSection(const std::filesystem::path& file);
  ~CommitSection();
  CommitSection(const CommitSection&) = delete;
  CommitSection& operator=(const CommitSection&) = delete;

 private:
  bool scratch_;
};

// Where a signal was recorded during or after a commit, the line main()
// prints ("interrupted by SIGINT after the outputs were complete; nothing
// was lost"), the signal cleared; empty where none was.
std::string TakeInterruptAfterCommit();

// A temporary file the handler removes: registered before it is created,
// unregistered once renamed into place or removed.
class RegisteredTemporary {
 public:
  explicit RegisteredTemporary(const std::filesystem::path& path);
  ~RegisteredTemporary();
  RegisteredTemporary(RegisteredTemporary&& other) noexcept;
  RegisteredTemporary& operator=(RegisteredTemporary&&) = delete;
  RegisteredTemporary(const RegisteredTemporary&) = delete;
  RegisteredTemporary& operator=(const RegisteredTemporary&) = delete;

 private:
  std::filesystem::path path_;  // empty once moved from
};

// A directory this process created: the handler removes it if it is empty
// by then (after the temporary files), deepest first.
void RegisterCreatedDirectory(const std::filesystem::path& dir);

// A scratch directory (core/file_io.h ScratchDirectory), nothing in it an
// output: the handler removes it with everything in it.
void RegisterScratchDirectory(const std::filesystem::path& dir);

}  // namespace skybake
