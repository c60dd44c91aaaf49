// What each table of a LutSet means, in one place: the writer turns this into
// file metadata and manifest entries, the loader checks files against it, and
// docs/manifest.md documents the same words.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "bake/bake.h"
#include "formats/table_file.h"

namespace skybake {

// One texture axis and the physical coordinate it samples.
struct TableAxis {
  std::string axis;        // "x", "y", "z"
  std::string coordinate;  // "mu", "r", "mu_s", "nu" (names as in the runtime's GLSL)
  int size = 0;            // texels (for the packed scattering x axis: the size of this coordinate)
  double range_min = 0.0, range_max = 0.0;
  std::string units;    // "m" for r, "1" for cosines
  std::string mapping;  // how a value becomes a texture coordinate
};

struct TableChannel {
  std::string name;  // "R", "G", "B", "A"
  double wavelength_nm = 0.0;
  std::string meaning;
};

struct TableDescription {
  std::string name;      // "transmittance", "irradiance", "scattering", "single_mie_scattering"
  std::string encoding;  // what the channels hold
  std::string units;
  std::vector<TableChannel> channels;  // the meaningful channels, R, G, B[, A]
  std::vector<TableAxis> axes;
  std::string layout;  // one line: which texture axis holds what
  bool is_3d = false;
  int width = 0, height = 0, depth = 1;  // texture size
};

// The tables a LutSet holds, in writing order (single_mie_scattering only when
// single Mie is not packed into the scattering table's alpha).
std::vector<TableDescription> DescribeTables(const LutSet& luts);

// The LutSet member that holds a table; InternalError for an unknown name.
glsl::Texture& TableTexture(LutSet& luts, const std::string& name);
const glsl::Texture& TableTexture(const LutSet& luts, const std::string& name);

// The runtime constants as JSON (manifest "parameters", metadata
// "skybake.parameters") and back; the reader throws json exceptions.
nlohmann::ordered_json ParametersToJson(const glsl::AtmosphereParameters& parameters);
glsl::AtmosphereParameters ParametersFromJson(const nlohmann::json& json);

// The metadata every file of `table` carries, identical for EXR and KTX2 and
// free of paths and command lines, so re-bakes are byte-identical.
Metadata TableMetadata(const LutSet& luts, const TableDescription& table);

// A table's texels as a TableImage of its meaningful channels, and back (the
// image's channels must include the table's; a KTX2 alpha that pads an RGB
// table is dropped).
TableImage MakeTableImage(const LutSet& luts, const TableDescription& table, FileFormat format, PixelType type);
void CopyTableImage(const TableImage& image, const TableDescription& table, glsl::Texture* texture,
                    const std::string& source);

}  // namespace skybake
