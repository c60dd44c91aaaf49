// The scattering tables' sun axis after sunset (shadow_edge.glsl, "The sun
// axis after sunset"): each ray's shadow edge, the own columns the bake
// places from it, and single scattering alone read through them against an
// independent quadrature, in twilight and in daylight, on Earth and on
// other atmospheres.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include <tbb/parallel_for.h>

#include "bake/bake.h"
#include "bake/config.h"
#include "bake/ray_integrals.h"
#include "bake/own_column_suns.h"
#include "core/constants.h"
#include "shaders_runtime/runtime.h"
#include "test_atmospheres.h"

namespace skybake {
namespace {

constexpr double kDegree = kPi / 180.0;

// nu: the cosine between the view (zenith cosine mu) and the sun at zenith
// angle `sun` and azimuth phi from the view.
double ViewSunCosine(double mu, double sun, double phi) {
  return mu * std::cos(sun) + glsl::SafeSqrt(1.0 - mu * mu) * std::sin(sun) * std::cos(phi);
}

// Single scattering, phase free, times the solar irradiance: the
// constituents with the Rayleigh phase as `rayleigh`, the others as `mie`
// (the atmospheres here have one lobe, the tables' Mie group).
struct Light {
  Spectrum rayleigh{0.0}, mie{0.0};
};

// The radiance of `light` at the angle nu = cos(theta) from the sun: each
// part times its phase function.
Spectrum Radiance(const glsl::AtmosphereParameters& p, const Light& light, double nu) {
  return light.rayleigh * glsl::RayleighPhaseFunction(nu) + light.mie * glsl::MiePhaseFunction(p, nu);
}

// Single scattering along the ray (r, mu) for the sun at (mu_s, nu) by its
// own quadrature, independent of the bake's: the trapezoid rule on 2048
// intervals, exponential between samples, each interval the shadow edge
// crosses (or the sun's disc straddles the horizon in) cut into 128. The
// sun's optical depth comes from the transmittance table, as the bake reads
// it, so that the comparison measures the scattering table alone.
Light SingleScatteringQuadrature(const LutSet& luts, double r, double mu, double mu_s, double nu) {
  const Atmosphere& a = luts.atmosphere;
  const glsl::AtmosphereParameters& p = luts.parameters;
  const glsl::sampler2D transmittance{&luts.transmittance};
  const double d = glsl::DistanceToNearestAtmosphereBoundary(p, r, mu, glsl::RayIntersectsGround(p, r, mu));
  struct Sample {
    std::vector<double> density;
    Spectrum optical_depth{0.0};  // from the ray's start
    Light light;
    double visible = 0.0;
  };
  auto sample_at = [&](double t, const Sample* previous, double step) {
    Sample s;
    const double radius = std::sqrt(t * t + 2.0 * r * mu * t + r * r);
    for (const Constituent& c : a.constituents) s.density.push_back(c.density.At(radius - p.bottom_radius));
    if (previous) {
      s.optical_depth = previous->optical_depth;
      for (std::size_t c = 0; c < a.constituents.size(); ++c) {
        s.optical_depth +=
            a.constituents[c].Extinction() * detail::ExponentialTrapezoid(previous->density[c], s.density[c], step);
      }
    }
    const double mu_s_t = glsl::ClampCosine((r * mu_s + t * nu) / radius);
    s.visible = glsl::SunVisibleFraction(p, radius, mu_s_t);
    if (s.visible > 0.0) {
      const Spectrum attenuation = glm::exp(-(s.optical_depth + glsl::GetOpticalDepthToTopAtmosphereBoundary(
                                                                    p, transmittance, radius, mu_s_t))) *
                                   s.visible;
      for (std::size_t c = 0; c < a.constituents.size(); ++c) {
        const Spectrum scattered = a.constituents[c].scattering_per_m * s.density[c] * attenuation;
        (a.constituents[c].phase.kind == PhaseKind::kRayleigh ? s.light.rayleigh : s.light.mie) += scattered;
      }
    }
    return s;
  };
  Light sum;
  auto add = [&](const Sample& from, const Sample& to, double step) {
    for (int c = 0; c < 3; ++c) {
      sum.rayleigh[c] += detail::ExponentialTrapezoid(from.light.rayleigh[c], to.light.rayleigh[c], step);
      sum.mie[c] += detail::ExponentialTrapezoid(from.light.mie[c], to.light.mie[c], step);
    }
  };
  constexpr int kIntervals = 2048, kEdgePieces = 128;
  const double step = d / kIntervals;
  Sample start = sample_at(0.0, nullptr, 0.0);
  for (int k = 1; k <= kIntervals; ++k) {
    Sample end = sample_at(k * step, &start, step);
    const bool edge = start.visible != end.visible || (start.visible > 0.0 && start.visible < 1.0);
    if (edge) {
      Sample piece_start = start;
      for (int i = 1; i <= kEdgePieces; ++i) {
        Sample piece_end = sample_at((k - 1) * step + i * step / kEdgePieces, &piece_start, step / kEdgePieces);
        add(piece_start, piece_end, step / kEdgePieces);
        piece_start = std::move(piece_end);
      }
    } else if (start.visible > 0.0 || end.visible > 0.0) {
      add(start, end, step);
    }
    start = std::move(end);
  }
  return {sum.rayleigh * a.solar_irradiance, sum.mie * a.solar_irradiance};
}

// The views of scripts/twilight_single_scattering.py (zenith 0/45/80/85/88
// degrees, azimuth 0/90/180 from the sun, camera at 0, 1 and 10 km) for
// the sun at `suns`.
struct View {
  double altitude, view_zenith, sun_zenith, azimuth;  // m, degrees
};
std::vector<View> Views(const std::vector<double>& suns) {
  std::vector<View> views;
  for (double sun : suns) {
    for (double view : {0.0, 45.0, 80.0, 85.0, 88.0}) {
      for (double azimuth : {0.0, 90.0, 180.0}) {
        for (double altitude : {0.0, 1000.0, 10000.0}) views.push_back({altitude, view, sun, azimuth});
      }
    }
  }
  return views;
}

// Relative errors of the tables' radiance (with both phase functions) per
// sun range, three channels each, over the values above 0 and over those at
// least kVisible; and the largest value where the exact one is 0.
// kVisible, 1e-9 W m^-2 sr^-1 nm^-1, is a third of the moonless night sky
// at 550 nm; the last lit stretch of a ray near its shadow edge gives
// values down to 1e-16, where the sunlight's grazing path through the
// transmittance table's horizon sets the texels' own error.
constexpr double kVisible = 1e-9;
struct RangeErrors {
  RangeErrors(std::string range_name, double low_sun, double high_sun)
      : name(std::move(range_name)), low(low_sun), high(high_sun) {}
  std::string name;
  double low, high;  // sun zenith, degrees
  std::vector<double> errors, visible_errors;
  std::string largest;  // the view, channel and values of the largest error
  double largest_magnitude = -1.0;
  double largest_where_dark = 0.0;
  static double Rms(const std::vector<double>& of) {
    double sum = 0.0;
    for (double e : of) sum += e * e;
    return std::sqrt(sum / of.size());
  }
  double Rms() const { return Rms(errors); }
  double VisibleRms() const { return Rms(visible_errors); }
  double Quantile(double q) const {
    std::vector<double> magnitudes;
    for (double e : errors) magnitudes.push_back(std::abs(e));
    std::sort(magnitudes.begin(), magnitudes.end());
    return magnitudes[std::min(magnitudes.size() - 1, std::size_t(q * magnitudes.size()))];
  }
};

// The tables' single scattering (GetScattering of both tables, as the
// runtime reads them) against the quadrature at `views`, per range.
std::vector<RangeErrors> Errors(const LutSet& luts, const std::vector<View>& views, std::vector<RangeErrors> ranges) {
  const glsl::AtmosphereParameters& p = luts.parameters;
  const glsl::sampler3D rayleigh_table{&luts.scattering}, mie_table{&luts.single_mie_scattering};
  std::vector<std::array<double, 6>> values(views.size());  // exact, then the tables', per channel
  tbb::parallel_for(std::size_t(0), views.size(), [&](std::size_t i) {
    const View& v = views[i];
    const double r = p.bottom_radius + v.altitude, mu = std::cos(v.view_zenith * kDegree);
    const double sun = v.sun_zenith * kDegree, phi = v.azimuth * kDegree;
    const double nu = ViewSunCosine(mu, sun, phi), mu_s = std::cos(sun);
    const bool ground = glsl::RayIntersectsGround(p, r, mu);
    const Light tables{Spectrum(glsl::GetScattering(p, rayleigh_table, r, mu, mu_s, nu, ground)),
                       Spectrum(glsl::GetScattering(p, mie_table, r, mu, mu_s, nu, ground))};
    const Spectrum exact = Radiance(p, SingleScatteringQuadrature(luts, r, mu, mu_s, nu), nu);
    const Spectrum read = Radiance(p, tables, nu);
    for (int c = 0; c < 3; ++c) values[i][c] = exact[c], values[i][3 + c] = read[c];
  });
  for (std::size_t i = 0; i < views.size(); ++i) {
    for (RangeErrors& range : ranges) {
      const double sun = views[i].sun_zenith;
      if (sun < range.low || sun > range.high || (sun == range.low && range.low != ranges.front().low)) continue;
      for (int c = 0; c < 3; ++c) {
        if (values[i][c] > 0.0) {
          const double error = (values[i][3 + c] - values[i][c]) / values[i][c];
          if (std::abs(error) > range.largest_magnitude) {
            range.largest_magnitude = std::abs(error);
            char line[200];
            std::snprintf(line, sizeof line, "%g m, view %g, azimuth %g, sun %g, channel %d: exact %.3g, tables %.3g",
                          views[i].altitude, views[i].view_zenith, views[i].azimuth, views[i].sun_zenith, c,
                          values[i][c], values[i][3 + c]);
            range.largest = line;
          }
          range.errors.push_back(error);
          if (values[i][c] >= kVisible) range.visible_errors.push_back(error);
        } else {
          range.largest_where_dark = std::max(range.largest_where_dark, values[i][3 + c]);
        }
      }
    }
  }
  return ranges;
}

void Print(const char* what, const std::vector<RangeErrors>& ranges) {
  for (const RangeErrors& r : ranges) {
    std::printf(
        "%-12s sun %-7s %5zu values: RMS %.3g%%, median %.3g%%, 90th pct %.3g%%, max %.3g%%; "
        "%zu at least 1e-9: RMS %.3g%%; largest where exactly dark %.2g\n%-12s   largest error at %s\n",
        what, r.name.c_str(), r.errors.size(), 100 * r.Rms(), 100 * r.Quantile(0.5), 100 * r.Quantile(0.9),
        100 * r.Quantile(1.0), r.visible_errors.size(), 100 * r.VisibleRms(), r.largest_where_dark, "",
        r.largest.c_str());
  }
}

const std::vector<double> kTwilightSuns = {80, 84, 86, 88, 89, 90, 91, 92, 93, 94, 95, 96, 97, 98, 99, 100};
// The targets for single scattering alone, RMS per range.
constexpr double kTargets[] = {0.02, 0.05, 0.10};
std::vector<RangeErrors> TwilightRanges() { return {{"80-90", 80, 90}, {"90-96", 90, 96}, {"96-100", 96, 100}}; }

// ShadowEdgeSunZenith against the sun's visibility sampled along the ray:
// 0.01 degrees before the edge some point sees part of the disc, 0.01
// degrees past it none does; and the light there falls as D^3 (the
// comment of ShadowEdgeLitUnit): doubling D from 0.005 to 0.01 and 0.01 to
// 0.02 degrees multiplies it by 8 within 10 %.
TEST(TwilightSunAxis, ShadowEdgeIsWhereTheLastPointOfTheRaySeesTheSunSet) {
  const LutSet& luts = testing::DefaultSizeEarthSingleScattering();
  const glsl::AtmosphereParameters& p = luts.parameters;
  int rays = 0;
  for (double altitude : {0.0, 1000.0, 10000.0, 40000.0}) {
    for (double view : {0.0, 45.0, 80.0, 88.0, 95.0, 120.0}) {
      for (double azimuth : {0.0, 60.0, 120.0, 180.0}) {
        const double r = p.bottom_radius + altitude, mu = std::cos(view * kDegree), phi = azimuth * kDegree;
        const bool ground = glsl::RayIntersectsGround(p, r, mu);
        const double edge = glsl::ShadowEdgeSunZenith(p, r, mu, std::cos(phi), ground);
        if (edge > kPi - 0.1) continue;  // lit at every sun this side of the nadir
        const double d = glsl::DistanceToNearestAtmosphereBoundary(p, r, mu, ground);
        auto largest_visible = [&](double sun) {
          double largest = 0.0;
          for (int k = 0; k <= 20000; ++k) {
            const double t = d * k / 20000.0, r_t = glsl::RadiusAtDistance(p, r, mu, t);
            const double mu_s_t = glsl::ClampCosine((r * std::cos(sun) + t * ViewSunCosine(mu, sun, phi)) / r_t);
            largest = std::max(largest, glsl::SunVisibleFraction(p, r_t, mu_s_t));
          }
          return largest;
        };
        EXPECT_GT(largest_visible(edge - 0.01 * kDegree), 0.0) << altitude << " m, view " << view << ", az " << azimuth;
        EXPECT_EQ(largest_visible(edge + 0.01 * kDegree), 0.0) << altitude << " m, view " << view << ", az " << azimuth;
        ++rays;
      }
    }
  }
  EXPECT_GE(rays, 60);
  for (double view : {0.0, 85.0}) {
    const double r = p.bottom_radius, mu = std::cos(view * kDegree);
    const double edge = glsl::ShadowEdgeSunZenith(p, r, mu, 1.0, false);
    auto light = [&](double distance) {
      const double sun = edge - distance * kDegree;
      return SingleScatteringQuadrature(luts, r, mu, std::cos(sun), ViewSunCosine(mu, sun, 0.0)).rayleigh;
    };
    const Spectrum near = light(0.005), middle = light(0.01), far = light(0.02);
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(middle[c] / near[c], 8.0, 0.8) << "view " << view << " channel " << c;
      EXPECT_NEAR(far[c] / middle[c], 8.0, 0.8) << "view " << view << " channel " << c;
    }
  }
}

// The own columns' suns: the bake's (OwnColumnSuns, the edge's inverse read
// from a table) within 1e-7 radians of GetScatteringTexel's exact fixed
// point (a ray within a hair of the nadir, whose azimuth is undefined, has
// its fixed point wander by 2e-8); a texel's sun is where the lookup's
// position is its column; the lit columns lie between the split and
// SHADOW_EDGE_CLOSEST before the edge, the others at and past it.
TEST(TwilightSunAxis, OwnColumnsLieWhereTheLookupReadsThem) {
  const glsl::AtmosphereParameters p = MakeAtmosphereParameters(testing::Earth(), BakeSettings());
  ASSERT_GT(p.scattering_mu_s_split, glsl::SHADOW_EDGE_PAST_COLUMNS + 1);
  const detail::OwnColumnSuns own(p);
  const double split_sun = std::acos(glsl::GetScatteringSplitMuS(p, glsl::GetScatteringSunAxis(p)));
  double worst_sun = 0.0, worst_position = 0.0;
  int texels = 0;
  for (int z = 0; z < p.scattering_r_size; z += 3) {
    for (int y = 1; y + 1 < p.scattering_mu_size; y += 3) {
      for (int slice = 0; slice < p.scattering_nu_size; ++slice) {
        for (int column = 0; column < p.scattering_mu_s_split; ++column) {
          const int x = slice * p.scattering_mu_s_size + column;
          const ScatteringTexel t = GetScatteringTexel(p, x, y, z);
          const double sun = std::acos(t.mu_s);
          worst_sun = std::max(worst_sun, std::abs(std::acos(own.MuS(x, y, z)) - sun));
          const glsl::vec4 uvwz =
              glsl::GetScatteringTextureUvwzFromRMuMuSNu(p, t.r, t.mu, t.mu_s, t.nu, t.ray_intersects_ground);
          worst_position = std::max(worst_position, std::abs(uvwz.y * p.scattering_mu_s_size - 0.5 - column));
          const double edge = glsl::ShadowEdgeSunZenith(p, t.r, t.mu, glsl::ViewSunAzimuthCosine(t.mu, t.mu_s, t.nu),
                                                        t.ray_intersects_ground);
          if (column >= glsl::SHADOW_EDGE_PAST_COLUMNS) {
            EXPECT_GT(sun, split_sun - 1e-12);
            EXPECT_LE(sun, edge - glsl::SHADOW_EDGE_CLOSEST + 1e-9);
          } else {
            EXPECT_GE(sun, edge - 1e-9);
          }
          ++texels;
        }
      }
    }
  }
  std::printf("%d own texels: largest difference of the bake's suns %.3g rad, of the lookup's position %.3g columns\n",
              texels, worst_sun, worst_position);
  EXPECT_LT(worst_sun, 1e-7);
  EXPECT_LT(worst_position, 1e-6);
}

// The single-scattering targets (RMS 2 / 5 / 10 % at sun 80-90 /
// 90-96 / 96-100 degrees over all values, and never bright where the exact
// light is 0: below 1e-12, a thousandth of kVisible) on the default table
// read as the runtime reads it; off the whole degrees (every 0.1 degree
// from 80.037, and the suns 0.25, 0.5 and 0.75 degrees later); and in
// daylight (sun 10-80 degrees, every 2.5 from 10.25), where the tables'
// columns are the same for every ray, within 0.5 %.
TEST(TwilightSunAxis, SingleScatteringMeetsItsTargetsOnTheDefaultTable) {
  const LutSet& luts = testing::DefaultSizeEarthSingleScattering();
  std::vector<std::pair<std::string, std::vector<double>>> sun_sets = {{"whole degrees", kTwilightSuns},
                                                                       {"every 0.1 degree", {}}};
  for (int i = 0; i <= 200; ++i) sun_sets[1].second.push_back(80.037 + 0.1 * i);
  for (double offset : {0.25, 0.5, 0.75}) {
    sun_sets.push_back({"offset " + std::to_string(offset).substr(0, 4), {}});
    for (double sun : kTwilightSuns) sun_sets.back().second.push_back(sun + offset);
  }
  for (const auto& [name, suns] : sun_sets) {
    const std::vector<RangeErrors> errors = Errors(luts, Views(suns), TwilightRanges());
    std::printf("suns %s:\n", name.c_str());
    Print("tables", errors);
    for (int i = 0; i < 3; ++i) {
      EXPECT_LT(errors[i].Rms(), kTargets[i]) << errors[i].name << ", suns " << name;
      EXPECT_LT(errors[i].largest_where_dark, 1e-12) << errors[i].name << ", suns " << name;
    }
  }
  std::vector<double> daylight_suns;
  for (double sun = 10.25; sun < 80.0; sun += 2.5) daylight_suns.push_back(sun);
  const std::vector<RangeErrors> daylight = Errors(luts, Views(daylight_suns), {{"10-80", 10, 80}});
  Print("tables", daylight);
  EXPECT_LT(daylight[0].Rms(), 0.005);
}

// The same on other atmospheres: Mars (a planet half Earth's size, 80 km
// of thin air and dust with a forward lobe) and Earth under heavy haze, on
// the whole-degree suns, over the values at least kVisible: within the
// targets. Over all values both miss at 90-96 degrees, by values below
// 1e-11 (docs/accuracy.md, "Twilight: a sun axis measured from each ray's
// shadow edge").
TEST(TwilightSunAxis, SingleScatteringOnOtherAtmospheres) {
  for (const char* preset : {"mars", "heavy-haze"}) {
    BakeSettings settings;
    settings.orders = 1;
    settings.extrapolate_tail = false;
    const LutSet luts = Bake(LoadAtmosphere(preset), settings);
    const std::vector<RangeErrors> errors = Errors(luts, Views(kTwilightSuns), TwilightRanges());
    std::printf("%s:\n", preset);
    Print("tables", errors);
    for (int i = 0; i < 3; ++i) {
      EXPECT_LT(errors[i].VisibleRms(), kTargets[i]) << preset << ", " << errors[i].name;
      EXPECT_LT(errors[i].largest_where_dark, 1e-12) << preset << ", " << errors[i].name;
    }
  }
}

}  // namespace
}  // namespace skybake
