// A baked table set on disk: one file per table and format (OpenEXR and/or
// KTX2, formats/table_file.h) plus the manifest `skybake.json`
// (formats/manifest.h, docs/manifest.md) that lists them with checksums and
// the runtime constants. This is the one interface between the bake and the
// files: WriteLutSet writes a set, LoadLutSet rebuilds a LutSet from one.
//
// Table files carry only what the atmosphere and the settings determine (no
// command line, paths or dates), so a re-bake is byte-identical whatever the
// thread count; the command line is recorded in the manifest only.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "bake/bake.h"
#include "formats/lut_tables.h"
#include "formats/table_file.h"
#include "formats/table_stats.h"

namespace skybake {

// A text file shipped beside the tables (the generated GLSL runtime).
struct ShaderFile {
  std::string file;  // plain file name inside the output directory
  std::string text;
  std::string description;
};

struct WriteOptions {
  std::vector<FileFormat> formats = {FileFormat::kExr, FileFormat::kKtx2};
  bool half = false;          // store half floats instead of float32
  std::vector<std::string> half_tables;  // tables stored as half even without `half` (a scene's precision)
  // KTX2 files Zstandard-supercompressed at this level (1-22), 0: stored as is.
  int ktx2_zstd_level = 0;
  std::string command_line;   // recorded in the manifest
  std::string inputs_sha256;  // recorded in the manifest (pipeline/bake_inputs.h); empty: none
  std::vector<ShaderFile> shaders;  // written and listed under "shaders"
  // Remove the files of an earlier set in the directory that the new set does
  // not list (StaleSetFiles); without it such files make WriteLutSet refuse.
  bool clean = false;
};

struct WrittenFile {
  std::string table;  // empty for shader files
  std::string file;
  std::uint64_t bytes = 0;
};

struct WriteReport {
  std::vector<WrittenFile> files;  // in writing order, the manifest last
  // With `half`: the error rounding each table to half introduced.
  std::vector<std::pair<std::string, HalfError>> half_errors;
};

// Writes every table in every requested format, the shader files, and then
// the manifest, as one staged set: it appears complete or not at all, and an
// interrupt (core/interrupt.h) before the commit leaves the directory as it
// was. A directory it creates is removed again on failure. IoError on
// failure, and, before anything is written, when the directory holds files
// of an earlier set that the new set does not list (StaleSetFiles; removed
// after the commit with WriteOptions::clean).
WriteReport WriteLutSet(const LutSet& luts, const std::filesystem::path& dir, const WriteOptions& options);

// The plain names of the files WriteLutSet writes for `luts` with `options`:
// each table in each format, the shader files, the manifest. A LutSet
// without texels (atmosphere, settings, parameters, scene, colour) names the
// same files, so that a pipeline knows them before it bakes.
std::vector<std::string> SetFileNames(const LutSet& luts, const WriteOptions& options);

// The rule for what else an output folder holds. The files in `dir` that a
// set of `new_files` written there would leave behind from an earlier set:
// those the manifest in `dir` lists and `new_files` do not, and temporary
// files of a killed write. Without `clean` they are an IoError naming them
// (a set never mixes files of two bakes); with it they are returned, for
// WriteLutSet to remove once the new set is committed. Everything else is
// foreign (no skybake manifest there listed it: an engine's .meta files, a
// README, folders): left alone, and never in the way. A foreign file with
// the name of one of `new_files` is replaced. WriteLutSet checks this before
// it writes, the bake pipeline before it bakes.
std::vector<std::string> StaleSetFiles(const std::filesystem::path& dir, const std::vector<std::string>& new_files,
                                       bool clean);

// The image of `table` that WriteLutSet encodes into its `format` file: the
// pixel type `options` asks for, the storage ChooseFileStorage picks.
TableImage MakeTableFileImage(const LutSet& luts, const TableDescription& table, FileFormat format,
                              const WriteOptions& options);

struct LoadOptions {
  // The format to read. Unset: KTX2 if the manifest lists it for every table
  // and the files exist, else OpenEXR.
  std::optional<FileFormat> format;
};

// Reads a set written by WriteLutSet, checking every file against the
// manifest (size, SHA-256, format, table, dimensions, channels). One-line
// IoError naming the file for a missing, truncated, altered or foreign file.
LutSet LoadLutSet(const std::filesystem::path& dir, const LoadOptions& options = {});

}  // namespace skybake
