#include "formats/lut_files.h"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfStringAttribute.h>

#include <nlohmann/json.hpp>

#include "bake/config.h"
#include "bake/errors.h"
#include "bake/version.h"
#include "formats/file_io.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace skybake {

namespace {

constexpr const char* kManifestName = "skybake.json";
constexpr const char* kSchema = "skybake.manifest";
constexpr int kSchemaVersion = 1;

struct TableSpec {
  const char* name;
  const char* encoding;  // what the channels hold
  const char* units;
  int channels;  // 3 = RGB, 4 = RGBA
};

json Vec3ToJson(const glsl::vec3& v) { return json::array({v.x, v.y, v.z}); }
glsl::vec3 Vec3FromJson(const json& j) { return glsl::vec3(j.at(0).get<double>(), j.at(1).get<double>(), j.at(2).get<double>()); }

json ParametersToJson(const glsl::AtmosphereParameters& p) {
  return json{
      {"solar_irradiance", Vec3ToJson(p.solar_irradiance)},
      {"sun_angular_radius", p.sun_angular_radius},
      {"bottom_radius", p.bottom_radius},
      {"top_radius", p.top_radius},
      {"mu_s_min", p.mu_s_min},
      {"mie_phase", p.mie_phase},
      {"mie_g", p.mie_g},
      {"mie_to_rayleigh_scattering_ratio", Vec3ToJson(p.mie_to_rayleigh_scattering_ratio)},
      {"single_mie_in_scattering_alpha", p.single_mie_in_scattering_alpha},
      {"transmittance_width", p.transmittance_width},
      {"transmittance_height", p.transmittance_height},
      {"scattering_r_size", p.scattering_r_size},
      {"scattering_mu_size", p.scattering_mu_size},
      {"scattering_mu_s_size", p.scattering_mu_s_size},
      {"scattering_nu_size", p.scattering_nu_size},
      {"irradiance_width", p.irradiance_width},
      {"irradiance_height", p.irradiance_height},
  };
}

glsl::AtmosphereParameters ParametersFromJson(const json& j) {
  glsl::AtmosphereParameters p;
  p.solar_irradiance = Vec3FromJson(j.at("solar_irradiance"));
  p.sun_angular_radius = j.at("sun_angular_radius").get<double>();
  p.bottom_radius = j.at("bottom_radius").get<double>();
  p.top_radius = j.at("top_radius").get<double>();
  p.mu_s_min = j.at("mu_s_min").get<double>();
  p.mie_phase = j.at("mie_phase").get<int>();
  p.mie_g = j.at("mie_g").get<double>();
  p.mie_to_rayleigh_scattering_ratio = Vec3FromJson(j.at("mie_to_rayleigh_scattering_ratio"));
  p.single_mie_in_scattering_alpha = j.at("single_mie_in_scattering_alpha").get<int>();
  p.transmittance_width = j.at("transmittance_width").get<int>();
  p.transmittance_height = j.at("transmittance_height").get<int>();
  p.scattering_r_size = j.at("scattering_r_size").get<int>();
  p.scattering_mu_size = j.at("scattering_mu_size").get<int>();
  p.scattering_mu_s_size = j.at("scattering_mu_s_size").get<int>();
  p.scattering_nu_size = j.at("scattering_nu_size").get<int>();
  p.irradiance_width = j.at("irradiance_width").get<int>();
  p.irradiance_height = j.at("irradiance_height").get<int>();
  return p;
}

json SettingsToJson(const BakeSettings& s) {
  return json{{"orders", s.orders},
              {"transmittance_samples", s.transmittance_samples},
              {"ray_samples", s.ray_samples},
              {"sphere_samples", s.sphere_samples},
              {"pack_single_mie_in_alpha", s.pack_single_mie_in_alpha}};
}

const char* kChannelNames[4] = {"R", "G", "B", "A"};

void WriteExr(const fs::path& path, const glsl::Texture& texture, const TableSpec& spec, const LutSet& luts,
              const WriteOptions& options) {
  const int width = texture.width, height = texture.height * texture.depth;
  Imf::Header header(width, height);
  header.compression() = Imf::ZIP_COMPRESSION;
  Imf::PixelType type = options.half ? Imf::HALF : Imf::FLOAT;
  for (int c = 0; c < spec.channels; ++c) header.channels().insert(kChannelNames[c], Imf::Channel(type));
  const Spectrum& w = luts.atmosphere.wavelengths_nm;
  char wavelengths[96];
  std::snprintf(wavelengths, sizeof(wavelengths), "%.17g,%.17g,%.17g", w.x, w.y, w.z);
  header.insert("skybake.generator", Imf::StringAttribute("skybake " SKYBAKE_VERSION));
  header.insert("skybake.table", Imf::StringAttribute(spec.name));
  header.insert("skybake.encoding", Imf::StringAttribute(spec.encoding));
  header.insert("skybake.units", Imf::StringAttribute(spec.units));
  header.insert("skybake.wavelengths_nm", Imf::StringAttribute(wavelengths));
  header.insert("skybake.size", Imf::StringAttribute(std::to_string(texture.width) + "x" +
                                                     std::to_string(texture.height) + "x" +
                                                     std::to_string(texture.depth)));
  header.insert("skybake.parameters", Imf::StringAttribute(ParametersToJson(luts.parameters).dump()));
  header.insert("skybake.atmosphere", Imf::StringAttribute(ToToml(luts.atmosphere)));

  WriteFileAtomically(path, [&](const fs::path& temp) {
    try {
      Imf::OutputFile file(temp.c_str(), header);
      Imf::FrameBuffer frame;
      const size_t x_stride = 4 * sizeof(float), y_stride = x_stride * width;
      for (int c = 0; c < spec.channels; ++c) {
        char* base = reinterpret_cast<char*>(const_cast<float*>(texture.texels.data() + c));
        frame.insert(kChannelNames[c], Imf::Slice(Imf::FLOAT, base, x_stride, y_stride));
      }
      file.setFrameBuffer(frame);
      file.writePixels(height);
    } catch (const std::exception& e) {
      throw IoError(path.string() + ": cannot write: " + e.what());
    }
  });
}

glsl::Texture ReadExr(const fs::path& path, int width, int height, int depth, int channels) {
  glsl::Texture texture(width, height, depth);
  try {
    Imf::InputFile file(path.c_str());
    const Imath::Box2i window = file.header().dataWindow();
    int file_width = window.max.x - window.min.x + 1, file_height = window.max.y - window.min.y + 1;
    if (file_width != width || file_height != height * depth) {
      throw IoError(path.string() + ": is " + std::to_string(file_width) + "x" + std::to_string(file_height) +
                    ", the manifest says " + std::to_string(width) + "x" + std::to_string(height * depth));
    }
    Imf::FrameBuffer frame;
    const size_t x_stride = 4 * sizeof(float), y_stride = x_stride * width;
    for (int c = 0; c < channels; ++c) {
      if (!file.header().channels().findChannel(kChannelNames[c])) {
        throw IoError(path.string() + ": missing channel " + kChannelNames[c]);
      }
      char* base = reinterpret_cast<char*>(texture.texels.data() + c) -
                   window.min.x * x_stride - window.min.y * y_stride;
      frame.insert(kChannelNames[c], Imf::Slice(Imf::FLOAT, base, x_stride, y_stride));
    }
    file.setFrameBuffer(frame);
    file.readPixels(window.min.y, window.max.y);
  } catch (const IoError&) {
    throw;
  } catch (const std::exception& e) {
    throw IoError(path.string() + ": cannot read EXR: " + e.what());
  }
  return texture;
}

struct TableEntry {
  TableSpec spec;
  glsl::Texture* texture;
};

std::vector<TableEntry> Tables(LutSet& luts) {
  bool packed = luts.parameters.single_mie_in_scattering_alpha == 1;
  std::vector<TableEntry> tables = {
      {{"transmittance", "optical depth to the top of the atmosphere (transmittance = exp(-value))", "1", 3},
       &luts.transmittance},
      {{"irradiance", "indirect irradiance on a horizontal surface", "W m^-2 nm^-1", 3}, &luts.irradiance},
      {{"scattering",
        packed ? "single Rayleigh + multiple scattering radiance / Rayleigh phase (RGB), single Mie red (A)"
               : "single Rayleigh + multiple scattering radiance / Rayleigh phase",
        "W m^-2 sr^-1 nm^-1", packed ? 4 : 3},
       &luts.scattering},
  };
  if (!packed) {
    tables.push_back({{"single_mie_scattering", "single Mie scattering radiance without phase function",
                       "W m^-2 sr^-1 nm^-1", 3},
                      &luts.single_mie_scattering});
  }
  return tables;
}

}  // namespace

