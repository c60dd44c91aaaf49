// The manifest `skybake.json`: the versioned description of a baked set that
// engines and the loader read first (schema documented in docs/manifest.md).
// It lists every file with its format, pixel type, size, channel meanings,
// encoding, units, parameterization and SHA-256, plus the runtime constants,
// the bake settings, the resolved atmosphere, the command that wrote it and
// the hash of the bake's inputs (pipeline/bake_inputs.h).
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "bake/bake.h"
#include "formats/lut_tables.h"
#include "formats/table_file.h"

namespace skybake {

inline constexpr const char kManifestFileName[] = "skybake.json";
inline constexpr const char kManifestSchema[] = "skybake.manifest";
inline constexpr int kManifestSchemaVersion = 8;

class ManifestWriter {
 public:
  // `inputs_sha256`: the hash of what determined the set (recorded as
  // "inputs_sha256"); empty: none, null in the manifest.
  ManifestWriter(const LutSet& luts, std::string command_line, std::string inputs_sha256);

  // A table file as written: its size in bytes and their SHA-256 (hex).
  void AddTableFile(const TableDescription& table, const std::string& file, const TableImage& image,
                    std::size_t bytes, const std::string& sha256);
  // Any other file shipped beside the tables, such as the generated GLSL
  // runtime: one call lists it under "shaders" with its size and SHA-256.
  void AddShaderFile(const std::string& file, std::string_view bytes, const std::string& description);

  // The manifest as JSON text (two-space indent, final newline).
  std::string Text() const;

 private:
  const LutSet& luts_;
  std::string command_line_;
  std::string inputs_sha256_;
  nlohmann::ordered_json tables_ = nlohmann::ordered_json::array();
  nlohmann::ordered_json shaders_ = nlohmann::ordered_json::array();
};

// One file listed in a manifest.
struct ManifestFile {
  std::string table;  // empty for shader files
  std::string file;   // a plain name in the manifest's directory
  FileFormat format = FileFormat::kExr;  // table files only
  PixelType pixel_type = PixelType::kFloat;
  std::uint64_t bytes = 0;
  std::string sha256;
};

// A manifest read back: the set without texels, and its files.
struct Manifest {
  std::filesystem::path path;  // .../skybake.json
  LutSet luts;                 // atmosphere, settings and parameters; textures empty
  std::vector<ManifestFile> table_files;
  std::vector<ManifestFile> shader_files;
  // The hash of the bake's inputs; empty where the manifest records none
  // (written before it was recorded, or not by `skybake bake`).
  std::string inputs_sha256;
  nlohmann::json document;

  std::filesystem::path Directory() const { return path.parent_path(); }
  // The listed files of `table` in `format`; nullptr if there is none.
  const ManifestFile* Find(const std::string& table, FileFormat format) const;
};

// Reads and validates DIR/skybake.json (schema, version, settings, that file
// names are plain names). IoError naming the manifest for anything wrong.
Manifest ReadManifest(const std::filesystem::path& dir);

// The plain file names DIR/skybake.json lists (tables and shaders) and the
// manifest itself, read from any schema version; empty where there is no
// manifest or it is not a skybake manifest. What `bake --clean` may remove,
// and what `info` does not warn about.
std::vector<std::string> ListedFileNames(const std::filesystem::path& dir);

// The entry for `file` when the directory holding it has a manifest that
// lists it (as a table or shader file); nullopt when there is no manifest or
// it does not list the file. A manifest that cannot be read is an IoError.
std::optional<ManifestFile> FindListing(const std::filesystem::path& file);

// Reads a file the manifest lists and verifies it: IoError "<path>: missing
// (listed in skybake.json)", "...: truncated", "...: checksum mismatch".
std::vector<std::uint8_t> ReadListedFile(const Manifest& manifest, const ManifestFile& entry);

// IoError "<source>: ..." unless `bytes` has the listed size and SHA-256.
void VerifyListedFile(const ManifestFile& entry, const std::vector<std::uint8_t>& bytes, const std::string& source);

}  // namespace skybake
