// Small helpers shared by tests that run the skybake executable or other
// programs and work with temporary files.
#pragma once

#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace skybake::testing {

// A fresh directory under the system temporary directory, removed on destruction.
class TempDir {
 public:
  TempDir() {
    static std::atomic<int> counter{0};
    path_ = std::filesystem::temp_directory_path() /
            ("skybake_test_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

inline void WriteText(const std::filesystem::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

inline std::string ReadText(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

inline std::string ShellQuote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

// Runs a shell command in `dir`'s context, capturing stdout and stderr into
// files there; returns the exit code (-1 if killed by a signal).
inline int RunCommand(const std::string& command, const TempDir& dir, std::string* out = nullptr,
                      std::string* err = nullptr) {
  std::filesystem::path out_file = dir.path() / "run.stdout", err_file = dir.path() / "run.stderr";
  int status = std::system((command + " >" + ShellQuote(out_file) + " 2>" + ShellQuote(err_file)).c_str());
  if (out) *out = ReadText(out_file);
  if (err) *err = ReadText(err_file);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// The skybake executable under test, quoted for a shell. SKYBAKE_TEST_EXE
// points the command-line tests at another build (for example an older one,
// to see a regression test fail there).
inline std::string Skybake() {
  const char* other = std::getenv("SKYBAKE_TEST_EXE");
  return ShellQuote(other != nullptr && *other != '\0' ? other : SKYBAKE_EXE);
}

// Table sizes and samples of a bake that takes well under a second, and
// the same with two orders: the command-line tests' small bake.
inline const std::string kSmallTableOptions =
    " --transmittance-size 64 16 --irradiance-size 16 4 --scattering-size 8 32 8 4 --ray-samples 32"
    " --sphere-samples 8";
inline const std::string kSmallBakeOptions = kSmallTableOptions + " --orders 2";

inline std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

}  // namespace skybake::testing