void WriteLutSet(const LutSet& luts, const fs::path& dir, const WriteOptions& options) {
  EnsureWritableDirectory(dir);
  LutSet& mutable_luts = const_cast<LutSet&>(luts);  // Tables() only hands out pointers; nothing is modified
  json tables = json::array();
  for (const TableEntry& entry : Tables(mutable_luts)) {
    std::string file = std::string(entry.spec.name) + ".exr";
    WriteExr(dir / file, *entry.texture, entry.spec, luts, options);
    tables.push_back(json{{"name", entry.spec.name},
                          {"file", file},
                          {"format", "exr"},
                          {"pixel_type", options.half ? "half" : "float"},
                          {"width", entry.texture->width},
                          {"height", entry.texture->height},
                          {"depth", entry.texture->depth},
                          {"channels", entry.spec.channels},
                          {"encoding", entry.spec.encoding},
                          {"units", entry.spec.units}});
  }
  const Spectrum& w = luts.atmosphere.wavelengths_nm;
  json manifest = {{"schema", kSchema},
                   {"schema_version", kSchemaVersion},
                   {"generator", "skybake " SKYBAKE_VERSION},
                   {"command", options.command_line},
                   {"wavelengths_nm", json::array({w.x, w.y, w.z})},
                   {"parameters", ParametersToJson(luts.parameters)},
                   {"bake", SettingsToJson(luts.settings)},
                   {"tables", tables},
                   {"atmosphere_toml", ToToml(luts.atmosphere)}};
  WriteFileAtomically(dir / kManifestName, manifest.dump(2) + "\n");
}

