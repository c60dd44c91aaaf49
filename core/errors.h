// Error categories shared by every skybake command. Each maps to one
// documented exit code so build scripts can tell bad input from a full disk.
#pragma once

#include <stdexcept>
#include <string>
#include <utility>

namespace skybake {

enum class ExitCode : int {
  kOk = 0,
  kUsage = 1,          // bad command-line arguments or option values
  kInvalidInput = 2,   // malformed or physically impossible configuration / query
  kIoError = 3,        // missing, unreadable, unwritable, truncated or foreign file; output folder not clean
  kInternal = 4,       // a bug: an invariant of skybake itself failed
  kInterrupted = 130,  // SIGINT or SIGTERM before the outputs were complete (128 + SIGINT, as shells report it)
};

// Where in an input a problem lies, as far as it is known; machine-readable
// errors (`--json`) report it field by field.
struct ErrorLocation {
  ErrorLocation() = default;
  ErrorLocation(std::string file_name, int line_number = 0, std::string key_path = {})
      : file(std::move(file_name)), line(line_number), key(std::move(key_path)) {}
  std::string file;  // as the message names it; empty if unknown
  int line = 0;      // 1-based; 0 if unknown
  std::string key;   // key path in a TOML document, column of a CSV file; empty if unknown
};

// "FILE:LINE: " (or "FILE: " without a line): the one way a message locates a
// problem in a file.
inline std::string LocationPrefix(const std::string& file, int line = 0) {
  return file + (line > 0 ? ":" + std::to_string(line) : std::string()) + ": ";
}

// Base of all skybake errors: a one-line message plus the exit code it maps to.
class Error : public std::runtime_error {
 public:
  Error(ExitCode code, const std::string& message, ErrorLocation location = {})
      : std::runtime_error(message), code_(code), location_(std::move(location)) {}
  ExitCode code() const { return code_; }
  const ErrorLocation& location() const { return location_; }

 private:
  ExitCode code_;
  ErrorLocation location_;
};

struct UsageError : Error {
  explicit UsageError(const std::string& m) : Error(ExitCode::kUsage, m) {}
};
struct InputError : Error {
  explicit InputError(const std::string& m, ErrorLocation where = {})
      : Error(ExitCode::kInvalidInput, m, std::move(where)) {}
};
struct IoError : Error {
  explicit IoError(const std::string& m, ErrorLocation where = {}) : Error(ExitCode::kIoError, m, std::move(where)) {}
};
struct InternalError : Error {
  explicit InternalError(const std::string& m) : Error(ExitCode::kInternal, m) {}
};
// An error the command has already reported on stdout as part of its --json
// output (a batch's report): main() only prints the line on stderr.
struct ReportedError : Error {
  explicit ReportedError(const Error& e) : Error(e) {}
};
struct InterruptedError : Error {
  explicit InterruptedError(const std::string& m) : Error(ExitCode::kInterrupted, m) {}
};

}  // namespace skybake
