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

}  // namespace skybake::cli
