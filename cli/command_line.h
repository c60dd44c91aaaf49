// The command line that started the program, recorded in every output file.
#pragma once

#include <string>

#include <CLI/CLI.hpp>

namespace skybake::cli {

void SetCommandLine(int argc, char** argv);
const std::string& CommandLine();

// The value of --ktx2-supercompression: "none" (0), "zstd" (the default
// level) or "zstd:LEVEL" (1-22), as WriteOptions::ktx2_zstd_level.
// UsageError for anything else.
int ParseKtx2Supercompression(const std::string& value);

// The check of every option that names an output file or folder: an empty
// path names neither, a usage error before any work (`-o ''`).
const CLI::Validator& OutputPath();
inline constexpr const char kKtx2SupercompressionHelp[] =
    "KTX2 supercompression: none, zstd or zstd:LEVEL (1 fastest ... 22 smallest; zstd alone: level 3), "
    "lossless, read by libktx and three.js's KTX2Loader";

}  // namespace skybake::cli
