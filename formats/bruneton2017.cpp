#include "formats/bruneton2017.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <nlohmann/json.hpp>

#include "core/errors.h"
#include "core/file_io.h"
#include "shaders_runtime/runtime.h"
#include "shaders_runtime/twin.h"

namespace skybake {

namespace {

using glsl::ClampCosine;
using glsl::vec3;

// The inverse of Bruneton's GetTextureCoordFromUnitRange, u = 0.5 / n +
// x (1 - 1 / n), at the centre u = (i + 0.5) / n of texel i: x = i / (n - 1).
double UnitRangeAtTexel(int i, int n) { return double(i) / double(n - 1); }

// With H = sqrt(top^2 - bottom^2) and rho = sqrt(r^2 - bottom^2), the
// distance d to the top boundary along mu satisfies
// d^2 + 2 r mu d + r^2 = top^2, so mu = (H^2 - rho^2 - d^2) / (2 r d)
// (1 where d = 0, straight up from the top).
double MuOfDistanceToTop(double H, double rho, double r, double d) {
  return d == 0.0 ? 1.0 : ClampCosine((H * H - rho * rho - d * d) / (2.0 * r * d));
}

// The distance to the ground along mu: d^2 + 2 r mu d + r^2 = bottom^2, so
// mu = -(rho^2 + d^2) / (2 r d) (-1 where d = 0, straight down on the ground).
double MuOfDistanceToGround(double rho, double r, double d) {
  return d == 0.0 ? -1.0 : ClampCosine(-(rho * rho + d * d) / (2.0 * r * d));
}

double DistanceToTop(double top_radius, double r, double mu) {
  const double discriminant = r * r * (mu * mu - 1.0) + top_radius * top_radius;
  return std::max(0.0, -r * mu + std::sqrt(std::max(0.0, discriminant)));
}

TableImage EmptyImage(const Bruneton2017Layout&, const char* table, int width, int height, int depth,
                      PixelType pixel_type) {
  TableImage image;
  image.format = FileFormat::kExr;
  image.pixel_type = pixel_type;
  image.width = width, image.height = height, image.depth = depth, image.is_3d = depth > 1;
  image.channel_names = {"R", "G", "B", "A"};
  image.values.resize(image.TexelCount() * 4);
  image.metadata[kTableKey] = table;
  image.metadata[kLayoutKey] = "bruneton2017";
  return image;
}

void Store(TableImage* image, std::size_t texel, const vec3& rgb, double alpha) {
  float* v = &image->values[texel * 4];
  v[0] = float(rgb.x), v[1] = float(rgb.y), v[2] = float(rgb.z), v[3] = float(alpha);
}

void CheckExportable(const LutSet& luts) {
  if (luts.scene) {
    throw InputError("scene '" + luts.scene->name +
                     "': the Bruneton 2017 layout covers the whole atmosphere; export a set baked without --scene");
  }
  if (luts.colour) {
    throw InputError("a spectral bake's tables hold CIE XYZ colour; the Bruneton 2017 layout holds one wavelength "
                     "per channel (bake without --spectral)");
  }
  if (luts.parameters.mie_phase != glsl::PHASE_CORNETTE_SHANKS && luts.parameters.mie_g != 0.0) {
    throw InputError("the set's Mie phase function is Henyey-Greenstein; the Bruneton 2017 runtimes evaluate only "
                     "Cornette-Shanks");
  }
}

}  // namespace

RMu Bruneton2017TransmittanceTexel(const Bruneton2017Layout& layout, double bottom_radius, double top_radius, int x,
                                   int y) {
  const double H = std::sqrt(top_radius * top_radius - bottom_radius * bottom_radius);
  const double rho = H * UnitRangeAtTexel(y, layout.transmittance_height);
  const double r = std::sqrt(rho * rho + bottom_radius * bottom_radius);
  // x runs over the distance to the top, from straight up (top - r) to the
  // horizon (rho + H).
  const double d_min = top_radius - r, d_max = rho + H;
  const double d = d_min + UnitRangeAtTexel(x, layout.transmittance_width) * (d_max - d_min);
  return {r, MuOfDistanceToTop(H, rho, r, d)};
}

RMu Bruneton2017IrradianceTexel(const Bruneton2017Layout& layout, double bottom_radius, double top_radius, int x,
                                int y) {
  const double r = bottom_radius + UnitRangeAtTexel(y, layout.irradiance_height) * (top_radius - bottom_radius);
  return {r, ClampCosine(2.0 * UnitRangeAtTexel(x, layout.irradiance_width) - 1.0)};
}

ScatteringTexelGeometry Bruneton2017ScatteringTexel(const Bruneton2017Layout& layout, double bottom_radius,
                                                    double top_radius, int x, int y, int z) {
  ScatteringTexelGeometry g;
  const double H = std::sqrt(top_radius * top_radius - bottom_radius * bottom_radius);
  const double rho = H * UnitRangeAtTexel(z, layout.scattering_r_size);
  g.r = std::sqrt(rho * rho + bottom_radius * bottom_radius);

  // mu: the lower half of the rows holds the rays that meet the ground, by
  // their distance to it from the horizon (row half - 1) down to straight
  // down (row 0); the upper half the others, by their distance to the top
  // from straight up (row half) to the horizon.
  const int half = layout.scattering_mu_size / 2;
  g.ray_intersects_ground = y < half;
  if (g.ray_intersects_ground) {
    const double d_min = g.r - bottom_radius, d_max = rho;
    const double d = d_min + UnitRangeAtTexel(half - 1 - y, half) * (d_max - d_min);
    g.mu = MuOfDistanceToGround(rho, g.r, d);
  } else {
    const double d_min = top_radius - g.r, d_max = rho + H;
    const double d = d_min + UnitRangeAtTexel(y - half, half) * (d_max - d_min);
    g.mu = MuOfDistanceToTop(H, rho, g.r, d);
  }

  // mu_s: by the distance d to the top from the ground along mu_s, through
  // x_mu_s = 1 - a / A with a = (d - d_min) / (d_max - d_min) and A that of
  // mu_s_min, warped as a = A (1 - x) / (1 + x A) so that low suns get more
  // texels.
  const int nu_index = x / layout.scattering_mu_s_size;
  const int mu_s_index = x - nu_index * layout.scattering_mu_s_size;
  const double x_mu_s = UnitRangeAtTexel(mu_s_index, layout.scattering_mu_s_size);
  const double d_min = top_radius - bottom_radius, d_max = H;
  const double A = (DistanceToTop(top_radius, bottom_radius, layout.mu_s_min) - d_min) / (d_max - d_min);
  const double a = (A - x_mu_s * A) / (1.0 + x_mu_s * A);
  const double d = d_min + std::min(a, A) * (d_max - d_min);
  g.mu_s = d == 0.0 ? 1.0 : ClampCosine((H * H - d * d) / (2.0 * bottom_radius * d));

  // nu: linear in [-1, 1] over the slices (slice coordinate index / (size - 1)),
  // then clamped to what mu and mu_s allow.
  g.nu = ClampedNu(2.0 * double(nu_index) / double(layout.scattering_nu_size - 1) - 1.0, g.mu, g.mu_s);
  return g;
}

Bruneton2017Tables ResampleToBruneton2017(const LutSet& luts, const Bruneton2017Layout& layout, PixelType pixel_type) {
  CheckExportable(luts);
  const Twin twin(MakeTwinTables(luts));
  const double bottom = luts.parameters.bottom_radius, top = luts.parameters.top_radius;
  // The set has no light for a sun below its lowest.
  const double lowest_mu_s = luts.parameters.mu_s_min;
  Bruneton2017Tables t;

  t.transmittance = EmptyImage(layout, "transmittance", layout.transmittance_width, layout.transmittance_height, 1,
                               pixel_type);
  for (int y = 0; y < layout.transmittance_height; ++y) {
    for (int x = 0; x < layout.transmittance_width; ++x) {
      const RMu g = Bruneton2017TransmittanceTexel(layout, bottom, top, x, y);
      Store(&t.transmittance, std::size_t(y) * layout.transmittance_width + x,
            glsl::exp(-twin.OpticalDepthToTop(g.r, g.mu)), 1.0);
    }
  }

  t.irradiance =
      EmptyImage(layout, "irradiance", layout.irradiance_width, layout.irradiance_height, 1, pixel_type);
  for (int y = 0; y < layout.irradiance_height; ++y) {
    for (int x = 0; x < layout.irradiance_width; ++x) {
      const RMu g = Bruneton2017IrradianceTexel(layout, bottom, top, x, y);
      const vec3 irradiance = g.mu >= lowest_mu_s ? twin.Irradiance(g.r, g.mu) : vec3(0.0);
      Store(&t.irradiance, std::size_t(y) * layout.irradiance_width + x, irradiance, 1.0);
    }
  }

  const int width = layout.scattering_nu_size * layout.scattering_mu_s_size;
  t.scattering = EmptyImage(layout, "scattering", width, layout.scattering_mu_size, layout.scattering_r_size,
                            pixel_type);
  t.single_mie_scattering = EmptyImage(layout, "single_mie_scattering", width, layout.scattering_mu_size,
                                       layout.scattering_r_size, pixel_type);
  for (int z = 0; z < layout.scattering_r_size; ++z) {
    for (int y = 0; y < layout.scattering_mu_size; ++y) {
      for (int x = 0; x < width; ++x) {
        const ScatteringTexelGeometry g = Bruneton2017ScatteringTexel(layout, bottom, top, x, y, z);
        vec3 scattering(0.0), single_mie(0.0);
        if (g.mu_s >= lowest_mu_s) {
          scattering = twin.CombinedScattering(g.r, g.mu, g.mu_s, g.nu, g.ray_intersects_ground, &single_mie);
        }
        const std::size_t texel = (std::size_t(z) * layout.scattering_mu_size + y) * width + x;
        Store(&t.scattering, texel, scattering, single_mie.x);
        Store(&t.single_mie_scattering, texel, single_mie, 1.0);
      }
    }
  }
  return t;
}

std::string Bruneton2017ParametersJson(const LutSet& luts, const Bruneton2017Layout& layout) {
  using nlohmann::json;
  const glsl::AtmosphereParameters& p = luts.parameters;
  Spectrum mie, others;
  GroundScatteringOfMieAndOthers(luts.atmosphere, &mie, &others);
  auto per_km = [](const Spectrum& s) { return json::array({s[0] * 1e3, s[1] * 1e3, s[2] * 1e3}); };
  json parameters = {
      {"solarIrradiance", {p.solar_irradiance.x, p.solar_irradiance.y, p.solar_irradiance.z}},
      {"sunAngularRadius", p.sun_angular_radius},
      {"bottomRadius", p.bottom_radius},
      {"topRadius", p.top_radius},
      // Only their ratio is read at run time, to rebuild single Mie's green
      // and blue from the combined layout's alpha.
      {"rayleighScattering", per_km(others)},
      {"mieScattering", per_km(mie)},
      {"miePhaseFunctionG", p.mie_g},
      {"muSMin", layout.mu_s_min},
  };
  json document = {
      {"layout", "bruneton2017"},
      {"atmosphere", luts.atmosphere.name},
      {"wavelengths_nm", {luts.atmosphere.wavelengths_nm[0], luts.atmosphere.wavelengths_nm[1],
                          luts.atmosphere.wavelengths_nm[2]}},
      {"set_lowest_sun_mu_s", p.mu_s_min},
      {"sizes",
       {{"transmittance", {layout.transmittance_width, layout.transmittance_height}},
        {"scattering", {layout.scattering_nu_size, layout.scattering_mu_s_size, layout.scattering_mu_size,
                        layout.scattering_r_size}},
        {"irradiance", {layout.irradiance_width, layout.irradiance_height}}}},
      {"parameters", parameters},
  };
  return document.dump(2) + "\n";
}

void WriteBruneton2017Set(const LutSet& luts, const Bruneton2017Layout& layout, PixelType pixel_type,
                          const std::filesystem::path& dir) {
  Bruneton2017Tables tables = ResampleToBruneton2017(luts, layout, pixel_type);
  const std::string parameters = Bruneton2017ParametersJson(luts, layout);
  EnsureWritableDirectory(dir);
  StagedFiles files;
  for (TableImage* image : {&tables.transmittance, &tables.scattering, &tables.single_mie_scattering,
                            &tables.irradiance}) {
    image->exr_compression = ExrCompression::kZip;
    const std::vector<std::uint8_t> bytes = EncodeTableImage(*image);
    files.Write(dir / (image->metadata[kTableKey] + ".exr"),
                std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
  }
  files.Write(dir / "parameters.json", parameters);
  files.Commit();
}

}  // namespace skybake
