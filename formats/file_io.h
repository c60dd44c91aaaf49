// File primitives every writer uses: outputs appear complete or not at all.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

namespace skybake {

// Calls `write` with a temporary path in the same directory as `path`, then
// renames the temporary file over `path`. If `write` throws (or the rename
// fails) the temporary file is removed and any earlier `path` is left intact.
// Errors from the filesystem are thrown as IoError naming `path`.
void WriteFileAtomically(const std::filesystem::path& path,
                         const std::function<void(const std::filesystem::path& temp_path)>& write);
void WriteFileAtomically(const std::filesystem::path& path, std::string_view bytes);

// Whole-file read; IoError if the file is missing or unreadable.
std::vector<std::uint8_t> ReadFileBytes(const std::filesystem::path& path);
std::string ReadFileText(const std::filesystem::path& path);

// Creates `dir` (and parents) if needed; IoError if it cannot be created or is
// not a writable directory.
void EnsureWritableDirectory(const std::filesystem::path& dir);

}  // namespace skybake
