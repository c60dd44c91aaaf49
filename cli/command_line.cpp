#include "cli/command_line.h"

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
    bool quote = arg.empty() || arg.find_first_of(" \t\"'\\$") != std::string::npos;
    s += quote ? "'" + arg + "'" : arg;
  }
}

const std::string& CommandLine() { return Storage(); }

}  // namespace skybake::cli
