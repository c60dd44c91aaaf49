#include "cli/command_line.h"

#include "core/errors.h"
#include "formats/ktx2.h"

namespace skybake::cli {

namespace {
std::string& Storage() {
  static std::string command_line;
  return command_line;
}
}  // namespace

void SetCommandLine(int argc, char** argv) {
  std::string& s = Storage();
  s.clear();
  for (int i = 0; i < argc; ++i) {
    if (i) s += ' ';
    std::string arg = i == 0 ? std::string("skybake") : std::string(argv[i]);
    // Shell-quote anything a shell would split or expand, so the recorded
    // line can be pasted back.
    bool plain = !arg.empty() && arg.find_first_of(" \t\n'\"\\$`") == std::string::npos;
    if (!plain) {
      std::string quoted = "'";
      for (char c : arg) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
      arg = quoted + "'";
    }
    s += arg;
  }
}

const std::string& CommandLine() { return Storage(); }

const CLI::Validator& OutputPath() {
  static const CLI::Validator check(
      [](const std::string& path) { return path.empty() ? std::string("an empty path names no file or folder") : ""; },
      "PATH");
  return check;
}

int ParseKtx2Supercompression(const std::string& value) {
  if (value == "none") return 0;
  if (value == "zstd") return ktx2::kZstdDefaultLevel;
  const std::string prefix = "zstd:";
  if (value.compare(0, prefix.size(), prefix) == 0) {
    const std::string digits = value.substr(prefix.size());
    if (!digits.empty() && digits.size() <= 2 && digits.find_first_not_of("0123456789") == std::string::npos) {
      const int level = std::stoi(digits);
      if (level >= ktx2::kZstdMinLevel && level <= ktx2::kZstdMaxLevel) return level;
    }
  }
  throw UsageError("--ktx2-supercompression: '" + value + "' is not none, zstd or zstd:LEVEL with LEVEL " +
                   std::to_string(ktx2::kZstdMinLevel) + " to " + std::to_string(ktx2::kZstdMaxLevel));
}

}  // namespace skybake::cli