LutSet LoadLutSet(const fs::path& dir) {
  fs::path manifest_path = dir / kManifestName;
  std::string text = ReadFileText(manifest_path);
  LutSet luts;
  try {
    json manifest = json::parse(text);
    if (manifest.value("schema", "") != kSchema) throw IoError(manifest_path.string() + ": not a skybake manifest");
    if (manifest.at("schema_version").get<int>() != kSchemaVersion) {
      throw IoError(manifest_path.string() + ": unsupported schema version " +
                    std::to_string(manifest.at("schema_version").get<int>()));
    }
    luts.parameters = ParametersFromJson(manifest.at("parameters"));
    luts.atmosphere = ParseAtmosphere(manifest.at("atmosphere_toml").get<std::string>(), manifest_path.string());
    const json& bake = manifest.at("bake");
    BakeSettings& s = luts.settings;
    s.orders = bake.at("orders").get<int>();
    s.transmittance_samples = bake.at("transmittance_samples").get<int>();
    s.ray_samples = bake.at("ray_samples").get<int>();
    s.sphere_samples = bake.at("sphere_samples").get<int>();
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
    try {
      s.Validate();
    } catch (const InputError& e) {
      throw IoError(manifest_path.string() + ": " + e.what());
    }
    for (TableEntry& entry : Tables(luts)) {
      auto found = std::find_if(manifest.at("tables").begin(), manifest.at("tables").end(),
                                [&](const json& t) { return t.at("name") == entry.spec.name; });
      if (found == manifest.at("tables").end()) {
        throw IoError(manifest_path.string() + ": no table " + entry.spec.name);
      }
      // Sizes come from the parameters, so a manifest cannot describe a table
      // the runtime would sample differently.
      int width = 0, height = 0, depth = 1;
      std::string name = entry.spec.name;
      if (name == "transmittance") width = p.transmittance_width, height = p.transmittance_height;
      else if (name == "irradiance") width = p.irradiance_width, height = p.irradiance_height;
      else width = p.scattering_nu_size * p.scattering_mu_s_size, height = p.scattering_mu_size, depth = p.scattering_r_size;
      if (found->at("width") != width || found->at("height") != height || found->at("depth") != depth) {
        throw IoError(manifest_path.string() + ": table " + name + " dimensions disagree with the parameters");
      }
      fs::path file = found->at("file").get<std::string>();
      if (file.has_parent_path()) throw IoError(manifest_path.string() + ": table file must be in the same directory");
      *entry.texture = ReadExr(dir / file, width, height, depth, entry.spec.channels);
    }
  } catch (const json::exception& e) {
    throw IoError(manifest_path.string() + ": malformed manifest: " + e.what());
  } catch (const InputError& e) {
    throw IoError(std::string(e.what()));
  }
  return luts;
}

}  // namespace skybake
