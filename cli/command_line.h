// The command line that started the program, recorded in every output file.
#pragma once

#include <string>

namespace skybake::cli {

void SetCommandLine(int argc, char** argv);
const std::string& CommandLine();

}  // namespace skybake::cli
