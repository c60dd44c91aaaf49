// `skybake report`: its error statistics and Pareto front on inputs worked
// out by hand, the bake's order snapshots, the quality ladder's settings, the
// single-scattering ray march against an exact integral, and the command
// end to end on a tiny ladder.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include <OpenImageIO/imageio.h>
#include <nlohmann/json.hpp>

#include "bake/bake.h"
#include "core/errors.h"
#include "report/case_errors.h"
#include "report/colour_errors.h"
#include "report/error_stats.h"
#include "report/quality_ladder.h"
#include "report/ray_march.h"
#include "shaders_runtime/primitives.h"
#include "test_atmospheres.h"
#include "test_util.h"

namespace skybake {
namespace {

using report::ErrorSample;
using report::ErrorStats;

TEST(ReportErrorStats, RmsMaxAndNoiseMatchHandComputedValues) {
  std::vector<ErrorSample> samples = {
      {1.1, 1.0, 0.01},   // 10% off; noise bound 2% -> measured
      {0.95, 1.0, 0.05},  // 5% off, inside 2 x 0.05 -> below noise
      {2.0, 2.0, 0.0},    // exact reference, exact answer: 0%, not "below noise"
      {0.3, 0.0, 0.0},    // no reference light (sun below the horizon): skipped
      {1.0, NAN, 0.0},    // not finite: skipped
  };
  ErrorStats s = report::ComputeErrorStats(samples);
  EXPECT_EQ(s.count, 3);
  EXPECT_EQ(s.skipped, 2);
  EXPECT_EQ(s.below_noise, 1);
  // sqrt((0.1^2 + 0.05^2 + 0) / 3) and sqrt((0.02^2 + 0.1^2 + 0) / 3).
  EXPECT_NEAR(s.rms_relative, std::sqrt(0.0125 / 3.0), 1e-15);
  EXPECT_NEAR(s.max_relative, 0.1, 1e-15);
  EXPECT_NEAR(s.rms_noise, std::sqrt(0.0104 / 3.0), 1e-15);
  EXPECT_FALSE(s.RmsBelowNoise());  // 6.45% > 5.89%
  EXPECT_FALSE(s.MaxBelowNoise());
  EXPECT_EQ(report::FormatRms(s), "6.45%");
  EXPECT_EQ(report::FormatMax(s), "10.00%");
}

TEST(ReportErrorStats, ErrorsInsideTheReferenceNoiseAreReportedAsSuch) {
  ErrorStats s = report::ComputeErrorStats({{1.01, 1.0, 0.01}, {0.99, 1.0, 0.01}});
  EXPECT_EQ(s.below_noise, 2);
  EXPECT_NEAR(s.rms_relative, 0.01, 1e-12);
  EXPECT_NEAR(s.rms_noise, 0.02, 1e-12);
  EXPECT_TRUE(s.RmsBelowNoise());
  EXPECT_TRUE(s.MaxBelowNoise());
  EXPECT_EQ(report::FormatRms(s), "below noise (< 2.00%)");
  EXPECT_EQ(report::FormatMax(s), "below noise");
  // Nothing measured is "n/a", never 0.
  ErrorStats none = report::ComputeErrorStats({{1.0, 0.0, 0.0}});
  EXPECT_EQ(none.count, 0);
  EXPECT_EQ(report::FormatRms(none), "n/a");
  EXPECT_EQ(report::FormatMax(none), "n/a");
  // A non-finite answer is an infinite error, not a skipped sample.
  ErrorStats broken = report::ComputeErrorStats({{NAN, 1.0, 0.0}});
  EXPECT_EQ(broken.count, 1);
  EXPECT_EQ(report::FormatMax(broken), "inf");
}

TEST(ReportErrorStats, LuminanceUsesRec709Weights) {
  EXPECT_NEAR(report::Luminance(glm::dvec3(1.0)), 1.0, 1e-15);
  EXPECT_NEAR(report::Luminance(glm::dvec3(0.0, 2.0, 0.0)), 1.4304, 1e-15);
  // Independent channels: sqrt(sum of (weight * error)^2).
  EXPECT_NEAR(report::LuminanceStandardError(glm::dvec3(1.0, 0.0, 0.0)), 0.2126, 1e-15);
  EXPECT_NEAR(report::LuminanceStandardError(glm::dvec3(1.0)),
              std::sqrt(0.2126 * 0.2126 + 0.7152 * 0.7152 + 0.0722 * 0.0722), 1e-15);
}

TEST(ReportParetoFront, KeepsExactlyThePointsNoOtherBeats) {
  // (cost, error): (1, 5) cheapest; (2, 3) twice (ties do not dominate each
  // other); (3, 4) beaten by (2, 3); (4, 1) most accurate; (0.5, NaN) not measured.
  std::vector<double> cost = {1, 2, 3, 4, 2, 0.5};
  std::vector<double> error = {5, 3, 4, 1, 3, NAN};
  std::vector<bool> front = report::ParetoFront(cost, error);
  EXPECT_EQ(front, (std::vector<bool>{true, true, false, true, true, false}));
  EXPECT_THROW(report::ParetoFront({1.0}, {}), InternalError);
}

TEST(ReportCaseErrors, GroupsIrradianceTwiceAndLeavesUnansweredGroupsOut) {
  const std::string text =
      "group,altitude_m,view_zenith_deg,sun_zenith_deg,view_sun_azimuth_deg,normal_zenith_deg,"
      "radiance_680nm,radiance_550nm,radiance_440nm,radiance_stderr_680nm,radiance_stderr_550nm,"
      "radiance_stderr_440nm,sun_irradiance_680nm,sun_irradiance_550nm,sun_irradiance_440nm,"
      "sky_irradiance_680nm,sky_irradiance_550nm,sky_irradiance_440nm,sky_irradiance_stderr_680nm,"
      "sky_irradiance_stderr_550nm,sky_irradiance_stderr_440nm\n"
      "daylight,0,0,30,0,,1,1,1,0,0,0,,,,,,,,,\n"
      "space,100000,90,30,0,,2,2,2,0,0,0,,,,,,,,,\n"
      "irradiance,0,0,30,0,0,0.5,0.5,0.5,0,0,0,1,1,1,2,2,2,0,0,0\n";
  report::ReferenceSet reference = report::ParseReference(text, "r.csv", testing::Earth());
  EXPECT_EQ(report::MeasuredGroups(reference),
            (std::vector<std::string>{"daylight", "space", "sun_irradiance", "sky_irradiance"}));
  // A model 10% high everywhere, with no view from space and no sky irradiance.
  std::vector<report::GroupErrors> errors = report::MeasureErrors(reference, [](const report::ReferenceCase& c) {
    report::ModelAnswer a;
    if (c.group == "space") return a;
    a.has_radiance = true;
    a.radiance = 1.1 * c.radiance;
    a.has_sun_irradiance = c.query.has_normal;
    a.sun_irradiance = 1.1 * c.sun_irradiance;
    return a;
  });
  EXPECT_NEAR(report::FindGroup(errors, "daylight").luminance.rms_relative, 0.1, 1e-12);
  EXPECT_NEAR(report::FindGroup(errors, "sun_irradiance").channel[2].max_relative, 0.1, 1e-12);
  EXPECT_FALSE(report::FindGroup(errors, "space").Answered());
  EXPECT_FALSE(report::FindGroup(errors, "sky_irradiance").Answered());
  EXPECT_TRUE(report::FindGroup(errors, "daylight").Answered());
  // A reference for other wavelengths is refused.
  Atmosphere other = testing::Earth();
  other.wavelengths_nm = Spectrum(700.0, 550.0, 440.0);
  EXPECT_THROW(report::ParseReference(text, "r.csv", other), InputError);
}

// One bake yields every order: the snapshot after order N is the bake of N
// orders, texel for texel, and the reported time grows with the orders;
// with a last order, the orders after it are not taken and the tables are
// the same.
TEST(BakeOrderSnapshot, EachOrderEqualsABakeOfThatManyOrders) {
  BakeSettings settings = testing::SmallBakeSettings();
  settings.orders = 3;
  std::vector<LutSet> snapshots;
  std::vector<double> seconds;
  LutSet final_tables =
      Bake(testing::Earth(), settings, nullptr, nullptr, {[&](int order, const LutSet& tables, double bake_seconds) {
             EXPECT_EQ(order, static_cast<int>(snapshots.size()) + 1);
             snapshots.push_back(tables);
             seconds.push_back(bake_seconds);
           }});
  ASSERT_EQ(snapshots.size(), 3u);
  std::vector<int> taken;
  const LutSet up_to_first = Bake(testing::Earth(), settings, nullptr, nullptr,
                                  {[&](int order, const LutSet&, double) { taken.push_back(order); }, 1});
  EXPECT_EQ(taken, std::vector<int>{1});
  EXPECT_EQ(up_to_first.scattering.texels, final_tables.scattering.texels);
  EXPECT_LT(seconds[0], seconds[1]);
  EXPECT_LT(seconds[1], seconds[2]);
  for (int orders = 1; orders <= 2; ++orders) {
    BakeSettings s = settings;
    s.orders = orders;
    LutSet expected = Bake(testing::Earth(), s);
    const LutSet& got = snapshots[orders - 1];
    EXPECT_EQ(got.scattering.texels, expected.scattering.texels) << orders;
    EXPECT_EQ(got.irradiance.texels, expected.irradiance.texels) << orders;
    EXPECT_EQ(got.single_mie_scattering.texels, expected.single_mie_scattering.texels) << orders;
    EXPECT_EQ(got.transmittance.texels, expected.transmittance.texels) << orders;
  }
  EXPECT_EQ(snapshots[2].scattering.texels, final_tables.scattering.texels);
  EXPECT_EQ(snapshots[2].irradiance.texels, final_tables.irradiance.texels);
}

TEST(ReportLadder, ChangesOneKnobAtATime) {
  BakeSettings base;
  report::LadderPlan plan = report::MakeLadder(base, false);
  EXPECT_EQ(plan.max_orders, 8);
  // Six knobs at x1/2 and x2, the preview and half storage.
  ASSERT_EQ(plan.variants.size(), 14u);
  auto find = [&](const std::string& name) -> const report::LadderStep& {
    for (const report::LadderStep& s : plan.variants) {
      if (s.name == name) return s;
    }
    ADD_FAILURE() << "no step " << name;
    return plan.variants.front();
  };
  EXPECT_EQ(find("scattering mu size x1/2").settings.scattering_mu_size, 64);
  EXPECT_EQ(find("scattering mu size x1/2").settings.scattering_r_size, base.scattering_r_size);
  EXPECT_EQ(find("scattering mu_s+nu size x2").settings.scattering_mu_s_size, 64);
  EXPECT_EQ(find("scattering mu_s+nu size x2").settings.scattering_nu_size, 16);
  EXPECT_EQ(find("transmittance+irradiance size x2").settings.transmittance_width, 512);
  EXPECT_EQ(find("transmittance+irradiance size x2").settings.irradiance_height, 32);
  EXPECT_EQ(find("sphere samples x1/2").settings.sphere_samples, 8);
  EXPECT_EQ(find("ray samples x2").settings.ray_samples, 256);
  EXPECT_TRUE(find("half").half);
  const BakeSettings& preview = find("preview (--preview)").settings;
  EXPECT_EQ(preview.scattering_nu_size, PreviewBakeSettings().scattering_nu_size);
  EXPECT_EQ(preview.ray_samples, PreviewBakeSettings().ray_samples);
  EXPECT_EQ(preview.orders, base.orders);
  // Halving keeps the scattering mu size even.
  BakeSettings small = testing::SmallBakeSettings();
  small.scattering_mu_size = 12;
  EXPECT_EQ(report::MakeLadder(small, false).variants[4].settings.scattering_mu_size, 6);
  small.scattering_mu_size = 10;
  EXPECT_EQ(report::MakeLadder(small, false).variants[4].settings.scattering_mu_size, 6);
  // The quick ladder: transmittance and irradiance sizes and half; orders 1-3.
  report::LadderPlan quick = report::MakeLadder(testing::SmallBakeSettings(), true);
  EXPECT_EQ(quick.max_orders, 3);
  EXPECT_EQ(quick.variants.size(), 3u);
  BakeSettings auto_orders = base;
  auto_orders.orders = 0;
  EXPECT_THROW(report::MakeLadder(auto_orders, false), UsageError);
}

// A camera on the ground looking at the zenith with the sun overhead, in one
// exponential Rayleigh constituent: every point of the view ray is lit along
// the same vertical line, so the optical depth camera -> point -> sun is the
// whole column, tau = beta H (1 - exp(-L / H)), at every point, and
//   L = E beta_s P(1) H (1 - exp(-L / H)) exp(-tau)
// exactly (L the atmosphere's thickness). The midpoint rule is second order:
// its error must fall about fourfold per doubling of the steps.
TEST(ReportRayMarch, ConvergesToTheExactIntegralOfAVerticalColumn) {
  Atmosphere a;
  a.name = "column";
  a.bottom_radius_m = 6360e3;
  a.top_radius_m = 6420e3;
  a.solar_irradiance = Spectrum(1.5, 1.8, 1.9);
  const double scale_height = 8000.0;
  a.constituents = {testing::ExponentialConstituent("rayleigh", Spectrum(5.802e-6, 13.558e-6, 33.100e-6),
                                                    Spectrum(1e-6), scale_height,
                                                    PhaseFunction{PhaseKind::kRayleigh, 0.0})};
  const double thickness = a.top_radius_m - a.bottom_radius_m;
  const double column = scale_height * (1.0 - std::exp(-thickness / scale_height));
  const Spectrum tau = a.constituents[0].Extinction() * column;
  const double phase = glsl::RayleighPhaseFunction(1.0);
  const Spectrum exact = a.solar_irradiance * a.constituents[0].scattering_per_m * phase * column * glm::exp(-tau);

  const glm::dvec3 camera(0.0, 0.0, a.bottom_radius_m), up(0.0, 0.0, 1.0);
  std::vector<double> errors;
  for (int steps : {8, 16, 32, 64}) {
    report::SingleScatteringRayMarch march(a, steps, steps);
    glm::dvec3 transmittance;
    long samples = 0;
    glm::dvec3 radiance = march.Radiance(camera, up, up, 0.0, &transmittance, &samples);
    EXPECT_EQ(samples, steps * (steps + 1));  // counted: N view points, N light points each
    double error = 0.0;
    for (int c = 0; c < 3; ++c) error = std::max(error, std::abs(radiance[c] / exact[c] - 1.0));
    errors.push_back(error);
    // The view ray's optical depth: the midpoint rule on exp(-z / H) in steps
    // dt is low by the factor x / sinh(x), x = dt / 2H: at most x^2 / 6.
    const double x = thickness / steps / (2.0 * scale_height);
    for (int c = 0; c < 3; ++c) {
      EXPECT_LE(std::abs(-std::log(transmittance[c]) / tau[c] - 1.0), x * x / 6.0) << steps;
    }
  }
  for (size_t i = 1; i < errors.size(); ++i) {
    EXPECT_GT(errors[i - 1] / errors[i], 3.5) << "steps " << (8 << i);
    EXPECT_LT(errors[i - 1] / errors[i], 4.5) << "steps " << (8 << i);
  }
  EXPECT_LT(errors.back(), 1e-3);
}

TEST(ReportRayMarch, TheGroundShadowsTheSunAndEndsTheView) {
  Atmosphere a = testing::Earth();
  report::SingleScatteringRayMarch march(a, 8, 8);
  const glm::dvec3 ground(0.0, 0.0, a.bottom_radius_m);
  const glm::dvec3 up(0.0, 0.0, 1.0);
  const glm::dvec3 below_horizon = glm::normalize(glm::dvec3(1.0, 0.0, -0.1));
  EXPECT_EQ(march.SunIrradiance(ground, up, below_horizon), glm::dvec3(0.0));
  EXPECT_GT(march.SunIrradiance(ground, up, up).y, 0.0);
  // A view from 1 km down at the ground: a finite segment, lit, not through the planet.
  glm::dvec3 transmittance;
  glm::dvec3 radiance =
      march.Radiance(ground + up * 1000.0, glm::normalize(glm::dvec3(1.0, 0.0, -1.0)), up, 0.0, &transmittance);
  EXPECT_GT(radiance.z, 0.0);
  EXPECT_GT(transmittance.z, 0.5);  // ~1.4 km of air
}

std::string QuickReportArguments() {
  // SmallBakeSettings() on the command line: the ladder in a few seconds.
  return " --quick -q --transmittance-size 64 16 --irradiance-size 16 4 --scattering-size 8 32 8 4"
         " --ray-samples 32 --sphere-samples 8 --orders 2 --march-steps 4 --passes 1";
}

TEST(ReportCommand, QuickLadderWritesTablesCsvJsonAndPlots) {
  testing::TempDir dir;
  const std::filesystem::path out = dir.path() / "report";
  std::string stdout_text, stderr_text;
  int code = testing::RunCommand(testing::Skybake() + " report earth -o " + testing::ShellQuote(out.string()) +
                                     QuickReportArguments(),
                                 dir, &stdout_text, &stderr_text);
  ASSERT_EQ(code, 0) << stderr_text;
  EXPECT_NE(stdout_text.find("| **orders 2 (base)** |"), std::string::npos) << stdout_text;
  EXPECT_NE(stdout_text.find("| ray march, 4 x 4 steps |"), std::string::npos) << stdout_text;

  nlohmann::json j = nlohmann::json::parse(testing::ReadText(out / "report.json"));
  EXPECT_EQ(j["atmosphere"], "earth");
  int bakes = 0, models = 0, base = 0;
  for (const nlohmann::json& row : j["rows"]) {
    (row["kind"] == "bake" ? bakes : models) += 1;
    if (row["kind"] == "bake") {
      base += row["is_base"].get<bool>();
      EXPECT_GT(row["bake_seconds"].get<double>(), 0.0);
      EXPECT_GT(row["bytes"].get<double>(), 0.0);
    }
    // Every group of the case set, answered or not.
    EXPECT_EQ(row["errors"].size(), 7u) << row["name"];
  }
  EXPECT_EQ(bakes, 1 + 3 + 2 + 1);  // base, orders 1-3, transmittance+irradiance x1/2 and x2, half
  EXPECT_EQ(models, 3);         // tables, Hoffman & Preetham, one ray march
  EXPECT_EQ(base, 1);

  std::vector<std::string> csv = testing::Lines(testing::ReadText(out / "report.csv"));
  ASSERT_GT(csv.size(), 1u);
  EXPECT_EQ(csv[0].rfind("kind,name,knob,", 0), 0u);
  // 10 rows x 7 groups x (3 wavelengths + luminance), and the header.
  EXPECT_EQ(csv.size(), 1u + 10 * 7 * 4);
  for (const std::string& line : csv) {
    for (const char* bad : {",nan", ",-nan", ",inf", ",-inf"}) EXPECT_EQ(line.find(bad), std::string::npos) << line;
  }

  // The colour section: the base settings at 15 wavelengths against the
  // committed spectral reference, and the base bake read as sRGB, every
  // group measured on the same cases for both, every figure finite (how
  // close they are at default sizes: SpectralBake.DefaultEarthAgainstTheSpectralReference).
  EXPECT_NE(stdout_text.find("### Colour (against earth_spectral_reference.csv)"), std::string::npos);
  const nlohmann::json& colour = j["colour"];
  EXPECT_EQ(colour["wavelengths"], 15);
  EXPECT_EQ(colour["reference"], "earth_spectral_reference.csv");
  ASSERT_EQ(colour["groups"].size(), std::size(report::kColourGroups));
  for (std::size_t i = 0; i < colour["groups"].size(); ++i) {
    const nlohmann::json& g = colour["groups"][i];
    EXPECT_EQ(g["group"], report::kColourGroups[i]);
    EXPECT_GT(g["spectral"]["cases"].get<int>(), 0) << g;
    EXPECT_EQ(g["spectral"]["cases"], g["as_srgb"]["cases"]) << g;
    for (const char* set : {"spectral", "as_srgb"}) {
      for (const char* figure : {"luminance_rms", "luminance_max", "delta_uv_rms", "delta_uv_max"}) {
        EXPECT_TRUE(std::isfinite(g[set][figure].get<double>())) << g;
      }
    }
  }

  EXPECT_NE(testing::ReadText(out / "error_vs_bake_time.svg").find("<svg"), std::string::npos);
  auto png = OIIO::ImageInput::open((out / "error_vs_bake_time.png").string());
  ASSERT_TRUE(png);
  EXPECT_GT(png->spec().width, 100);
  png->close();
}

TEST(ReportCommand, AnAtmosphereWithoutReferenceIsAOneLineInputError) {
  testing::TempDir dir;
  const std::string out = testing::ShellQuote((dir.path() / "report").string());
  std::string stderr_text;
  EXPECT_EQ(testing::RunCommand(testing::Skybake() + " report mars -o " + out + QuickReportArguments(), dir,
                                nullptr, &stderr_text),
            2);
  EXPECT_EQ(testing::Lines(stderr_text).size(), 1u) << stderr_text;
  EXPECT_NE(stderr_text.find("--reference"), std::string::npos) << stderr_text;
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "report"));
  // A missing reference file is an I/O error.
  EXPECT_EQ(testing::RunCommand(testing::Skybake() + " report earth -o " + out + " --reference " +
                                    testing::ShellQuote((dir.path() / "missing.csv").string()) +
                                    QuickReportArguments(),
                                dir, nullptr, &stderr_text),
            3);
  EXPECT_EQ(testing::Lines(stderr_text).size(), 1u) << stderr_text;
}

