// Single scattering against a brute-force nested quadrature that uses no
// table: adaptive Simpson along the view ray, with the optical depth to the
// camera and to the sun each integrated exactly at every sample. Multiple
// scattering: order-by-order decay and the size of orders 2..4.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "bake/bake.h"
#include "core/constants.h"
#include "quadrature.h"
#include "render/lut_plots.h"
#include "report/case_errors.h"
#include "report/run_time_models.h"
#include "shaders_runtime/runtime.h"
#include "shaders_runtime/twin.h"
#include "test_atmospheres.h"
#include "test_util.h"

namespace skybake {
namespace {

// Default transmittance table (the sun's optical depth is looked up in it)
// and the default mu resolution (so texel centres come close to the
// horizon); fewer r, mu_s and nu texels keep the test fast.
BakeSettings SingleScatteringSettings() {
  BakeSettings s;
  s.orders = 1;
  s.scattering_r_size = 16;
  s.scattering_mu_s_size = 16;
  s.scattering_nu_size = 4;
  return s;
}

const LutSet& EarthSingleScattering() {
  static const LutSet luts = Bake(testing::Earth(), SingleScatteringSettings());
  return luts;
}

struct SingleScattering {
  Spectrum rayleigh{0.0}, mie{0.0};  // phase free, times the solar irradiance
};
SingleScattering operator+(const SingleScattering& a, const SingleScattering& b) {
  return {a.rayleigh + b.rayleigh, a.mie + b.mie};
}
SingleScattering operator-(const SingleScattering& a, const SingleScattering& b) {
  return {a.rayleigh - b.rayleigh, a.mie - b.mie};
}
SingleScattering operator*(double k, const SingleScattering& a) { return {k * a.rayleigh, k * a.mie}; }
SingleScattering operator/(const SingleScattering& a, double k) { return {a.rayleigh / k, a.mie / k}; }
SingleScattering& operator+=(SingleScattering& a, const SingleScattering& b) { return a = a + b; }
double MaxAbs(const SingleScattering& a) { return std::max(testing::MaxAbs(a.rayleigh), testing::MaxAbs(a.mie)); }

SingleScattering BruteForceSingleScattering(const Atmosphere& a, const glsl::AtmosphereParameters& p,
                                            const ScatteringTexel& t) {
  double d = glsl::DistanceToNearestAtmosphereBoundary(p, t.r, t.mu, t.ray_intersects_ground);
  const Constituent& rayleigh = a.constituents[0];
  const Constituent& mie = a.constituents[1];
  auto integrand = [&](double s) {
    double r_s = std::sqrt(s * s + 2.0 * t.r * t.mu * s + t.r * t.r);
    double mu_s_s = std::clamp((t.r * t.mu_s + s * t.nu) / r_s, -1.0, 1.0);
    double visible = glsl::SunVisibleFraction(p, std::max(r_s, p.bottom_radius), mu_s_s);
    if (visible <= 0.0) return SingleScattering{};
    // 1e-6 relative optical depth: far below the 0.5% being tested.
    Spectrum to_camera = testing::ExactOpticalDepth(a, t.r, t.mu, s, 1e-6);
    // While the sun's disc straddles the horizon the model attenuates its
    // visible part along the grazing ray (Bruneton 2017): clamp the sun
    // direction to the horizon rather than integrate through the planet.
    double mu_horizon = -std::sqrt(std::max(0.0, 1.0 - (p.bottom_radius / r_s) * (p.bottom_radius / r_s)));
    double mu_sun = std::max(mu_s_s, mu_horizon);
    Spectrum to_sun =
        testing::ExactOpticalDepth(a, r_s, mu_sun, glsl::DistanceToTopAtmosphereBoundary(p, r_s, mu_sun), 1e-6);
    Spectrum attenuation = glm::exp(-(to_camera + to_sun)) * visible;
    double h = r_s - a.bottom_radius_m;
    return SingleScattering{rayleigh.scattering_per_m * rayleigh.density.At(h) * attenuation,
                            mie.scattering_per_m * mie.density.At(h) * attenuation};
  };
  // Enough initial pieces that the lit stretch of a twilight ray (the sun
  // hidden by the planet elsewhere) is never stepped over.
  SingleScattering rough = testing::Integrate<SingleScattering>(integrand, 0.0, d, 1e300, 256);
  SingleScattering value = testing::Integrate<SingleScattering>(integrand, 0.0, d, 1e-4 * MaxAbs(rough), 256);
  return {value.rayleigh * a.solar_irradiance, value.mie * a.solar_irradiance};
}

TEST(SingleScattering, MatchesBruteForceQuadratureWithinHalfPercent) {
  const LutSet& luts = EarthSingleScattering();
  const glsl::AtmosphereParameters& p = luts.parameters;
  const int width = p.scattering_nu_size * p.scattering_mu_s_size;
  std::mt19937 rng(11);
  std::vector<std::array<int, 3>> texels;
  std::uniform_int_distribution<int> x_dist(0, width - 1), y_dist(0, p.scattering_mu_size - 1),
      z_dist(1, p.scattering_r_size - 1);  // z = 0 lies on the ground: half its rays have length 0
  while (texels.size() < 240) texels.push_back({x_dist(rng), y_dist(rng), z_dist(rng)});
  // Texels within 0.1 degree of the horizon (both halves of the mu axis).
  int near_horizon = 0;
  for (int z = 1; z < p.scattering_r_size && near_horizon < 40; z += 2) {
    for (int y : {0, 1, p.scattering_mu_size - 2, p.scattering_mu_size - 1}) {
      ScatteringTexel t = GetScatteringTexel(p, 0, y, z);
      double horizon = -std::sqrt(1.0 - (p.bottom_radius / t.r) * (p.bottom_radius / t.r));
      if (std::abs(std::acos(t.mu) - std::acos(horizon)) < 0.1 * kPi / 180.0) {
        texels.push_back({x_dist(rng), y, z});
        ++near_horizon;
      }
    }
  }
  ASSERT_GE(near_horizon, 10);

  // Daylight texels (sun above the horizon) must match within 0.5%. In
  // twilight the lit part of the ray is reached by sunlight grazing the
  // ground, whose optical depth comes from the transmittance table near its
  // horizon; there the bake is bounded at 1.5% and the worst case printed.
  // Below the split the columns crowd toward each ray's shadow edge, where
  // all of its lit stretch sees the sun at the table's horizon: within a
  // degree of the edge, 2.5%.
  double worst_day = 0.0, worst_twilight = 0.0, worst_near_edge = 0.0;
  int compared = 0;
  for (const auto& [x, y, z] : texels) {
    ScatteringTexel t = GetScatteringTexel(p, x, y, z);
    SingleScattering expected = BruteForceSingleScattering(luts.atmosphere, p, t);
    // A slice past the range of nu that (mu, mu_s) allow holds what the
    // lookup's blend extends to (Baker::ExtendSlicesPastTheirRange): there
    // the lookup at the texel's own, clamped nu is the light it stands for.
    const bool extended = t.nu != t.grid_nu;
    auto value = [&](const glsl::Texture& table) {
      return extended ? glsl::GetScattering(p, glsl::sampler3D{&table}, t.r, t.mu, t.mu_s, t.nu, t.ray_intersects_ground)
                      : table.Fetch(x, y, z);
    };
    glsl::vec4 rayleigh = value(luts.scattering);
    glsl::vec4 mie = value(luts.single_mie_scattering);
    bool twilight = t.mu_s < 0.0;
    // Within a degree of the ray's shadow edge its lit stretch sees the sun
    // grazing the ground, through the transmittance table's horizon.
    const bool near_edge = glsl::ShadowEdgeSunZenith(p, t.r, t.mu, glsl::ViewSunAzimuthCosine(t.mu, t.mu_s, t.nu),
                                                     t.ray_intersects_ground) -
                               std::acos(t.mu_s) <
                           kPi / 180.0;
    for (int c = 0; c < 3; ++c) {
      // Values far below the table's scale (the sun hidden for all but a
      // sliver of the ray) are not meaningful relative comparisons.
      for (auto [got, want] : {std::pair{rayleigh[c], expected.rayleigh[c]}, std::pair{mie[c], expected.mie[c]}}) {
        if (want < 1e-6) continue;
        double error = std::abs(got - want) / want;
        double& worst = near_edge ? worst_near_edge : twilight ? worst_twilight : worst_day;
        worst = std::max(worst, error);
        EXPECT_LE(error, near_edge  ? 2.5e-2
                         : twilight ? 1.5e-2
                                    : 5e-3)
            << "texel " << x << "," << y << "," << z << " r " << t.r << " mu " << t.mu << " mu_s " << t.mu_s << " nu "
            << t.nu << " channel " << c;
        ++compared;
      }
    }
  }
  std::printf(
      "single scattering vs brute force: %d values (%d texels near the horizon): max relative error "
      "%.3g with the sun up, %.3g in twilight, %.3g within a degree of the ray's shadow edge\n",
      compared, near_horizon, worst_day, worst_twilight, worst_near_edge);
  EXPECT_GE(compared, 600);  // 6 values per texel, less those below the table's scale
}

// The runtime's blend along mu_s for a low sun (LogMonotoneCubicMix): the
// end columns at t = 0 and 1; exact where ln L is linear (an exponential
// fall); above the geometric mean at mid-column where the fall steepens
// (ln L concave, as after sunset); never outside [b, c] and falling all the
// way where the next column is nearly dark (a cliff, where an unlimited
// cubic in ln L overshoots); the geometric blend where a column is dark.
TEST(Twilight, LowSunBlendAlongMuSIsAMonotoneCubicInLnL) {
  auto blend = [](double a, double b, double c, double d, double t) {
    return glsl::LogMonotoneCubicMix(glsl::vec4(a), glsl::vec4(b), glsl::vec4(c), glsl::vec4(d), true, true, t).x;
  };
  EXPECT_DOUBLE_EQ(blend(2.0, 1.0, 0.3, 0.01, 0.0), 1.0);
  EXPECT_NEAR(blend(2.0, 1.0, 0.3, 0.01, 1.0), 0.3, 1e-15);
  for (double t : {0.1, 0.5, 0.9}) {
    EXPECT_NEAR(blend(1.0, std::exp(-1.0), std::exp(-2.0), std::exp(-3.0), t), std::exp(-1.0 - t), 1e-14) << t;
  }
  EXPECT_GT(blend(1.0, std::exp(-1.0), std::exp(-3.0), std::exp(-6.0), 0.5), std::exp(-2.0));
  double previous = 0.5;
  for (int i = 1; i <= 20; ++i) {
    const double value = blend(1.0, 0.5, 0.25, 1e-20, i / 20.0);
    EXPECT_LE(value, previous) << i;
    EXPECT_GE(value, 0.25 * (1.0 - 1e-12)) << i;
    previous = value;
  }
  EXPECT_EQ(blend(1.0, 0.5, 0.0, 0.0, 0.5),
            glsl::SunCosineMix(glsl::vec4(0.5), glsl::vec4(0.0), 0.5, true).x);
}

// Below the lowest mu_s column (LowestSunLogFall): where both lowest
// columns are below the horizon, exact for ln L = A - k mu_s^2 (the light
// from above a shadow whose height grows as the square of the sun's
// depression); where the second is above it, the line through the two in
// ln L; held where L does not rise from the lowest column to the next, or
// the lowest is dark; per channel.
TEST(Twilight, BelowTheLowestSunLnLIsContinuedFromTheTwoLowestColumns) {
  auto continued = [](glsl::vec4 a, glsl::vec4 b, double mu_s_a, double mu_s_b, double mu_s) {
    return glsl::LowestSunContinued(glsl::LogLight(a), glsl::LogLight(b), mu_s_a, mu_s_b, mu_s);
  };
  auto shadowed = [](double mu_s) { return std::exp(-3.0 - 400.0 * mu_s * mu_s); };
  const double mu_s_a = -0.2079, mu_s_b = -0.1862;
  for (double mu_s : {-0.21, -0.25, -0.4}) {
    const glsl::vec4 value =
        continued(glsl::vec4(shadowed(mu_s_a)), glsl::vec4(shadowed(mu_s_b)), mu_s_a, mu_s_b, mu_s);
    EXPECT_NEAR(value.x / shadowed(mu_s), 1.0, 1e-9) << mu_s;
  }
  // The second column above the horizon: ln L linear through the two.
  const glsl::vec4 line = continued(glsl::vec4(1.0), glsl::vec4(std::exp(0.5)), -0.05, 0.05, -0.15);
  EXPECT_NEAR(line.x, std::exp(-0.5), 1e-12);
  // Not rising, or dark at the lowest column: held there. Channels apart.
  const glsl::vec4 held = continued(glsl::vec4(2.0, 0.0, shadowed(mu_s_a), 0.0),
                                    glsl::vec4(1.0, 1.0, shadowed(mu_s_b), 0.0), mu_s_a, mu_s_b, -0.3);
  EXPECT_DOUBLE_EQ(held.x, 2.0);
  EXPECT_EQ(held.y, 0.0);
  EXPECT_NEAR(held.z / shadowed(-0.3), 1.0, 1e-9);
}

// The horizon band at sunset (reference/cases/earth_horizon.csv; docs/
// accuracy.md, "The horizon band at sunset: single scattering"): the
// default table's single scattering, as the twin reads it, against the
// reference's over the values of at least 1e-9 W m^-2 sr^-1 nm^-1, held
// near what it measures now so that the band cannot get worse unnoticed:
// RMS 2.19 % at sun 85-90 degrees (bound 2.5 %), and at 91-96 a median of
// 1.66 % (bound 2 %) under a tail across the sun that the nu slices cannot
// follow (RMS 92.2 %, bound 120 %). The targets of 2 % and 5 % RMS are not
// met. Where the exact light is 0 the tables stay below 1e-12 (2.2e-15).
TEST(SingleScattering, HorizonBandHoldsItsMeasuredError) {
  const LutSet& luts = testing::DefaultSizeEarthSingleScattering();
  const Twin twin(MakeTwinTables(luts));
  const report::ReferenceSet reference = report::ParseReference(
      testing::ReadText(std::string(SKYBAKE_SOURCE_DIR) + "/reference/cases/earth_horizon_single_reference.csv"),
      "earth_horizon_single_reference.csv", luts.atmosphere);
  ASSERT_EQ(reference.cases.size(), 2484u);
  // Per range the samples at least 1e-9 (ComputeErrorStats measures them
  // against the reference), and their relative errors for the median.
  std::vector<report::ErrorSample> before_sunset, after_sunset;
  std::vector<double> after_sunset_errors;
  double brightest_where_dark = 0.0;
  for (const report::ReferenceCase& c : reference.cases) {
    const report::ModelAnswer answer = report::EvaluateTwin(twin, c);
    for (int k = 0; k < 3; ++k) {
      const double exact = c.radiance[k], baked = answer.radiance[k];
      if (exact == 0.0) {
        brightest_where_dark = std::max(brightest_where_dark, baked);
      } else if (exact >= 1e-9) {
        (c.query.sun_zenith_deg <= 90.0 ? before_sunset : after_sunset).push_back({baked, exact});
        if (c.query.sun_zenith_deg > 90.0) after_sunset_errors.push_back(std::abs(baked - exact) / exact);
      }
    }
  }
  const report::ErrorStats before = report::ComputeErrorStats(before_sunset);
  const report::ErrorStats after = report::ComputeErrorStats(after_sunset);
  std::nth_element(after_sunset_errors.begin(), after_sunset_errors.begin() + after_sunset_errors.size() / 2,
                   after_sunset_errors.end());
  const double after_median = after_sunset_errors[after_sunset_errors.size() / 2];
  std::printf("sun 85-90: %d values, RMS %.3g; 91-96: %d values, RMS %.3g, median %.3g; brightest where dark %.3g\n",
              before.count, before.rms_relative, after.count, after.rms_relative, after_median, brightest_where_dark);
  ASSERT_EQ(before.count, 3726);
  ASSERT_GT(after.count, 2800);
  EXPECT_LT(before.rms_relative, 0.025);
  EXPECT_LT(after_median, 0.02);
  EXPECT_LT(after.rms_relative, 1.2);
  EXPECT_LT(brightest_where_dark, 1e-12);
}

// Between mu_s texels, from low sun to deep twilight: the zenith view (where
// nu plays no part) at every fifth r row, the sun halfway in texture
// coordinate between each pair of mu_s columns below LOW_SUN_MU_S, looked up
// by the twin and integrated by brute force, at the default table sizes. The
// light falls by up to a hundredfold between two such columns; linear
// interpolation of the same two stored texels is measured alongside and must
// do worse. Values below 1e-9 W m^-2 sr^-1 nm^-1 (a third of the moonless
// night sky at 550 nm, about 2e-4 cd/m^2) are left out of the relative
// errors; where the exact value is 0 (the ray wholly in the Earth's shadow)
// the lookup must be below that too.
TEST(SingleScattering, LowSunLookupsBetweenTexelsFollowTheFall) {
  const LutSet& luts = testing::DefaultSizeEarthSingleScattering();
  const Twin twin(MakeTwinTables(luts));
  const glsl::AtmosphereParameters& p = luts.parameters;
  const int size = p.scattering_mu_s_size, zenith_row = p.scattering_mu_size / 2;
  const double x_low_sun = glsl::GetScatteringTextureUMuS(p, glsl::LOW_SUN_MU_S);
  const double visible = 1e-9;
  double lookup_sum = 0.0, linear_sum = 0.0, worst = 0.0;
  int compared = 0, dark = 0;
  for (int z = 0; z < p.scattering_r_size; z += 5) {
    for (int column = 0; (column + 0.5) / size < x_low_sun; ++column) {
      double r, mu, mu_s, nu;
      bool ground;
      glsl::GetRMuMuSNuFromScatteringTextureUvwz(
          p, glsl::vec4(0.0, (column + 1.0) / size, (zenith_row + 0.5) / p.scattering_mu_size,
                        (z + 0.5) / p.scattering_r_size),
          r, mu, mu_s, nu, ground);
      ASSERT_NEAR(mu, 1.0, 1e-9);
      ASSERT_FALSE(ground);
      const ScatteringTexel exact_texel{r, 1.0, mu_s, mu_s, mu_s, false};
      const Spectrum exact = BruteForceSingleScattering(luts.atmosphere, p, exact_texel).rayleigh;
      const glsl::vec4 looked_up = twin.Scattering(r, 1.0, mu_s, mu_s, false);
      const glsl::vec4 linear = 0.5 * (luts.scattering.Fetch(column, zenith_row, z) +
                                       luts.scattering.Fetch(column + 1, zenith_row, z));
      for (int c = 0; c < 3; ++c) {
        if (exact[c] == 0.0) {
          EXPECT_LT(looked_up[c], visible) << "r " << r << " mu_s " << mu_s;
          ++dark;
          continue;
        }
        if (exact[c] < visible) continue;
        const double error = (looked_up[c] - exact[c]) / exact[c];
        const double linear_error = (linear[c] - exact[c]) / exact[c];
        lookup_sum += error * error, linear_sum += linear_error * linear_error;
        worst = std::max(worst, std::abs(error));
        ++compared;
      }
    }
  }
  const double lookup_rms = std::sqrt(lookup_sum / compared), linear_rms = std::sqrt(linear_sum / compared);
  std::printf("zenith single scattering halfway between low-sun mu_s texels: %d values, RMS relative error "
              "%.3g (linear interpolation: %.3g), max %.3g; %d exactly dark\n",
              compared, lookup_rms, linear_rms, worst, dark);
  // (Below the split six of the ray's own columns lie at and past its
  // shadow edge, where it is dark.)
  EXPECT_GE(compared, 250);
  EXPECT_GE(dark, 10);
  EXPECT_LT(lookup_rms, 0.5 * linear_rms);
  // On columns at the same suns for every ray, next to a column where the
  // ray is (nearly) all in the Earth's shadow, the lookup fell too early, by
  // up to 100 % of a small value, and read 0.191 RMS; on the ray's own
  // columns, which follow its edge (shadow_edge.glsl, "The sun axis after
  // sunset"), 0.013.
  EXPECT_LT(lookup_rms, 0.03);
}

// The default bake of earth, all orders.
const LutSet& DefaultEarth() {
  static const LutSet luts = Bake(testing::Earth(), BakeSettings{});
  return luts;
}

// Below the table's lowest sun the lookups go on falling (the sky by
// LowestSunLogFall, the irradiance geometrically, each from its two lowest
// mu_s columns) instead of holding the lowest one, and never rise above it: sky
// and irradiance for the sun down to 10 degrees below the lowest sun.
TEST(Twilight, LookupsBelowTheLowestSunKeepFalling) {
  const LutSet& luts = DefaultEarth();
  const Twin twin(MakeTwinTables(luts));
  const glsl::AtmosphereParameters& p = luts.parameters;
  const double lowest = std::acos(p.scattering_mu_s_min);
  for (double altitude : {0.0, 10000.0, 59000.0}) {
    const double r = p.bottom_radius + altitude;
    for (double mu : {1.0, 0.2, -0.05}) {
      const bool ground = glsl::RayIntersectsGround(p, r, mu);
      glsl::vec4 previous = twin.Scattering(r, mu, p.scattering_mu_s_min, mu * p.scattering_mu_s_min, ground);
      glsl::vec3 previous_irradiance = twin.Irradiance(r, p.mu_s_min);
      for (int step = 1; step <= 20; ++step) {
        const double mu_s = std::cos(lowest + step * 0.5 * kPi / 180.0);
        const glsl::vec4 value = twin.Scattering(r, mu, mu_s, mu * mu_s, ground);
        const glsl::vec3 irradiance = twin.Irradiance(r, mu_s);
        for (int c = 0; c < 3; ++c) {
          EXPECT_LE(value[c], previous[c]) << "altitude " << altitude << " mu " << mu << " step " << step;
          EXPECT_LE(irradiance[c], previous_irradiance[c]) << "altitude " << altitude << " step " << step;
          EXPECT_GE(value[c], 0.0);
        }
        previous = value, previous_irradiance = irradiance;
      }
      const glsl::vec4 lowest_value = twin.Scattering(r, mu, p.scattering_mu_s_min, mu * p.scattering_mu_s_min, ground);
      if (lowest_value[0] > 0.0) {  // 0: a ray of length 0 (from the ground, down)
        EXPECT_LT(previous[0], lowest_value[0]) << "altitude " << altitude << " mu " << mu << ": no fall at all";
      }
    }
  }
}

// Through sunset and twilight the sky's luminance at the zenith and near
// the horizon, toward and away from the sun, falls at every 0.05 degree
// step of the sun, and falls smoothly: no step where a mu_s texel column or a scattering order takes over. A step
// or a kink shows as the fall of ln L over one 0.05 degree step changing
// abruptly at the next. Linear interpolation between the mu_s texels of
// the same tables changes it by up to 3.7 times (at the zenith 3.0, toward
// the sun 2.1), their geometric blend by up to 1.54, where the sun's disc
// sets; this lookup (a monotone cubic in ln L along mu_s) by at most 1.09.
// The bound, 1.3, sits between the last two.
TEST(Twilight, SkyLuminanceFallsSmoothlyThroughSunset) {
  const LutSet& luts = DefaultEarth();
  const Twin twin(MakeTwinTables(luts));
  const render::SunsetCurves curves = render::ComputeSunsetCurves(twin, false);
  ASSERT_EQ(curves.sun_zenith_deg.size(), 341u);  // 85 to 102 degrees
  const std::pair<const char*, const std::vector<double>*> views[] = {
      {"zenith", &curves.zenith}, {"sunward", &curves.sunward_horizon}, {"antisolar", &curves.antisolar_horizon}};
  for (const auto& [name, luminance] : views) {
    std::vector<double> fall;  // ln L(i) - ln L(i + 1) > 0
    for (std::size_t i = 0; i + 1 < luminance->size(); ++i) {
      ASSERT_GT((*luminance)[i + 1], 0.0) << name << " at sun " << curves.sun_zenith_deg[i + 1];
      ASSERT_LT((*luminance)[i + 1], (*luminance)[i]) << name << " at sun " << curves.sun_zenith_deg[i + 1];
      fall.push_back(std::log((*luminance)[i] / (*luminance)[i + 1]));
    }
    double worst = 1.0, worst_sun = 0.0;
    for (std::size_t i = 0; i + 1 < fall.size(); ++i) {
      const double change = std::max(fall[i] / fall[i + 1], fall[i + 1] / fall[i]);
      if (change > worst) worst = change, worst_sun = curves.sun_zenith_deg[i + 1];
    }
    std::printf("%s: luminance %.3g at sun 85 deg to %.3g at 102; largest change of the fall of ln L from "
                "one 0.05 degree step to the next: x%.3g (sun %.2f deg)\n",
                name, luminance->front(), luminance->back(), worst, worst_sun);
    EXPECT_LT(worst, 1.3) << name;
  }
}

// The default tables' errors per case group against a committed reference
// file in reference/cases (its cases with the sun at most `highest_sun_deg`
// from the zenith), through the CPU twin of the runtime.
// The errors of an Earth bake on a committed reference file's cases with
// the sun at most `highest_sun_deg` from the zenith, per group.
std::vector<report::GroupErrors> EarthErrors(const LutSet& luts, const std::string& file,
                                             double highest_sun_deg = 180.0) {
  const Twin twin(MakeTwinTables(luts));
  report::ReferenceSet reference = report::ParseReference(
      testing::ReadText(std::string(SKYBAKE_SOURCE_DIR) + "/reference/cases/" + file), file, luts.atmosphere);
  reference.cases.erase(std::remove_if(reference.cases.begin(), reference.cases.end(),
                                       [&](const report::ReferenceCase& c) {
                                         return c.query.sun_zenith_deg > highest_sun_deg;
                                       }),
                        reference.cases.end());
  return report::MeasureErrors(reference,
                               [&](const report::ReferenceCase& c) { return report::EvaluateTwin(twin, c); });
}

std::vector<report::GroupErrors> DefaultEarthErrors(const std::string& file, double highest_sun_deg = 180.0) {
  return EarthErrors(DefaultEarth(), file, highest_sun_deg);
}

// A whole table with too few mu_s texels for the split (the preview's 16),
// its orders on a grid of half its r and mu rows (--higher-order-divisor 2):
// the final gather of their summed J follows J's fall between the columns
// and below the lowest sun, as the orders' own gathers do. Gathered
// linearly and held below the lowest sun it read the twilight sky at sun
// 101-102 degrees about 30 times too bright (3000 % RMS); now within a
// quarter of the RMS error of the same table with its orders on its own
// grid, per channel (measured: at most 1.11 times).
TEST(HigherOrderDivisor, AWholeTableWithoutASplitKeepsTheDeepTwilight) {
  BakeSettings own_grid = PreviewBakeSettings();
  ASSERT_EQ(own_grid.higher_order_divisor, 1);
  BakeSettings coarse = own_grid;
  coarse.higher_order_divisor = 2;
  const std::vector<report::GroupErrors> fine_errors =
      EarthErrors(Bake(testing::Earth(), own_grid), "earth_twilight_reference.csv");
  const std::vector<report::GroupErrors> coarse_errors =
      EarthErrors(Bake(testing::Earth(), coarse), "earth_twilight_reference.csv");
  for (const char* group : {"twilight_sky_sun_97-100", "twilight_sky_sun_101-102"}) {
    for (int c = 0; c < 3; ++c) {
      const double fine = report::FindGroup(fine_errors, group).channel[c].rms_relative;
      const double with_divisor = report::FindGroup(coarse_errors, group).channel[c].rms_relative;
      std::cout << group << " channel " << c << ": RMS " << with_divisor << " with the divisor, " << fine
                << " without\n";
      EXPECT_LE(with_divisor, 1.25 * fine) << group << " channel " << c;
    }
  }
}

// Earth baked with two orders and no tail, the scattering table's nu
// slices and the sphere rule's polar nodes as given (0: the defaults).
LutSet SecondOrderEarth(int nu_size, int sphere_samples) {
  BakeSettings s;
  s.orders = 2;
  s.extrapolate_tail = false;
  if (nu_size > 0) s.scattering_nu_size = nu_size;
  if (sphere_samples > 0) s.sphere_samples = sphere_samples;
  return Bake(testing::Earth(), s);
}

const LutSet& DefaultSecondOrderEarth() {
  static const LutSet luts = SecondOrderEarth(0, 0);
  return luts;
}

// The second order seen from 100 km through the limb away from the sun
// (azimuth 180 degrees, and 140) at sun 98-100.8 degrees, where the view
// ray runs to where the sun is 15 degrees lower, with the default tables
// and with `other`, each channel's relative difference printed and held
// within `bound`.
void ExpectSecondOrderDeepInTheShadowClose(const LutSet& other, const char* what, double bound) {
  const Twin default_twin(MakeTwinTables(DefaultSecondOrderEarth())), other_twin(MakeTwinTables(other));
  struct View {
    double view_zenith, sun_zenith, azimuth;
  };
  for (const View& v : {View{99.0, 98.0, 180.0}, View{99.0, 100.0, 180.0}, View{102.0, 98.0, 180.0},
                        View{102.0, 100.0, 180.0}, View{99.0, 100.79, 140.0}}) {
    report::ReferenceCase c;
    c.query.altitude_m = 100000.0, c.query.view_zenith_deg = v.view_zenith;
    c.query.sun_zenith_deg = v.sun_zenith, c.query.view_sun_azimuth_deg = v.azimuth;
    const glm::dvec3 value = report::EvaluateTwin(default_twin, c).radiance;
    const glm::dvec3 other_value = report::EvaluateTwin(other_twin, c).radiance;
    for (int channel = 0; channel < 3; ++channel) {
      ASSERT_GT(other_value[channel], 0.0);
      const double difference = value[channel] / other_value[channel] - 1.0;
      std::printf("view %g, sun %g, azimuth %g, channel %d: default %+.2f %% from %s\n", v.view_zenith,
                  v.sun_zenith, v.azimuth, channel, 100.0 * difference, what);
      EXPECT_LT(std::abs(difference), bound)
          << "view " << v.view_zenith << " sun " << v.sun_zenith << " azimuth " << v.azimuth << " channel " << channel;
    }
  }
}

// Deep in the Earth's shadow a point's light comes from within a few
// degrees above its horizon toward the sun, where it peaks steeply; the
// scattering density's sphere rule resolves that band with its own nodes
// (AppendSkyRule in bake/scattering_density.cpp). The default rule against
// four times its polar and azimuthal nodes: with a quarter of the polar
// nodes in the band the default read 440 nm up to 16 % high there, with
// half of them within 0.8 % (docs/accuracy.md, "Twilight: the horizon band
// of the sphere's rule"). Bound: 3 %.
TEST(Twilight, SecondOrderDeepInTheShadowConvergedInTheSphereRule) {
  ExpectSecondOrderDeepInTheShadowClose(SecondOrderEarth(0, 4 * BakeSettings{}.sphere_samples),
                                        "four times the sphere rule's nodes", 0.03);
}

// The same light peaks sharply toward the sun's azimuth, where the
// single-scattering table's 8 nu slices are 40 degrees of azimuth apart:
// read from the table, the second order there was up to 15 % higher than
// with 16 slices; with the single scattering integrated along the
// density's rings toward the sun (Baker::SingleScatteringOnRings) the two
// agree within 1.5 % (docs/accuracy.md, "Twilight: the second order's
// light integrated along its rings"). Bound: 2 %.
TEST(Twilight, SecondOrderDeepInTheShadowIndependentOfTheNuSlices) {
  ExpectSecondOrderDeepInTheShadowClose(SecondOrderEarth(2 * BakeSettings{}.scattering_nu_size, 0),
                                        "twice the nu slices", 0.02);
}

// The default tables after sunset against the twilight case sets'
// references (reference/cases/earth_twilight_reference.csv, whole degrees,
// standard errors up to 1 % to sun 100 degrees, 3 % at 101-102; and
// earth_twilight_between_reference.csv, the sun between whole degrees, up to
// 0.5 %): the RMS relative error over the cases and the three channels per
// group. Gathering the second order linearly along mu_s (holding the lowest
// column below the grid's lowest sun) read 18.3 % at sun 91-96 degrees and
// 436 % at 97-100; following its fall, 10.5 % and 94 %, 615 % at 101-102;
// with every order's J continued below the lowest sun per channel by
// LowestSunLogFall, and the lookups below it the same way, 6.7 %, 7.8 % and
// 28 %, and between whole degrees 1.61 %, 3.08 % and 6.98 % at sun 90-93,
// 94-96 and 97-99; with 14.7 instead of 11.1 of the 31 mu_s intervals below
// the horizon (SCATTERING_MU_S_HIGH_SUN_SHARE 1/2 instead of 1), 2.15 %,
// 6.88 % and 22.6 %, and 1.08 %, 2.29 % and 1.99 %; with J and the sky
// below the lowest sun continued by the Earth's shadow's parabola from two
// columns instead of a parabola through three, 2.14 %, 5.51 % and 12.6 %;
// with half instead of a quarter of the scattering density's polar nodes
// in its horizon band, 2.05 %, 4.27 % and 9.62 %, and 1.08 %, 2.26 % and
// 2.22 %; with the second order's single scattering integrated along the
// density's rings toward a low sun, 2.00 %, 2.19 % and 4.77 %, and 1.09 %,
// 2.29 % and 0.89 % (docs/accuracy.md). The bounds sit between the last
// two for the groups that changed, else between the two before; the aim is
// 5 %.
TEST(Twilight, SkyAfterSunsetAgainstTheReference) {
  struct Bound {
    const char* file;
    const char* group;
    double rms;
  };
  for (const Bound& bound : {Bound{"earth_twilight_reference.csv", "twilight_sky_sun_91-96", 0.05},
                             Bound{"earth_twilight_reference.csv", "twilight_sky_sun_97-100", 0.03},
                             Bound{"earth_twilight_reference.csv", "twilight_sky_sun_101-102", 0.07},
                             Bound{"earth_twilight_between_reference.csv", "twilight_between_sun_90-93", 0.013},
                             Bound{"earth_twilight_between_reference.csv", "twilight_between_sun_94-96", 0.027},
                             Bound{"earth_twilight_between_reference.csv", "twilight_between_sun_97-99", 0.015}}) {
    const report::GroupErrors& e = report::FindGroup(DefaultEarthErrors(bound.file), bound.group);
    double squares = 0.0;
    int count = 0;
    for (const report::ErrorStats& channel : e.channel) {
      squares += channel.count * channel.rms_relative * channel.rms_relative;
      count += channel.count;
    }
    const double rms = std::sqrt(squares / count);
    std::printf("%s: RMS relative error %.3g over %d values\n", bound.group, rms, count);
    EXPECT_LT(rms, bound.rms) << bound.group;
  }
}

// The twilight case set's sky after sunset (reference/cases/
// earth_twilight_reference.csv, groups sun 88-90, 91-96 and 97-100
// degrees) against the targets of the twilight work: luminance RMS 3 % and
// max 10 %, every channel RMS 5 %. Before the scattering density's horizon
// band had half of its polar nodes, 440 nm read 5.08 % RMS there; after,
// luminance 2.39 % / 15.9 %, channels 2.60 / 2.63 / 3.02 %, the max at the
// camera at 100 km looking through the limb away from the sun at sun 100
// degrees; with the second order's single scattering integrated along the
// density's rings toward a low sun, luminance 1.23 % / 6.04 %, channels
// 2.50 / 1.42 / 1.37 % (docs/accuracy.md).
TEST(Twilight, TwilightSetWithinItsTargets) {
  const std::vector<report::GroupErrors> errors = DefaultEarthErrors("earth_twilight_reference.csv", 100.0);
  report::ErrorStats luminance;
  report::ErrorStats channels[3];
  // Pooled over the groups: counts add, squares of the RMS weighted by count.
  auto pool = [](report::ErrorStats& total, const report::ErrorStats& group) {
    const int count = total.count + group.count;
    if (count == 0) return;
    total.rms_relative = std::sqrt((total.count * total.rms_relative * total.rms_relative +
                                    group.count * group.rms_relative * group.rms_relative) /
                                   count);
    total.max_relative = std::max(total.max_relative, group.max_relative);
    total.count = count;
  };
  for (const char* group : {"twilight_sky_sun_88-90", "twilight_sky_sun_91-96", "twilight_sky_sun_97-100"}) {
    const report::GroupErrors& e = report::FindGroup(errors, group);
    pool(luminance, e.luminance);
    for (int c = 0; c < 3; ++c) pool(channels[c], e.channel[c]);
  }
  std::printf("twilight set, sky to sun 100 deg: luminance RMS %.3g max %.3g over %d cases; channels RMS %.3g %.3g "
              "%.3g\n",
              luminance.rms_relative, luminance.max_relative, luminance.count, channels[0].rms_relative,
              channels[1].rms_relative, channels[2].rms_relative);
  EXPECT_GT(luminance.count, 150);
  EXPECT_LT(luminance.rms_relative, 0.03);
  EXPECT_LT(luminance.max_relative, 0.10);
  for (const report::ErrorStats& channel : channels) EXPECT_LT(channel.rms_relative, 0.05);
}

// The report's twilight group (reference/cases/earth_reference.csv, sun 84
// to 100 degrees, standard errors up to 1.2 %) against the targets of the
// twilight work: luminance RMS 3 % and max 10 %, every channel RMS 5 %.
// Before the nu slices past their range were extended (Baker::
// ExtendSlicesPastTheirRange) it read 3.85 % / 17.5 %, channels 4.07 /
// 4.01 / 4.28 %; after, 1.67 % / 3.49 %, channels 2.21 / 1.79 / 2.90 %;
// with the monotone cubic along mu_s, 1.4 % / 4.3 %, channels 1.28 /
// 1.70 / 2.97 %.
TEST(Twilight, ReportGroupWithinItsTargets) {
  const std::vector<report::GroupErrors> errors = DefaultEarthErrors("earth_reference.csv");
  const report::GroupErrors& twilight = report::FindGroup(errors, "twilight");
  std::printf("twilight: luminance RMS %.3g max %.3g; channels RMS %.3g %.3g %.3g\n",
              twilight.luminance.rms_relative, twilight.luminance.max_relative, twilight.channel[0].rms_relative,
              twilight.channel[1].rms_relative, twilight.channel[2].rms_relative);
  EXPECT_GT(twilight.luminance.count, 20);
  EXPECT_LT(twilight.luminance.rms_relative, 0.03);
  EXPECT_LT(twilight.luminance.max_relative, 0.10);
  for (const report::ErrorStats& channel : twilight.channel) EXPECT_LT(channel.rms_relative, 0.05);
}

// The sky irradiance against the twilight targets, luminance RMS 2 % and
// max 5 % to sun 96 degrees, in the report's cases (reference/cases/
// earth_reference.csv, sun 0 to 95 degrees) and in the twilight set's (sun
// 88 to 96, ground and 10 km), each channel held to the same max. Integrated
// from the scattering table between its mu_s columns, the irradiance read
// 1.76 % / 5.31 % in the report's cases (7.2 % at 440 nm) and 3.38 % /
// 7.56 % in the twilight set's; integrated at the columns and read between
// them by a monotone cubic in ln E, 0.75 % / 2.00 % and 1.08 % / 1.79 %
// (docs/accuracy.md).
TEST(Twilight, SkyIrradianceWithinItsTargets) {
  for (const char* file : {"earth_reference.csv", "earth_twilight_reference.csv"}) {
    const report::GroupErrors& e = report::FindGroup(DefaultEarthErrors(file, 96.0), "sky_irradiance");
    std::printf("%s, sky irradiance to sun 96 deg: luminance RMS %.3g max %.3g; channels max %.3g %.3g %.3g\n", file,
                e.luminance.rms_relative, e.luminance.max_relative, e.channel[0].max_relative,
                e.channel[1].max_relative, e.channel[2].max_relative);
    EXPECT_GE(e.luminance.count, 16) << file;
    EXPECT_LT(e.luminance.rms_relative, 0.02) << file;
    EXPECT_LT(e.luminance.max_relative, 0.05) << file;
    for (const report::ErrorStats& channel : e.channel) EXPECT_LT(channel.max_relative, 0.05) << file;
  }
}

// Looking down from a low camera, the sun overhead: the ray gathers light
// about in proportion to its length, between r rows that sit at 0, 63, 250
// and 563 m. Every such lookup of the default tables within 1 % of the
// brute-force quadrature, cameras from 10 m to 1 km, views from 95 to 179
// degrees (a position between the rows linear in rho instead read a camera
// at 10 m 150 % high looking straight down).
TEST(SingleScattering, DownwardViewsFromLowCamerasWithinOnePercent) {
  const LutSet& luts = testing::DefaultSizeEarthSingleScattering();
  const Twin twin(MakeTwinTables(luts));
  const glsl::AtmosphereParameters& p = luts.parameters;
  double worst = 0.0;
  for (double altitude : {10.0, 30.0, 100.0, 300.0, 1000.0}) {
    for (double view_zenith : {95.0, 100.0, 120.0, 150.0, 179.0}) {
      const double r = p.bottom_radius + altitude, mu = std::cos(view_zenith * kPi / 180.0);
      ASSERT_TRUE(glsl::RayIntersectsGround(p, r, mu));
      const ScatteringTexel texel{r, mu, 1.0, mu, mu, true};
      const Spectrum exact = BruteForceSingleScattering(luts.atmosphere, p, texel).rayleigh;
      const glsl::vec4 looked_up = twin.Scattering(r, mu, 1.0, mu, true);
      for (int c = 0; c < 3; ++c) {
        const double error = std::abs(looked_up[c] - exact[c]) / exact[c];
        worst = std::max(worst, error);
        EXPECT_LT(error, 0.01) << "altitude " << altitude << " m, view zenith " << view_zenith << ", channel " << c;
      }
    }
  }
  std::printf("single scattering looking down from 10 m to 1 km: largest relative error %.3g\n", worst);
}

}  // namespace
}  // namespace skybake

