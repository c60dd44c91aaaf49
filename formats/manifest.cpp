#include "formats/manifest.h"

#include <algorithm>

#include "bake/colour.h"
#include "bake/config.h"
#include "bake/spectral.h"
#include "core/errors.h"
#include "core/file_io.h"
#include "core/version.h"
#include "formats/settings_record.h"
#include "formats/sha256.h"
#include "shaders_runtime/runtime.h"

namespace fs = std::filesystem;
using nlohmann::json;
using nlohmann::ordered_json;

namespace skybake {

namespace {

ordered_json SizeToJson(int width, int height, int depth, bool is_3d) {
  return is_3d ? ordered_json::array({width, height, depth}) : ordered_json::array({width, height});
}

// The constants the texture-coordinate mappings use, named as in the runtime's GLSL.
ordered_json ParameterizationToJson(const glsl::AtmosphereParameters& p) {
  return ordered_json{
      {"functions", "shaders_runtime/: GetTransmittanceTextureUvFromRMu (geometry.glsl), "
                    "GetIrradianceTextureUvFromRMuS (table_mappings.glsl), "
                    "GetScatteringTextureUvwzFromRMuMuSNu (lookups.glsl)"},
      {"bottom_radius", p.bottom_radius},
      {"top_radius", p.top_radius},
      {"H", glsl::HorizonDistanceAtTop(p)},
      {"mu_s_min", p.mu_s_min},
      {"texel_centres", "u = 0.5 / n + x * (1 - 1 / n) for x in [0, 1] on an axis of n texels"},
  };
}

bool IsPlainFileName(const std::string& name) {
  return !name.empty() && name != "." && name != ".." && name.find('/') == std::string::npos &&
         name.find('\\') == std::string::npos && name.find('\0') == std::string::npos;
}

bool IsHexDigest(const std::string& s) {
  return s.size() == 64 && std::all_of(s.begin(), s.end(), [](char c) {
           return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f');
         });
}

}  // namespace

ManifestWriter::ManifestWriter(const LutSet& luts, std::string command_line, std::string inputs_sha256)
    : luts_(luts), command_line_(std::move(command_line)), inputs_sha256_(std::move(inputs_sha256)) {
  for (const TableDescription& t : DescribeTables(luts)) {
    ordered_json channels = ordered_json::array();
    for (const TableChannel& c : t.channels) {
      channels.push_back({{"name", c.name}, {"wavelength_nm", c.wavelength_nm}, {"meaning", c.meaning}});
    }
    ordered_json axes = ordered_json::array();
    for (const TableAxis& a : t.axes) {
      axes.push_back({{"axis", a.axis},
                      {"coordinate", a.coordinate},
                      {"size", a.size},
                      {"range", {a.range_min, a.range_max}},
                      {"units", a.units},
                      {"mapping", a.mapping}});
    }
    tables_.push_back({{"name", t.name},
                       {"encoding", t.encoding},
                       {"units", t.units},
                       {"size", SizeToJson(t.width, t.height, t.depth, t.is_3d)},
                       {"layout", t.layout},
                       {"channels", channels},
                       {"axes", axes},
                       {"files", ordered_json::array()}});
  }
}

void ManifestWriter::AddTableFile(const TableDescription& table, const std::string& file, const TableImage& image,
                                  std::size_t bytes, const std::string& sha256) {
  auto entry = std::find_if(tables_.begin(), tables_.end(), [&](const ordered_json& t) { return t["name"] == table.name; });
  if (entry == tables_.end()) throw InternalError("manifest: no table " + table.name);
  ordered_json f = {{"file", file},
                    {"format", ToString(image.format)},
                    {"pixel_type", ToString(image.pixel_type)},
                    {"storage", image.StorageName()},
                    {"size", SizeToJson(image.width, image.height, image.depth, image.is_3d)},
                    {"stored_channels", StoredChannels(image)}};
  if (image.format == FileFormat::kExr && image.is_3d) {
    f["atlas"] = ordered_json::array({image.width, image.height * image.depth});
  }
  f["bytes"] = bytes;
  f["sha256"] = sha256;
  (*entry)["files"].push_back(f);
}

void ManifestWriter::AddShaderFile(const std::string& file, std::string_view bytes, const std::string& description) {
  if (!IsPlainFileName(file)) throw InternalError("manifest: shader file '" + file + "' is not a plain file name");
  shaders_.push_back(
      {{"file", file}, {"description", description}, {"bytes", bytes.size()}, {"sha256", Sha256Hex(bytes)}});
}

namespace {

// A spectral set's "colour": what its channels are, and the altitude
// profiles of its parameters, which are not those of the atmosphere at any
// three wavelengths (bake/spectral.h) and so are stored, not recomputed.
ordered_json ColourToJson(const LutSet& luts) {
  const glsl::AtmosphereParameters& p = luts.parameters;
  auto profile = [](const glsl::vec3* values) {
    ordered_json list = ordered_json::array();
    for (int i = 0; i < glsl::ALTITUDE_PROFILE_SIZE; ++i) list.push_back({values[i].x, values[i].y, values[i].z});
    return list;
  };
  const glm::dmat3& m = XyzToLinearSrgbMatrix();
  ordered_json to_srgb = ordered_json::array();
  for (int row = 0; row < 3; ++row) to_srgb.push_back({m[0][row], m[1][row], m[2][row]});
  return {{"space", "CIE 1931 XYZ"},
          {"observer", "CIE 1931 2 degree"},
          {"units", "photometric: Y is luminance in cd m^-2 (illuminance in lx for irradiance), X and Z alike"},
          {"luminous_efficacy_lm_per_w", kLuminousEfficacyLmPerW},
          {"wavelengths_nm", luts.colour->wavelengths_nm},
          {"higher_order_wavelengths_nm", luts.colour->higher_order_wavelengths_nm},
          {"xyz_to_linear_srgb", to_srgb},
          {"transmittance", "of sunlight's colour: exp(-depth) is the sun's XYZ through the ray over its XYZ"},
          {"extinction_profile", profile(p.extinction_profile)},
          {"mie_scattering_profile", profile(p.mie_scattering_profile)},
          {"rayleigh_scattering_profile", profile(p.rayleigh_scattering_profile)}};
}

void ColourProfilesFromJson(const json& colour, const std::string& where, glsl::AtmosphereParameters* p) {
  auto read = [&](const char* key, glsl::vec3* values) {
    const json& list = colour.at(key);
    if (list.size() != glsl::ALTITUDE_PROFILE_SIZE) {
      throw IoError(where + ": colour." + key + " holds " + std::to_string(list.size()) + " values, not " +
                    std::to_string(glsl::ALTITUDE_PROFILE_SIZE));
    }
    for (int i = 0; i < glsl::ALTITUDE_PROFILE_SIZE; ++i) {
      values[i] = glsl::vec3(list.at(i).at(0).get<double>(), list.at(i).at(1).get<double>(),
                             list.at(i).at(2).get<double>());
    }
  };
  read("extinction_profile", p->extinction_profile);
  read("mie_scattering_profile", p->mie_scattering_profile);
  read("rayleigh_scattering_profile", p->rayleigh_scattering_profile);
}

}  // namespace

std::string ManifestWriter::Text() const {
  const Spectrum& w = luts_.atmosphere.wavelengths_nm;
  ordered_json manifest = {
      {"schema", kManifestSchema},
      {"schema_version", kManifestSchemaVersion},
      {"generator", "skybake " SKYBAKE_VERSION},
      {"command", command_line_},
      {"inputs_sha256", inputs_sha256_.empty() ? ordered_json(nullptr) : ordered_json(inputs_sha256_)},
      {"wavelengths_nm", luts_.colour ? ordered_json(luts_.colour->wavelengths_nm) : ordered_json({w.x, w.y, w.z})},
      {"colour", luts_.colour ? ColourToJson(luts_) : ordered_json(nullptr)},
      {"parameters", ParametersToJson(luts_.parameters)},
      {"parameterization", ParameterizationToJson(luts_.parameters)},
      {"bake", SettingsJson(luts_.settings, SettingsFields::kManifest, luts_.orders_used)},
      {"tables", tables_},
      {"shaders", shaders_},
      {"atmosphere", ordered_json::parse(ToJson(luts_.atmosphere))},
      {"atmosphere_toml", ToToml(luts_.atmosphere)},
  };
  if (luts_.scene) {
    // After the tables, so that sets baked without a scene stay byte-identical.
    ordered_json scene = ordered_json::parse(SceneToJson(*luts_.scene));
    ordered_json omitted = ordered_json::array();
    for (const OmittedTable& t : PlanScene(*luts_.scene, luts_.atmosphere).omitted) {
      omitted.push_back({{"table", t.table}, {"reason", t.reason}});
    }
    scene["omitted_tables"] = omitted;
    manifest["scene"] = scene;
  }
  return manifest.dump(2) + "\n";
}

const ManifestFile* Manifest::Find(const std::string& table, FileFormat format) const {
  for (const ManifestFile& f : table_files) {
    if (f.table == table && f.format == format) return &f;
  }
  return nullptr;
}

std::vector<std::string> ListedFileNames(const fs::path& dir) {
  const fs::path path = dir / kManifestFileName;
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) return {};
  const json document = json::parse(ReadFileText(path), nullptr, /*allow_exceptions=*/false);
  if (!document.is_object() || document.value("schema", "") != kManifestSchema) return {};
  std::vector<std::string> names = {kManifestFileName};
  auto add = [&](const json& entry) {
    if (!entry.is_object() || !entry.contains("file") || !entry["file"].is_string()) return;
    const std::string file = entry["file"].get<std::string>();
    if (IsPlainFileName(file)) names.push_back(file);
  };
  for (const json& table : document.value("tables", json::array())) {
    if (table.is_object()) {
      for (const json& file : table.value("files", json::array())) add(file);
    }
  }
  for (const json& shader : document.value("shaders", json::array())) add(shader);
  return names;
}