// The colour section's options: a count that cannot be baked (a bad option
// value, exit 1), or a spectral reference with nothing to bake against it
// (exit 2), is a one-line error before any bake, with no output folder;
// --wavelengths 0 leaves the section out.
TEST(ReportCommand, ColourSectionOptions) {
  testing::TempDir dir;
  const std::filesystem::path out = dir.path() / "report";
  std::string stdout_text, stderr_text;
  struct Refusal {
    std::string options;
    int code;
  };
  for (const Refusal& r : {Refusal{" --wavelengths 2", 1}, Refusal{" --wavelengths -4", 1},
                           Refusal{" --wavelengths 0 --spectral-reference r.csv", 2}}) {
    const std::string& options = r.options;
    EXPECT_EQ(testing::RunCommand(testing::Skybake() + " report earth -o " + testing::ShellQuote(out.string()) +
                                      QuickReportArguments() + options,
                                  dir, nullptr, &stderr_text),
              r.code)
        << options;
    EXPECT_EQ(testing::Lines(stderr_text).size(), 1u) << stderr_text;
    EXPECT_FALSE(std::filesystem::exists(out)) << options;
  }
  ASSERT_EQ(testing::RunCommand(testing::Skybake() + " report earth -o " + testing::ShellQuote(out.string()) +
                                    QuickReportArguments() + " --wavelengths 0",
                                dir, &stdout_text, &stderr_text),
            0)
      << stderr_text;
  EXPECT_EQ(stdout_text.find("### Colour"), std::string::npos);
  EXPECT_FALSE(nlohmann::json::parse(testing::ReadText(out / "report.json")).contains("colour"));
}

}  // namespace
}  // namespace skybake