namespace skybake {
namespace {

// Small tables keep four bakes fast; the decay of orders does not depend on
// the resolution.
BakeSettings SmallSettings(int orders) {
  BakeSettings s;
  s.orders = orders;
  s.extrapolate_tail = false;  // each order on its own
  s.transmittance_width = 128, s.transmittance_height = 32;
  s.scattering_r_size = 8, s.scattering_mu_size = 32, s.scattering_mu_s_size = 8, s.scattering_nu_size = 4;
  s.irradiance_width = 32, s.irradiance_height = 8;
  s.ray_samples = 32;
  s.sphere_samples = 8;
  return s;
}

TEST(MultipleScattering, EachOrderSmallerThanThePreviousForEarth) {
  // Order k's contribution = table(k orders) - table(k - 1 orders), summed
  // over the daylight texels (sun above the horizon) per channel.
  std::vector<LutSet> bakes;
  for (int orders = 1; orders <= 4; ++orders) bakes.push_back(Bake(testing::Earth(), SmallSettings(orders)));
  const glsl::AtmosphereParameters& p = bakes[0].parameters;
  std::vector<Spectrum> order_sum(5, Spectrum(0.0));
  for (int z = 0; z < p.scattering_r_size; ++z) {
    for (int y = 0; y < p.scattering_mu_size; ++y) {
      for (int x = 0; x < bakes[0].scattering.width; ++x) {
        if (GetScatteringTexel(p, x, y, z).mu_s < 0.0) continue;
        for (int k = 1; k <= 4; ++k) {
          glsl::vec4 now = bakes[k - 1].scattering.Fetch(x, y, z);
          glsl::vec4 before = k > 1 ? bakes[k - 2].scattering.Fetch(x, y, z) : glsl::vec4(0.0);
          order_sum[k] += Spectrum(now - before);
          if (k == 1) order_sum[1] += Spectrum(bakes[0].single_mie_scattering.Fetch(x, y, z));
        }
      }
    }
  }
  for (int c = 0; c < 3; ++c) {
    for (int k = 2; k <= 4; ++k) {
      EXPECT_GT(order_sum[k][c], 0.0) << "order " << k << " channel " << c;
      EXPECT_LT(order_sum[k][c], order_sum[k - 1][c]) << "order " << k << " channel " << c;
    }
    double fraction = (order_sum[2][c] + order_sum[3][c] + order_sum[4][c]) / order_sum[1][c];
    std::printf("channel %d: orders 2..4 / single = %.3f (order ratios %.3f %.3f)\n", c, fraction,
                order_sum[3][c] / order_sum[2][c], order_sum[4][c] / order_sum[3][c]);
    // Earth's clear sky: multiple scattering adds a few tens of percent to
    // single scattering (more in blue, which scatters more), never more than it.
    EXPECT_GT(fraction, 0.05);
    EXPECT_LT(fraction, 1.0);
  }
}

TEST(Twin, LookupAtTexelCentresReturnsStoredValues) {
  LutSet luts = Bake(testing::Earth(), SmallSettings(2));
  Twin twin(MakeTwinTables(luts));
  const glsl::AtmosphereParameters& p = luts.parameters;
  std::mt19937 rng(5);
  int checked = 0;
  for (int i = 0; i < 2000; ++i) {
    int x = rng() % luts.scattering.width, y = rng() % p.scattering_mu_size, z = rng() % p.scattering_r_size;
    ScatteringTexel t = GetScatteringTexel(p, x, y, z);
    bool degenerate = t.ray_intersects_ground && t.r == p.bottom_radius;  // ground slice: see parameterization_test
    bool tangent = y == 0 || y == p.scattering_mu_size - 1;
    if (degenerate || tangent) continue;
    glsl::vec4 stored = luts.scattering.Fetch(x, y, z);
    glsl::vec4 looked_up = twin.Scattering(t.r, t.mu, t.mu_s, t.grid_nu, t.ray_intersects_ground);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(looked_up[c], stored[c], 1e-5 * std::abs(stored[c]) + 1e-12);
    ++checked;
  }
  EXPECT_GT(checked, 1500);
  for (int y = 0; y < p.transmittance_height; ++y) {
    for (int x = 0; x < p.transmittance_width; ++x) {
      double r, mu;
      glsl::GetRMuFromTransmittanceTextureUv(
          p, glsl::vec2((x + 0.5) / p.transmittance_width, (y + 0.5) / p.transmittance_height), r, mu);
      glsl::vec3 stored(luts.transmittance.Fetch(x, y));
      glsl::vec3 looked_up = twin.OpticalDepthToTop(r, mu);
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(looked_up[c], stored[c], 1e-6 * stored[c] + 1e-9);
    }
  }
  for (int y = 0; y < p.irradiance_height; ++y) {
    for (int x = 0; x < p.irradiance_width; ++x) {
      double r, mu_s;
      glsl::GetRMuSFromIrradianceTextureUv(
          p, glsl::vec2((x + 0.5) / p.irradiance_width, (y + 0.5) / p.irradiance_height), r, mu_s);
      glsl::vec3 stored(luts.irradiance.Fetch(x, y));
      glsl::vec3 looked_up = twin.Irradiance(r, mu_s);
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(looked_up[c], stored[c], 1e-6 * stored[c] + 1e-12);
    }
  }
}

TEST(Bake, TablesFiniteAndNonNegative) {
  LutSet luts = Bake(testing::Earth(), SmallSettings(4));
  for (const glsl::Texture* t : {&luts.transmittance, &luts.irradiance, &luts.scattering, &luts.single_mie_scattering}) {
    for (float v : t->texels) {
      ASSERT_TRUE(std::isfinite(v));
      ASSERT_GE(v, 0.0f);
    }
  }
}

TEST(Bake, SameResultWithOneOrTwoThreads) {
  BakeSettings one = SmallSettings(3), two = SmallSettings(3);
  one.threads = 1, two.threads = 2;
  LutSet a = Bake(testing::Earth(), one), b = Bake(testing::Earth(), two);
  EXPECT_EQ(a.scattering.texels, b.scattering.texels);
  EXPECT_EQ(a.single_mie_scattering.texels, b.single_mie_scattering.texels);
  EXPECT_EQ(a.irradiance.texels, b.irradiance.texels);
  EXPECT_EQ(a.transmittance.texels, b.transmittance.texels);
}

}  // namespace
}  // namespace skybake