Manifest ReadManifest(const fs::path& dir) {
  Manifest m;
  m.path = dir / kManifestFileName;
  const std::string where = m.path.string();
  if (!fs::exists(m.path)) {
    throw IoError(where + ": no manifest (is " + dir.string() + " a directory written by skybake bake?)");
  }
  const std::string text = ReadFileText(m.path);
  try {
    m.document = json::parse(text);
    if (!m.document.is_object() || m.document.value("schema", "") != kManifestSchema) {
      throw IoError(where + ": not a skybake manifest");
    }
    const int version = m.document.at("schema_version").get<int>();
    if (version != kManifestSchemaVersion) {
      throw IoError(where + ": schema version " + std::to_string(version) + ", this skybake reads version " +
                    std::to_string(kManifestSchemaVersion) + " (re-bake, or use a matching skybake)");
    }
    LutSet& luts = m.luts;
    luts.parameters = ParametersFromJson(m.document.at("parameters"));
    luts.atmosphere = ParseAtmosphere(m.document.at("atmosphere_toml").get<std::string>(), where);
    const json& colour = m.document.at("colour");
    if (colour.is_null()) {
      // The coefficient profiles are a function of the atmosphere, not stored twice.
      SetAltitudeProfiles(luts.atmosphere, &luts.parameters);
    } else {
      const std::vector<double> wavelengths = colour.at("wavelengths_nm").get<std::vector<double>>();
      // Sets written before the higher orders could be interpolated computed them everywhere.
      luts.colour =
          SpectralColour{wavelengths, colour.contains("higher_order_wavelengths_nm")
                                          ? colour.at("higher_order_wavelengths_nm").get<std::vector<double>>()
                                          : wavelengths};
      ColourProfilesFromJson(colour, where, &luts.parameters);
    }
    const json& bake = m.document.at("bake");
    BakeSettings& s = luts.settings;
    const json& orders = bake.at("orders");
    s.orders = orders.is_string() && orders.get<std::string>() == "auto" ? 0 : orders.get<int>();
    luts.orders_used = bake.at("orders_used").get<int>();
    s.extrapolate_tail = bake.at("extrapolate_tail").get<bool>();
    s.transmittance_samples = bake.at("transmittance_samples").get<int>();
    s.ray_samples = bake.at("ray_samples").get<int>();
    s.sphere_samples = bake.at("sphere_samples").get<int>();
    s.higher_order_divisor = bake.at("higher_order_divisor").get<int>();
    s.pack_single_mie_in_alpha = bake.at("pack_single_mie_in_alpha").get<bool>();
    const glsl::AtmosphereParameters& p = luts.parameters;
    s.transmittance_width = p.transmittance_width;
    s.transmittance_height = p.transmittance_height;
    s.irradiance_width = p.irradiance_width;
    s.irradiance_height = p.irradiance_height;
    s.scattering_r_size = p.scattering_r_size;
    s.scattering_mu_size = p.scattering_mu_size;
    s.scattering_mu_s_size = p.scattering_mu_s_size;
    s.scattering_nu_size = p.scattering_nu_size;
    s.Validate();
    if (m.document.contains("scene")) luts.scene = SceneFromJson(m.document.at("scene").dump());
    if (p.single_mie_in_scattering_alpha != (s.pack_single_mie_in_alpha ? 1 : 0)) {
      throw IoError(where + ": parameters and bake settings disagree on packing single Mie");
    }

    auto read_file = [&](const json& f, const std::string& table) {
      ManifestFile entry;
      entry.table = table;
      entry.file = f.at("file").get<std::string>();
      if (!IsPlainFileName(entry.file)) {
        throw IoError(where + ": file '" + entry.file + "' must be a plain name in the manifest's directory");
      }
      entry.bytes = f.at("bytes").get<std::uint64_t>();
      entry.sha256 = f.at("sha256").get<std::string>();
      if (!IsHexDigest(entry.sha256)) throw IoError(where + ": file '" + entry.file + "': malformed sha256");
      return entry;
    };
    for (const json& t : m.document.at("tables")) {
      const std::string name = t.at("name").get<std::string>();
      for (const json& f : t.at("files")) {
        ManifestFile entry = read_file(f, name);
        auto format = ParseFileFormat(f.at("format").get<std::string>());
        if (!format) throw IoError(where + ": file '" + entry.file + "': unknown format " + f.at("format").dump());
        entry.format = *format;
        const std::string type = f.at("pixel_type").get<std::string>();
        if (type != "float" && type != "half") throw IoError(where + ": file '" + entry.file + "': unknown pixel_type");
        entry.pixel_type = type == "half" ? PixelType::kHalf : PixelType::kFloat;
        m.table_files.push_back(entry);
      }
    }
    for (const json& f : m.document.at("shaders")) m.shader_files.push_back(read_file(f, ""));
    // Added within schema version 8: absent in sets written before it, null
    // in sets not written by a bake.
    const json inputs = m.document.value("inputs_sha256", json(nullptr));
    if (!inputs.is_null()) {
      m.inputs_sha256 = inputs.get<std::string>();
      if (!IsHexDigest(m.inputs_sha256)) throw IoError(where + ": malformed inputs_sha256");
    }
  } catch (const json::exception& e) {
    throw IoError(where + ": malformed manifest: " + e.what());
  } catch (const InputError& e) {
    // Atmosphere errors already name the manifest; settings errors do not.
    const std::string message = e.what();
    throw IoError(message.rfind(where, 0) == 0 ? message : where + ": " + message);
  }
  return m;
}

