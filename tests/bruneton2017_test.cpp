// The export into Bruneton's 2017 layout (formats/bruneton2017.h): its texel
// geometry against his forward mappings (written here from functions.glsl
// of his reference implementation, the direction the runtimes read in), the
// sky his runtime's lookups read from it against skybake's own runtime, and,
// for Earth, its textures against those three-atmosphere ships (computed by
// his precomputation on a GPU).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "bake/config.h"
#include "core/constants.h"
#include "formats/bruneton2017.h"
#include "report/error_stats.h"
#include "shaders_runtime/runtime.h"
#include "shaders_runtime/twin.h"
#include "tests/test_util.h"

namespace skybake {
namespace {

using glsl::vec3;
using glsl::vec4;

// ---------------------------------------------------------------------------
// Bruneton's forward mappings, (r, mu, ...) to texture coordinates.

double TextureCoordFromUnitRange(double x, int n) { return 0.5 / n + x * (1.0 - 1.0 / n); }
double DistanceToTop(double top, double r, double mu) { return std::max(0.0, -r * mu + glsl::SafeSqrt(r * r * (mu * mu - 1.0) + top * top)); }

struct Planet {
  double bottom, top;
  double H() const { return std::sqrt(top * top - bottom * bottom); }
};

glsl::vec2 TransmittanceUv(const Bruneton2017Layout& l, const Planet& p, double r, double mu) {
  const double rho = glsl::SafeSqrt(r * r - p.bottom * p.bottom);
  const double d = DistanceToTop(p.top, r, mu), d_min = p.top - r, d_max = rho + p.H();
  return {TextureCoordFromUnitRange((d - d_min) / (d_max - d_min), l.transmittance_width),
          TextureCoordFromUnitRange(rho / p.H(), l.transmittance_height)};
}

glsl::vec2 IrradianceUv(const Bruneton2017Layout& l, const Planet& p, double r, double mu_s) {
  return {TextureCoordFromUnitRange(mu_s * 0.5 + 0.5, l.irradiance_width),
          TextureCoordFromUnitRange((r - p.bottom) / (p.top - p.bottom), l.irradiance_height)};
}

vec4 ScatteringUvwz(const Bruneton2017Layout& l, const Planet& p, double r, double mu, double mu_s, double nu,
                    bool ground) {
  const double H = p.H(), rho = glsl::SafeSqrt(r * r - p.bottom * p.bottom);
  const double u_r = TextureCoordFromUnitRange(rho / H, l.scattering_r_size);
  const double r_mu = r * mu, discriminant = r_mu * r_mu - r * r + p.bottom * p.bottom;
  double u_mu;
  if (ground) {
    const double d = -r_mu - glsl::SafeSqrt(discriminant), d_min = r - p.bottom, d_max = rho;
    u_mu = 0.5 - 0.5 * TextureCoordFromUnitRange(d_max == d_min ? 0.0 : (d - d_min) / (d_max - d_min),
                                                 l.scattering_mu_size / 2);
  } else {
    const double d = -r_mu + glsl::SafeSqrt(discriminant + H * H), d_min = p.top - r, d_max = rho + H;
    u_mu = 0.5 + 0.5 * TextureCoordFromUnitRange((d - d_min) / (d_max - d_min), l.scattering_mu_size / 2);
  }
  const double d_min = p.top - p.bottom, d_max = H;
  const double a = (DistanceToTop(p.top, p.bottom, mu_s) - d_min) / (d_max - d_min);
  const double A = (DistanceToTop(p.top, p.bottom, l.mu_s_min) - d_min) / (d_max - d_min);
  const double u_mu_s = TextureCoordFromUnitRange(std::max(1.0 - a / A, 0.0) / (1.0 + a), l.scattering_mu_s_size);
  return {(nu + 1.0) / 2.0, u_mu_s, u_mu, u_r};
}

// Linear filtering with clamp-to-edge of an RGBA table image (a 3D one
// stacked as rows z * height + y), as a GPU samples it.
vec4 Texel(const TableImage& t, int x, int y, int z) {
  x = std::clamp(x, 0, t.width - 1), y = std::clamp(y, 0, t.height - 1), z = std::clamp(z, 0, t.depth - 1);
  const float* v = &t.values[((std::size_t(z) * t.height + y) * t.width + x) * 4];
  return {v[0], v[1], v[2], v[3]};
}
vec4 Sample(const TableImage& t, double u, double v, double w = 0.5) {
  const double x = u * t.width - 0.5, y = v * t.height - 0.5, z = w * t.depth - 0.5;
  const int x0 = int(std::floor(x)), y0 = int(std::floor(y)), z0 = int(std::floor(z));
  const double fx = x - x0, fy = y - y0, fz = z - z0;
  vec4 sum(0.0);
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i)
        sum += Texel(t, x0 + i, y0 + j, z0 + k) * ((i ? fx : 1 - fx) * (j ? fy : 1 - fy) * (k ? fz : 1 - fz));
  return sum;
}

// GetScattering of Bruneton's runtime: the two nu slices either side, each
// trilinear.
vec3 Scattering(const Bruneton2017Layout& l, const Planet& p, const TableImage& table, double r, double mu,
                double mu_s, double nu, bool ground) {
  const vec4 uvwz = ScatteringUvwz(l, p, r, mu, mu_s, nu, ground);
  const double x = uvwz.x * (l.scattering_nu_size - 1), slice = std::floor(x), t = x - slice;
  const vec4 a = Sample(table, (slice + uvwz.y) / l.scattering_nu_size, uvwz.z, uvwz.w);
  const vec4 b = Sample(table, (slice + 1.0 + uvwz.y) / l.scattering_nu_size, uvwz.z, uvwz.w);
  return vec3(a * (1.0 - t) + b * t);
}

double RayleighPhase(double nu) { return 3.0 / (16.0 * kPi) * (1.0 + nu * nu); }
double CornetteShanksPhase(double g, double nu) {
  const double k = 3.0 / (8.0 * kPi) * (1.0 - g * g) / (2.0 + g * g);
  return k * (1.0 + nu * nu) / std::pow(1.0 + g * g - 2.0 * g * nu, 1.5);
}

const LutSet& DefaultEarth() {
  static const LutSet luts = Bake(LoadPreset("earth"), BakeSettings{});
  return luts;
}

// ---------------------------------------------------------------------------

TEST(Bruneton2017Layout, EveryTexelsGeometryMapsBackToItsCentre) {
  const Planet p{6360e3, 6420e3};
  Bruneton2017Layout l;
  l.mu_s_min = std::cos(120.0 * kPi / 180.0);
  double worst = 0.0;
  for (int y = 0; y < l.transmittance_height; ++y) {
    for (int x = 0; x < l.transmittance_width; ++x) {
      const RMu g = Bruneton2017TransmittanceTexel(l, p.bottom, p.top, x, y);
      const glsl::vec2 uv = TransmittanceUv(l, p, g.r, g.mu);
      worst = std::max({worst, std::abs(uv.x * l.transmittance_width - (x + 0.5)),
                        std::abs(uv.y * l.transmittance_height - (y + 0.5))});
    }
  }
  for (int y = 0; y < l.irradiance_height; ++y) {
    for (int x = 0; x < l.irradiance_width; ++x) {
      const RMu g = Bruneton2017IrradianceTexel(l, p.bottom, p.top, x, y);
      const glsl::vec2 uv = IrradianceUv(l, p, g.r, g.mu);
      worst = std::max({worst, std::abs(uv.x * l.irradiance_width - (x + 0.5)),
                        std::abs(uv.y * l.irradiance_height - (y + 0.5))});
    }
  }
  const int width = l.scattering_nu_size * l.scattering_mu_s_size;
  for (int z = 0; z < l.scattering_r_size; ++z) {
    for (int y = 0; y < l.scattering_mu_size; ++y) {
      // On the ground every ray that meets it has d = 0: the rows are one ray.
      if (z == 0 && y < l.scattering_mu_size / 2) continue;
      for (int x = 0; x < width; ++x) {
        const ScatteringTexelGeometry g = Bruneton2017ScatteringTexel(l, p.bottom, p.top, x, y, z);
        const vec4 uvwz = ScatteringUvwz(l, p, g.r, g.mu, g.mu_s, g.nu, g.ray_intersects_ground);
        const int mu_s_index = x % l.scattering_mu_s_size, nu_index = x / l.scattering_mu_s_size;
        worst = std::max({worst, std::abs(uvwz.y * l.scattering_mu_s_size - (mu_s_index + 0.5)),
                          std::abs(uvwz.z * l.scattering_mu_size - (y + 0.5)),
                          std::abs(uvwz.w * l.scattering_r_size - (z + 0.5))});
        // nu is the slice's own (index / (size - 1)) where mu and mu_s allow it.
        const double slice_nu = 2.0 * nu_index / (l.scattering_nu_size - 1) - 1.0;
        EXPECT_LE(std::abs(g.nu - ClampedNu(slice_nu, g.mu, g.mu_s)), 1e-12);
        ASSERT_EQ(g.ray_intersects_ground, y < l.scattering_mu_size / 2);
      }
    }
  }
  // In texels: a thousandth, what rounding costs where mu is near +-1 and
  // the distances move fastest with it.
  EXPECT_LT(worst, 1e-3);
}

// Sky radiance as Bruneton's runtime assembles it from the export
// (scattering * RayleighPhase + single Mie * MiePhase), against skybake's
// runtime on the set it came from, for daylight views from the ground to
// 50 km, every direction and suns up to 85 degrees.
TEST(Bruneton2017Export, DaylightSkyFromTheExportMatchesSkybakesRuntime) {
  const LutSet& luts = DefaultEarth();
  const Bruneton2017Layout layout{.mu_s_min = luts.parameters.mu_s_min};
  const Bruneton2017Tables tables = ResampleToBruneton2017(luts, layout, PixelType::kHalf);
  const Twin twin(MakeTwinTables(luts));
  const Planet p{luts.parameters.bottom_radius, luts.parameters.top_radius};
  const double g = luts.parameters.mie_g;
  // Views in the sun zenith range [low, high) degrees.
  auto measure = [&](double low, double high) {
    std::vector<report::ErrorSample> samples;
    for (double altitude : {0.0, 1e3, 5e3, 20e3, 50e3}) {
      const double r = p.bottom + altitude;
      for (int i = 0; i < 24; ++i) {
        const double mu = std::cos((i + 0.5) / 24.0 * kPi);
        for (int j = 0; j < 18; ++j) {
          const double mu_s = std::cos((low + (j + 0.5) / 18.0 * (high - low)) * kPi / 180.0);
          for (int k = 0; k < 12; ++k) {
            const double azimuth = k / 11.0 * kPi;
            const double nu = mu * mu_s + std::cos(azimuth) * glsl::SafeSqrt((1 - mu * mu) * (1 - mu_s * mu_s));
            const bool ground = r * r * (mu * mu - 1.0) + p.bottom * p.bottom >= 0.0 && mu < 0.0;
            vec3 mie;
            const vec3 own = twin.CombinedScattering(r, mu, mu_s, nu, ground, &mie);
            const vec3 expected = own * RayleighPhase(nu) + mie * CornetteShanksPhase(g, nu);
            const vec3 s = Scattering(layout, p, tables.scattering, r, mu, mu_s, nu, ground);
            const vec3 m = Scattering(layout, p, tables.single_mie_scattering, r, mu, mu_s, nu, ground);
            const vec3 exported = s * RayleighPhase(nu) + m * CornetteShanksPhase(g, nu);
            samples.push_back({report::Luminance(exported), report::Luminance(expected), 0.0});
          }
        }
      }
    }
    const report::ErrorStats stats = report::ComputeErrorStats(samples);
    std::printf("export against skybake's runtime, sun %g-%g deg, luminance over %d views: mean %.3f%%, RMS %.3f%%, "
                "max %.3f%%\n",
                low, high, stats.count, 100 * stats.mean_relative, 100 * stats.rms_relative,
                100 * stats.max_relative);
    return stats;
  };
  // What the layout loses after sunset, reported (docs/bruneton2017.md).
  measure(85.0, 90.0);
  measure(90.0, 96.0);
  measure(96.0, 102.0);
  const report::ErrorStats stats = measure(0.0, 85.0);
  EXPECT_GT(stats.count, 20000);
  EXPECT_LT(stats.rms_relative, 0.025);
}

// The export of skybake's Earth (Bruneton's own parameters) against the
// textures three-atmosphere ships for it, texel by texel, on the lowest sun
// those use (120 degrees). Texels where the reference is below `floor` (dark
// ones whose relative difference says nothing) and, in the scattering
// tables, those of suns below the set's lowest (102 degrees; zero in the
// export by design) are left out. Bounds: measured figures with a margin
// (docs/bruneton2017.md gives them and their causes).
TEST(Bruneton2017Export, EarthMatchesThreeAtmospheresTextures) {
  if (std::string(SKYBAKE_NODE_EXECUTABLE).empty()) GTEST_SKIP() << "node is not installed";
  testing::TempDir dir;
  const std::string work_dir = SKYBAKE_NPM_WORK_DIR "/three_atmosphere";
  const std::filesystem::path script = std::filesystem::path(SKYBAKE_SOURCE_DIR) / "tests/three_atmosphere/fetch_assets.mjs";
  std::string out, err;
  const int status = testing::RunCommand(testing::ShellQuote(SKYBAKE_NODE_EXECUTABLE) + " " +
                                             testing::ShellQuote(script.string()) + " --work-dir " +
                                             testing::ShellQuote(work_dir),
                                         dir, &out, &err);
  if (status == 77) GTEST_SKIP() << out;
  ASSERT_EQ(status, 0) << out << err;
  const std::filesystem::path assets = out.substr(0, out.find('\n'));

  const LutSet& luts = DefaultEarth();
  Bruneton2017Layout layout;
  layout.mu_s_min = std::cos(120.0 * kPi / 180.0);
  const Bruneton2017Tables tables = ResampleToBruneton2017(luts, layout, PixelType::kHalf);
  const Planet p{luts.parameters.bottom_radius, luts.parameters.top_radius};

  // Bounds on the daylight texels (sun at most 80 degrees from the zenith)
  // and on all of them up to the set's lowest sun.
  struct Table {
    const char* name;
    const TableImage* exported;
    double floor, day_rms, day_max, rms;
  };
  const Table checked[] = {
      {"transmittance", &tables.transmittance, 1e-3, 0.005, 0.1, 0.005},
      {"irradiance", &tables.irradiance, 1e-4, 0.08, 0.4, 0.08},
      {"scattering", &tables.scattering, 1e-4, 0.03, 0.2, 0.15},
      {"single_mie_scattering", &tables.single_mie_scattering, 1e-5, 0.04, 0.2, 0.05},
  };
  const double day_mu_s = std::cos(80.0 * kPi / 180.0), horizon_mu_s = 0.0;
  for (const Table& t : checked) {
    const TableImage reference = ReadTableImage(assets / (std::string(t.name) + ".exr"));
    ASSERT_EQ(reference.width, t.exported->width) << t.name;
    ASSERT_EQ(reference.height * reference.depth, t.exported->height * t.exported->depth) << t.name;
    ASSERT_EQ(reference.channel_names.size(), 4u) << t.name;
    // Sun groups: day, 80-90 degrees, 90 degrees to the set's lowest sun.
    std::vector<report::ErrorSample> groups[3];
    const std::size_t texels = t.exported->TexelCount();
    for (std::size_t i = 0; i < texels; ++i) {
      const int x = int(i % t.exported->width), yz = int(i / t.exported->width);
      double mu_s = 1.0;
      if (t.exported->depth > 1) {
        mu_s = Bruneton2017ScatteringTexel(layout, p.bottom, p.top, x, yz % t.exported->height,
                                           yz / t.exported->height)
                   .mu_s;
      } else if (t.exported == &tables.irradiance) {
        mu_s = Bruneton2017IrradianceTexel(layout, p.bottom, p.top, x, yz).mu;
      }
      if (mu_s < luts.parameters.mu_s_min) continue;
      const int group = mu_s >= day_mu_s ? 0 : mu_s >= horizon_mu_s ? 1 : 2;
      // three.js's EXRLoader flips rows (the file's first scanline is the
      // texture's last row), and the package's files are written for it.
      const std::size_t rows = std::size_t(reference.height) * reference.depth, row = i / reference.width;
      const std::size_t j = (rows - 1 - row) * reference.width + i % reference.width;
      for (int c = 0; c < 3; ++c) {
        const double ref = reference.values[j * 4 + c];
        if (ref < t.floor) continue;
        groups[group].push_back({t.exported->values[i * 4 + c], ref, 0.0});
      }
    }
    std::vector<report::ErrorSample> all;
    const char* group_names[] = {"sun <= 80 deg", "sun 80-90 deg", "sun 90-102 deg"};
    for (int g = 0; g < 3; ++g) {
      all.insert(all.end(), groups[g].begin(), groups[g].end());
      if (groups[g].empty()) continue;
      const report::ErrorStats stats = report::ComputeErrorStats(groups[g]);
      double bias = 0.0;
      for (const report::ErrorSample& e : groups[g]) bias += (e.value - e.reference) / e.reference;
      std::printf("%s, %s, against three-atmosphere's: %d values, mean %.3f%% (signed %+.3f%%), RMS %.3f%%, max "
                  "%.3f%%\n",
                  t.name, group_names[g], stats.count, 100 * stats.mean_relative, 100 * bias / groups[g].size(),
                  100 * stats.rms_relative, 100 * stats.max_relative);
    }
    const report::ErrorStats day = report::ComputeErrorStats(groups[0]);
    const report::ErrorStats stats = report::ComputeErrorStats(all);
    std::printf("%s, all, against three-atmosphere's: %d values, mean %.3f%%, RMS %.3f%%, max %.3f%%\n", t.name,
                stats.count, 100 * stats.mean_relative, 100 * stats.rms_relative, 100 * stats.max_relative);
    EXPECT_GT(day.count, int(texels / 4)) << t.name;
    EXPECT_LT(day.rms_relative, t.day_rms) << t.name;
    EXPECT_LT(day.max_relative, t.day_max) << t.name;
    EXPECT_LT(stats.rms_relative, t.rms) << t.name;
  }
}

}  // namespace
}  // namespace skybake

