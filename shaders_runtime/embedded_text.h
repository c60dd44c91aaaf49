// Text files compiled into the program from the source tree (see
// cmake/EmbedText.cmake): the atmosphere presets, the GLSL runtime and the
// published spectral data.
#pragma once

#include <string_view>
#include <vector>

namespace skybake {

struct EmbeddedText {
  std::string_view name;  // file name, e.g. "earth.toml"
  std::string_view text;
};

// examples/atmospheres/*.toml
extern const std::vector<EmbeddedText> kPresetFiles;
// shaders_runtime/*.glsl and shaders_runtime/generated/*
extern const std::vector<EmbeddedText> kRuntimeShaderFiles;
// data/*.csv (data/README.md)
extern const std::vector<EmbeddedText> kSpectralDataFiles;

}  // namespace skybake
