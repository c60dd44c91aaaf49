#include "formats/lut_tables.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "bake/config.h"
#include "core/errors.h"

namespace skybake {

namespace {

using nlohmann::json;
using nlohmann::ordered_json;

ordered_json Vec3ToJson(const glsl::vec3& v) { return ordered_json::array({v.x, v.y, v.z}); }
glsl::vec3 Vec3FromJson(const json& j) {
  return glsl::vec3(j.at(0).get<double>(), j.at(1).get<double>(), j.at(2).get<double>());
}

std::string Nm(double nm) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%g nm", nm);
  return buffer;
}

// Shared wording of the texture-coordinate mappings (the runtime's GLSL, shaders_runtime/, has the code).
constexpr const char* kTexelCentres = "; u = 0.5 / n + x * (1 - 1 / n) puts x = 0 and 1 on the first and last texel centres";
constexpr const char* kRhoOverH =
    "x = rho / H, rho = sqrt(r^2 - bottom_radius^2), H = sqrt(top_radius^2 - bottom_radius^2)";

TableAxis RAxis(const std::string& axis, int size, const glsl::AtmosphereParameters& p, const std::string& mapping) {
  return TableAxis{axis, "r", size, p.bottom_radius, p.top_radius, "m", mapping};
}

}  // namespace

