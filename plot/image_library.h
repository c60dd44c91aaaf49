// Access to the image module (plot/image_module.h), loaded on first use:
// installed, from PREFIX/lib/skybake beside the executable's PREFIX/bin; in
// the build tree, from build/lib (SKYBAKE_IMAGE_MODULE_DIR, set by
// plot/CMakeLists.txt).
#pragma once

#include <filesystem>
#include <string>

#include "plot/image_module.h"

namespace skybake {

// The module's functions. IoError naming the file if it cannot be loaded or
// was built from another version of the interface.
const image_module::Functions& ImageModule();

// The error a module function returned, as an IoError naming `path`; nothing
// if it returned "".
void ThrowIfImageError(const std::filesystem::path& path, const std::string& error);

}  // namespace skybake