std::optional<ManifestFile> FindListing(const fs::path& file) {
  const fs::path dir = file.has_parent_path() ? file.parent_path() : fs::path(".");
  if (!fs::exists(dir / kManifestFileName)) return std::nullopt;
  const Manifest manifest = ReadManifest(dir);
  const std::string name = file.filename().string();
  for (const auto* list : {&manifest.table_files, &manifest.shader_files}) {
    for (const ManifestFile& f : *list) {
      if (f.file == name) return f;
    }
  }
  return std::nullopt;
}

std::vector<std::uint8_t> ReadListedFile(const Manifest& manifest, const ManifestFile& entry) {
  const fs::path path = manifest.Directory() / entry.file;
  std::error_code ec;
  if (!fs::exists(path, ec)) throw IoError(path.string() + ": missing (listed in " + kManifestFileName + ")");
  std::vector<std::uint8_t> bytes = ReadFileBytes(path);
  VerifyListedFile(entry, bytes, path.string());
  return bytes;
}

void VerifyListedFile(const ManifestFile& entry, const std::vector<std::uint8_t>& bytes, const std::string& source) {
  if (bytes.size() != entry.bytes) {
    throw IoError(source + ": " + (bytes.size() < entry.bytes ? "truncated" : "wrong size") + ": " +
                  std::to_string(bytes.size()) + " bytes, the manifest says " + std::to_string(entry.bytes));
  }
  const std::string digest = Sha256Hex(bytes.data(), bytes.size());
  if (digest != entry.sha256) {
    throw IoError(source + ": checksum mismatch: sha256 " + digest.substr(0, 16) + "..., the manifest says " +
                  entry.sha256.substr(0, 16) + "... (the file changed after the bake)");
  }
}

}  // namespace skybake
