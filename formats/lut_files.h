// A baked table set on disk: one OpenEXR file per table plus the manifest
// `skybake.json` that lists them with the runtime constants. This is the one
// interface between the bake and the files; readers rebuild a LutSet from it.
//
// EXR conventions: channels R, G, B (and A where used) hold the three
// wavelengths in the order of `wavelengths_nm`; ZIP compression (lossless);
// float32 or half. 3D tables are stored as a 2D atlas of depth slices
// stacked vertically: atlas row = z * height + y, so the 4D scattering table
// (x = nu * mu_s_size + mu_s, y = mu, z = r) is (nu_size * mu_s_size) wide and
// (r_size * mu_size) tall. Attributes under "skybake." record the table kind,
// channel encoding, units, wavelengths, the runtime parameters (JSON), the
// resolved atmosphere (TOML), and the tool version. The command line is
// recorded in the manifest only, so table files depend on nothing but the
// atmosphere and the settings (byte-identical across runs and thread counts).
#pragma once

#include <filesystem>
#include <string>

#include "bake/bake.h"

namespace skybake {

struct WriteOptions {
  bool half = false;         // store half floats instead of float32
  std::string command_line;  // recorded in the manifest
};

// Writes every table and then the manifest, each atomically. IoError on failure.
void WriteLutSet(const LutSet& luts, const std::filesystem::path& dir, const WriteOptions& options);

// Reads a set written by WriteLutSet. IoError for missing, truncated or
// foreign files and for tables that disagree with the manifest.
LutSet LoadLutSet(const std::filesystem::path& dir);

}  // namespace skybake