namespace skybake {
namespace {

TEST(Bake, PackingSingleMieIntoAlphaKeepsItsRedChannel) {
  BakeSettings separate = SmallSettings(2), packed = SmallSettings(2);
  packed.pack_single_mie_in_alpha = true;
  LutSet a = Bake(testing::Earth(), separate), b = Bake(testing::Earth(), packed);
  EXPECT_TRUE(b.single_mie_scattering.empty());
  EXPECT_EQ(b.parameters.single_mie_in_scattering_alpha, 1);
  Twin twin_separate(MakeTwinTables(a)), twin_packed(MakeTwinTables(b));
  const glsl::AtmosphereParameters& p = a.parameters;
  int compared = 0;
  for (int z = 1; z < p.scattering_r_size; ++z) {
    for (int y = 0; y < p.scattering_mu_size; ++y) {
      for (int x = 0; x < a.scattering.width; ++x) {
        glsl::vec4 rgba = b.scattering.Fetch(x, y, z);
        EXPECT_EQ(rgba.a, a.single_mie_scattering.Fetch(x, y, z).r);
        EXPECT_EQ(glsl::vec3(rgba), glsl::vec3(a.scattering.Fetch(x, y, z)));
      }
    }
  }
  // Through the runtime: the red channel of the sky is unchanged; the others
  // use Bruneton's colour reconstruction, an approximation (bounded loosely).
  for (double sun_zenith : {0.3, 1.0, 1.4}) {
    for (double view_zenith : {0.0, 0.8, 1.5}) {
      glsl::vec3 camera(0.0, 0.0, p.bottom_radius + 100.0);
      glsl::vec3 view(std::sin(view_zenith), 0.0, std::cos(view_zenith));
      glsl::vec3 sun(std::sin(sun_zenith), 0.0, std::cos(sun_zenith));
      glsl::vec3 s = twin_separate.SkyRadiance(camera, view, sun, nullptr);
      glsl::vec3 k = twin_packed.SkyRadiance(camera, view, sun, nullptr);
      EXPECT_NEAR(k.r, s.r, 1e-6 * s.r);
      for (int c = 1; c < 3; ++c) EXPECT_NEAR(k[c], s[c], 0.5 * s[c]);
      ++compared;
    }
  }
  EXPECT_EQ(compared, 9);
}

}  // namespace
}  // namespace skybake
