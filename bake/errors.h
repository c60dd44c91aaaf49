// Error categories shared by every skybake command. Each maps to one
// documented exit code so build scripts can tell bad input from a full disk.
#pragma once

#include <stdexcept>
#include <string>

namespace skybake {

enum class ExitCode : int {
  kOk = 0,
  kUsage = 1,         // bad command-line arguments
  kInvalidInput = 2,  // malformed or physically impossible configuration / query
  kIoError = 3,       // unreadable, unwritable, truncated or foreign file
  kInternal = 4,      // a bug: an invariant of skybake itself failed
};

// Base of all skybake errors: a one-line message plus the exit code it maps to.
class Error : public std::runtime_error {
 public:
  Error(ExitCode code, const std::string& message)
      : std::runtime_error(message), code_(code) {}
  ExitCode code() const { return code_; }

 private:
  ExitCode code_;
};

struct UsageError : Error {
  explicit UsageError(const std::string& m) : Error(ExitCode::kUsage, m) {}
};
struct InputError : Error {
  explicit InputError(const std::string& m) : Error(ExitCode::kInvalidInput, m) {}
};
struct IoError : Error {
  explicit IoError(const std::string& m) : Error(ExitCode::kIoError, m) {}
};
struct InternalError : Error {
  explicit InternalError(const std::string& m) : Error(ExitCode::kInternal, m) {}
};

}  // namespace skybake