namespace skybake {
namespace {

// `skybake convert SET OUT --layout bruneton2017` writes the four tables
// and the parameters, which name three-atmosphere's AtmosphereParameters
// fields; what it cannot export it refuses in one line, writing nothing.
TEST(Bruneton2017Command, WritesTheSetOrRefusesInOneLine) {
  testing::TempDir dir;
  const std::string set = (dir.path() / "set").string(), out = (dir.path() / "b17").string();
  std::string text, err;
  ASSERT_EQ(testing::RunCommand(testing::Skybake() + " bake earth" + testing::kSmallBakeOptions + " -o " +
                                    testing::ShellQuote(set),
                                dir, &text, &err),
            0)
      << err;
  ASSERT_EQ(testing::RunCommand(testing::Skybake() + " convert " + testing::ShellQuote(set) + " " +
                                    testing::ShellQuote(out) + " --layout bruneton2017 --lowest-sun-zenith-deg 120",
                                dir, &text, &err),
            0)
      << err;
  for (const char* file : {"transmittance.exr", "scattering.exr", "single_mie_scattering.exr", "irradiance.exr"}) {
    const TableImage image = ReadTableImage(std::filesystem::path(out) / file);
    EXPECT_EQ(image.pixel_type, PixelType::kHalf) << file;
    EXPECT_EQ(image.channel_names.size(), 4u) << file;
  }
  EXPECT_EQ(ReadTableImage(std::filesystem::path(out) / "scattering.exr").width, 256);
  const nlohmann::json parameters =
      nlohmann::json::parse(testing::ReadText(std::filesystem::path(out) / "parameters.json"))["parameters"];
  for (const char* key : {"solarIrradiance", "sunAngularRadius", "bottomRadius", "topRadius", "rayleighScattering",
                          "mieScattering", "miePhaseFunctionG", "muSMin"}) {
    EXPECT_TRUE(parameters.contains(key)) << key;
  }
  EXPECT_NEAR(parameters["muSMin"].get<double>(), -0.5, 1e-12);
  EXPECT_DOUBLE_EQ(parameters["bottomRadius"].get<double>(), 6360e3);

  const std::string refused[] = {
      " convert " + testing::ShellQuote(set) + " " + testing::ShellQuote(out + "2") + " --layout other",
      " convert " + testing::ShellQuote(set + "/skybake.json") + " " + testing::ShellQuote(out + "2") +
          " --layout bruneton2017",
      " convert " + testing::ShellQuote(set) + " " + testing::ShellQuote(set) + " --layout bruneton2017",
      " convert " + testing::ShellQuote(set) + " " + testing::ShellQuote(out + "2") +
          " --layout bruneton2017 --lowest-sun-zenith-deg 80",
  };
  for (const std::string& command : refused) {
    EXPECT_NE(testing::RunCommand(testing::Skybake() + command, dir, &text, &err), 0) << command;
    EXPECT_EQ(testing::Lines(err).size(), 1u) << command << "\n" << err;
    EXPECT_FALSE(std::filesystem::exists(out + "2")) << command;
  }
}

}  // namespace
}  // namespace skybake