ordered_json ParametersToJson(const glsl::AtmosphereParameters& p) {
  return ordered_json{
      {"solar_irradiance", Vec3ToJson(p.solar_irradiance)},
      {"sun_angular_radius", p.sun_angular_radius},
      {"bottom_radius", p.bottom_radius},
      {"top_radius", p.top_radius},
      {"mu_s_min", p.mu_s_min},
      {"mie_phase", p.mie_phase},
      {"mie_g", p.mie_g},
      {"mie_to_rayleigh_scattering_ratio", Vec3ToJson(p.mie_to_rayleigh_scattering_ratio)},
      {"single_mie_in_scattering_alpha", p.single_mie_in_scattering_alpha},
      {"transmittance_is_colour", p.transmittance_is_colour},
      {"transmittance_width", p.transmittance_width},
      {"transmittance_height", p.transmittance_height},
      {"scattering_r_size", p.scattering_r_size},
      {"scattering_mu_size", p.scattering_mu_size},
      {"scattering_mu_s_size", p.scattering_mu_s_size},
      {"scattering_nu_size", p.scattering_nu_size},
      {"scattering_r_min", p.scattering_r_min},
      {"scattering_r_max", p.scattering_r_max},
      {"scattering_mu_s_min", p.scattering_mu_s_min},
      {"scattering_mu_s_max", p.scattering_mu_s_max},
      {"scattering_mu_s_split", p.scattering_mu_s_split},
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
  // (Absent from the manifests of earlier versions, whose runtime subtracted
  // table values for colour tables too.)
  p.transmittance_is_colour = j.value("transmittance_is_colour", 0);
  p.transmittance_width = j.at("transmittance_width").get<int>();
  p.transmittance_height = j.at("transmittance_height").get<int>();
  p.scattering_r_size = j.at("scattering_r_size").get<int>();
  p.scattering_mu_size = j.at("scattering_mu_size").get<int>();
  p.scattering_mu_s_size = j.at("scattering_mu_s_size").get<int>();
  p.scattering_nu_size = j.at("scattering_nu_size").get<int>();
  p.scattering_r_min = j.at("scattering_r_min").get<double>();
  p.scattering_r_max = j.at("scattering_r_max").get<double>();
  p.scattering_mu_s_min = j.at("scattering_mu_s_min").get<double>();
  p.scattering_mu_s_max = j.at("scattering_mu_s_max").get<double>();
  p.scattering_mu_s_split = j.at("scattering_mu_s_split").get<int>();
  p.irradiance_width = j.at("irradiance_width").get<int>();
  p.irradiance_height = j.at("irradiance_height").get<int>();
  return p;
}

std::vector<TableDescription> DescribeTables(const LutSet& luts) {
  const glsl::AtmosphereParameters& p = luts.parameters;
  const Spectrum& w = luts.atmosphere.wavelengths_nm;
  const bool packed = p.single_mie_in_scattering_alpha == 1;
  // A spectral set's channels are CIE XYZ (wavelength 0: no one wavelength).
  const bool colour = luts.colour.has_value();
  auto rgb = [&](const std::string& what) {
    std::vector<TableChannel> channels;
    const char* names[3] = {"R", "G", "B"};
    const char* xyz[3] = {"X", "Y", "Z"};
    for (int c = 0; c < 3; ++c) {
      channels.push_back(colour ? TableChannel{names[c], 0.0, "CIE " + std::string(xyz[c]) + " of " + what}
                                : TableChannel{names[c], w[c], what + " at " + Nm(w[c])});
    }
    return channels;
  };
  std::vector<TableDescription> tables;

  TableDescription transmittance;
  transmittance.name = "transmittance";
  transmittance.encoding = colour ? "optical depth of sunlight's colour to the top of the atmosphere (the sun's "
                                    "XYZ through the ray = exp(-value) times its XYZ)"
                                  : "optical depth to the top of the atmosphere (transmittance = exp(-value))";
  transmittance.units = "1";
  transmittance.channels = rgb("optical depth");
  transmittance.width = p.transmittance_width;
  transmittance.height = p.transmittance_height;
  transmittance.axes = {
      {"x", "mu", p.transmittance_width, -1.0, 1.0, "1",
       "rays above the horizon only (mu from -sqrt(1 - (bottom_radius / r)^2) to 1): x = (d - d_min) / (d_max - "
       "d_min), d = distance to the top boundary along (r, mu), d_min = top_radius - r, d_max = rho + H" +
           std::string(kTexelCentres)},
      RAxis("y", p.transmittance_height, p, kRhoOverH + std::string(kTexelCentres))};
  transmittance.layout = "x = mu (" + std::to_string(p.transmittance_width) + "), y = r (" +
                         std::to_string(p.transmittance_height) + ")";
  tables.push_back(transmittance);

  TableDescription irradiance;
  irradiance.name = "irradiance";
  irradiance.encoding = "indirect irradiance on a horizontal surface (the direct sun is computed at run time)";
  irradiance.units = colour ? "lx (Y; X and Z alike)" : "W m^-2 nm^-1";
  irradiance.channels = rgb("indirect irradiance");
  irradiance.width = p.irradiance_width;
  irradiance.height = p.irradiance_height;
  irradiance.axes = {{"x", "mu_s", p.irradiance_width, p.mu_s_min, 1.0, "1",
                      "x = (mu_s - mu_s_min) / (knee - mu_s_min) / 2 below knee, 1/2 + (mu_s - knee) / (1 - knee) / 2 "
                      "above; knee = 0.1 where mu_s_min < 0.1, else (mu_s_min + 1) / 2" +
                          std::string(kTexelCentres)},
                     RAxis("y", p.irradiance_height, p, std::string(kRhoOverH) + std::string(kTexelCentres))};
  irradiance.layout = "x = mu_s (" + std::to_string(p.irradiance_width) + "), y = r (" +
                      std::to_string(p.irradiance_height) + ")";
  tables.push_back(irradiance);

  // The 4D tables share their axes.
  const std::vector<TableAxis> axes_4d = {
      {"x", "nu", p.scattering_nu_size, -1.0, 1.0, "1",
       "slice s = (nu + 1) / 2 * (nu_size - 1), linear between slices; texel x = floor(s) * mu_s_size + mu_s texel"},
      {"x", "mu_s", p.scattering_mu_s_size, p.scattering_mu_s_min, p.scattering_mu_s_max, "1",
       "a = (d - d_min) / (d_max - d_min) with d = distance from the ground to the top boundary along mu_s, "
       "d_min = top_radius - bottom_radius, d_max = H; A = a at scattering_mu_s_min; f = max(1 - a / A, 0) / (1 + "
       "a / 2); x = f / f(scattering_mu_s_max)" +
           std::string(kTexelCentres) +
           "; from column scattering_mu_s_split up. Below it (where it is above 0) every ray (r, mu) and sun azimuth "
           "has its own columns, placed from the sun zenith angle E past which no point of the ray sees the sun "
           "(GetScatteringShadowEdgePosition in shadow_edge.glsl): 6 at and past E (the last at E, the others evenly to "
           "max(theta(scattering_mu_s_min), E + 2 degrees)), the others from D = E - theta = 0.05 degrees (D_min) to "
           "the split's sun at even steps of 0.3 (X(E - D) - X(E - D_min)) / (X(theta_split) - X(E - D_min)) + 0.7 "
           "ln(D / D_min) / ln((E - theta_split) / D_min), X = (1 - a / A) / (1 + a)"},
      {"y", "mu", p.scattering_mu_size, -1.0, 1.0, "1",
       "two halves of n / 2 texels, discontinuous at the horizon: rays that hit the ground in the lower half, "
       "u = 0.5 - 0.5 * (0.5 / (n / 2) + x * (1 - 1 / (n / 2))), x = (d - d_min) / (d_max - d_min), d = distance "
       "to the ground, d_min = r - bottom_radius, d_max = rho; other rays in the upper half, u = 0.5 + 0.5 * (...), "
       "d = distance to the top boundary, d_min = top_radius - r, d_max = rho + H"},
      {"z", "r", p.scattering_r_size, p.scattering_r_min, p.scattering_r_max, "m",
       "x = (rho - rho(scattering_r_min)) / (rho(scattering_r_max) - rho(scattering_r_min)), rho(r) = sqrt(r^2 - "
       "bottom_radius^2)" +
           std::string(kTexelCentres)}};
  const std::string layout_4d =
      "x = nu * " + std::to_string(p.scattering_mu_s_size) + " + mu_s (nu " + std::to_string(p.scattering_nu_size) +
      ", mu_s " + std::to_string(p.scattering_mu_s_size) + "), y = mu (" + std::to_string(p.scattering_mu_size) +
      "), z = r (" + std::to_string(p.scattering_r_size) + "); EXR files stack the z slices vertically (row = z * " +
      std::to_string(p.scattering_mu_size) + " + y)";
  auto table_4d = [&](TableDescription t) {
    t.axes = axes_4d;
    t.layout = layout_4d;
    t.is_3d = true;
    t.width = p.scattering_nu_size * p.scattering_mu_s_size;
    t.height = p.scattering_mu_size;
    t.depth = p.scattering_r_size;
    t.units = colour ? "cd m^-2 (Y; X and Z alike)" : "W m^-2 sr^-1 nm^-1";
    return t;
  };

  TableDescription scattering;
  scattering.name = "scattering";
  scattering.encoding = packed ? "single Rayleigh + multiple scattering radiance / Rayleigh phase (RGB), "
                                 "single Mie radiance without phase function, red only (A)"
                               : "single Rayleigh + multiple scattering radiance / Rayleigh phase";
  scattering.channels = rgb("single Rayleigh + multiple scattering / Rayleigh phase");
  if (packed) {
    scattering.channels.push_back(
        {"A", w[0], "single Mie scattering at " + Nm(w[0]) + " without phase function (other wavelengths rebuilt "
                    "at run time from mie_to_rayleigh_scattering_ratio)"});
  }
  tables.push_back(table_4d(scattering));

  if (!packed) {
    TableDescription single_mie;
    single_mie.name = "single_mie_scattering";
    single_mie.encoding = "single Mie scattering radiance without phase function";
    single_mie.channels = rgb("single Mie scattering without phase function");
    tables.push_back(table_4d(single_mie));
  }
  if (luts.scene) {
    // A scene's set holds only the tables its plan keeps.
    const ScenePlan plan = PlanScene(*luts.scene, luts.atmosphere);
    auto kept = [&](const TableDescription& t) {
      if (t.name == "irradiance") return plan.irradiance;
      if (t.name == "scattering" || t.name == "single_mie_scattering") return plan.scattering;
      return plan.transmittance;
    };
    tables.erase(std::remove_if(tables.begin(), tables.end(), [&](const TableDescription& t) { return !kept(t); }),
                 tables.end());
  }
  return tables;
}

glsl::Texture& TableTexture(LutSet& luts, const std::string& name) {
  if (name == "transmittance") return luts.transmittance;
  if (name == "irradiance") return luts.irradiance;
  if (name == "scattering") return luts.scattering;
  if (name == "single_mie_scattering") return luts.single_mie_scattering;
  throw InternalError("no table named '" + name + "'");
}

const glsl::Texture& TableTexture(const LutSet& luts, const std::string& name) {
  return TableTexture(const_cast<LutSet&>(luts), name);
}

Metadata TableMetadata(const LutSet& luts, const TableDescription& table) {
  // The channels' wavelengths, or those a spectral set's XYZ integrates.
  const Spectrum& w = luts.atmosphere.wavelengths_nm;
  const std::vector<double> listed = luts.colour ? luts.colour->wavelengths_nm : std::vector<double>{w.x, w.y, w.z};
  std::string wavelengths;
  for (double nm : listed) {
    char number[32];
    std::snprintf(number, sizeof(number), "%.17g", nm);
    wavelengths += (wavelengths.empty() ? "" : ",") + std::string(number);
  }
  std::string channels;
  for (const TableChannel& c : table.channels) channels += (channels.empty() ? "" : ",") + c.name;
  return Metadata{
      {kTableKey, table.name},
      {kEncodingKey, table.encoding},
      {kUnitsKey, table.units},
      {kWavelengthsKey, wavelengths},
      {kParametersKey, ParametersToJson(luts.parameters).dump()},
      {kLayoutKey, table.layout},
      {kChannelsKey, channels},
      {kAtmosphereKey, ToToml(luts.atmosphere)},
  };
}

TableImage MakeTableImage(const LutSet& luts, const TableDescription& table, FileFormat format, PixelType type) {
  const glsl::Texture& texture = TableTexture(luts, table.name);
  if (texture.width != table.width || texture.height != table.height || texture.depth != table.depth) {
    throw InternalError("table " + table.name + " is " + std::to_string(texture.width) + "x" +
                        std::to_string(texture.height) + "x" + std::to_string(texture.depth) +
                        ", its parameters say " + std::to_string(table.width) + "x" + std::to_string(table.height) +
                        "x" + std::to_string(table.depth));
  }
  TableImage image;
  image.format = format;
  image.pixel_type = type;
  image.width = table.width;
  image.height = table.height;
  image.depth = table.depth;
  image.is_3d = table.is_3d;
  const std::size_t channels = table.channels.size();
  for (const TableChannel& c : table.channels) image.channel_names.push_back(c.name);
  image.values.resize(image.TexelCount() * channels);
  for (std::size_t i = 0; i < image.TexelCount(); ++i) {
    for (std::size_t c = 0; c < channels; ++c) image.values[i * channels + c] = texture.texels[4 * i + c];
  }
  image.metadata = TableMetadata(luts, table);
  return image;
}

void CopyTableImage(const TableImage& image, const TableDescription& table, glsl::Texture* texture,
                    const std::string& source) {
  auto kind = image.metadata.find(kTableKey);
  if (kind == image.metadata.end()) throw IoError(source + ": not a skybake table (no " + kTableKey + ")");
  if (kind->second != table.name) {
    throw IoError(source + ": holds the " + kind->second + " table, expected " + table.name);
  }
  if (image.width != table.width || image.height != table.height || image.depth != table.depth ||
      image.is_3d != table.is_3d) {
    auto size = [](int w, int h, int d, bool is_3d) {
      return std::to_string(w) + "x" + std::to_string(h) + (is_3d ? "x" + std::to_string(d) : "");
    };
    throw IoError(source + ": is " + size(image.width, image.height, image.depth, image.is_3d) +
                  ", the manifest's parameters say " + size(table.width, table.height, table.depth, table.is_3d));
  }
  std::vector<int> index;  // image channel of each table channel
  for (const TableChannel& c : table.channels) {
    auto found = std::find(image.channel_names.begin(), image.channel_names.end(), c.name);
    if (found == image.channel_names.end()) throw IoError(source + ": missing channel " + c.name);
    index.push_back(static_cast<int>(found - image.channel_names.begin()));
  }
  *texture = glsl::Texture(table.width, table.height, table.depth);
  const std::size_t stride = image.channel_names.size();
  for (std::size_t i = 0; i < image.TexelCount(); ++i) {
    for (std::size_t c = 0; c < index.size(); ++c) texture->texels[4 * i + c] = image.values[i * stride + index[c]];
  }
}

}  // namespace skybake
