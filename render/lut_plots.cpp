#include "render/lut_plots.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "bake/bake.h"
#include "bake/scene.h"
#include "plot/plot.h"
#include "report/error_stats.h"
#include "shaders_runtime/twin.h"

namespace skybake::render {

namespace {

using glsl::vec3;
constexpr double kDegree = glsl::PI / 180.0;
// Palette indices (plot/plot.h) that read as red, green and blue.
constexpr int kChannelColor[3] = {2, 4, 0};

// How the plots name a set's channels and label their axes: a wavelength
// per channel, in W m^-2 sr^-1 nm^-1 (W m^-2 nm^-1 for irradiance); or, for
// a spectral set (bake/bake.h SpectralColour), CIE X, Y and Z in
// photometric units, Y in cd m^-2 (lux for irradiance).
struct ChannelLabels {
  std::string names[3];     // "680 nm" or "X"
  std::string radiance;     // the sky radiance plot's axis (its channel 1)
  std::string irradiance;   // the irradiance plot's axis (every channel)
  std::string luminance;    // the sunset plot's axis
};

ChannelLabels LabelsOf(const LutSet& luts) {
  ChannelLabels labels;
  if (luts.colour) {
    labels.names[0] = "X", labels.names[1] = "Y", labels.names[2] = "Z";
    labels.radiance = "luminance Y (cd m^-2)";
    labels.irradiance = "CIE X, Y, Z (Y: illuminance, lux)";
    labels.luminance = "luminance Y (cd m^-2)";
    return labels;
  }
  for (int c = 0; c < 3; ++c) {
    char name[32];
    std::snprintf(name, sizeof(name), "%.0f nm", luts.atmosphere.wavelengths_nm[c]);
    labels.names[c] = name;
  }
  labels.radiance = "radiance (W m^-2 sr^-1 nm^-1)";
  labels.irradiance = "irradiance (W m^-2 nm^-1)";
  labels.luminance = "luminance of the three channels (W m^-2 sr^-1 nm^-1, Rec. 709 weights)";
  return labels;
}

void Write(StagedFiles& files, const LinePlot& plot, const std::filesystem::path& dir, const std::string& stem,
           PlotFiles* out) {
  std::filesystem::path svg = dir / (stem + ".svg"), png = dir / (stem + ".png");
  WritePlotSvg(files, svg, plot);
  out->png_text = WritePlotPng(files, png, plot) && out->png_text;
  out->files.push_back(svg);
  out->files.push_back(png);
}

// Why `table` is not in `luts`: the scene's reason when a scene left it out.
std::string MissingTable(const LutSet& luts, const std::string& table) {
  std::string why = "the set has no " + table + " table";
  if (!luts.scene) return why;
  for (const OmittedTable& t : PlanScene(*luts.scene, luts.atmosphere).omitted)
    if (t.table == table) return why + " (scene '" + luts.scene->name + "': " + t.reason + ")";
  return why + " (scene '" + luts.scene->name + "')";
}

// The problem a scene has with a sky query from `altitude_m` with the sun at
// `sun_zenith_deg`; empty where the set covers it.
std::string SkyQueryProblem(const LutSet& luts, double altitude_m, double sun_zenith_deg) {
  if (!luts.scene) return "";
  Query sky;
  sky.altitude_m = altitude_m, sky.sun_zenith_deg = sun_zenith_deg;
  std::vector<std::string> unused;
  return SceneQueryProblem(*luts.scene, luts.parameters.bottom_radius, false, &sky, &unused);
}

// The zenith angle of the lowest sun the tables cover, in degrees.
double LowestSunZenithDeg(const glsl::AtmosphereParameters& p) {
  return std::acos(std::clamp(p.mu_s_min, -1.0, 1.0)) / kDegree;
}

constexpr double kSunsetCameraAltitudeM = 1.0;
constexpr double kSunsetFirstSunDeg = 85.0;

}  // namespace

SunsetCurves ComputeSunsetCurves(const Twin& twin, bool channels_are_xyz) {
  const glsl::AtmosphereParameters& p = twin.parameters();
  const double lowest_sun_deg = LowestSunZenithDeg(p);
  const vec3 camera(0.0, 0.0, p.bottom_radius + kSunsetCameraAltitudeM);
  const double horizon = 88.0 * kDegree;
  const vec3 sunward(std::sin(horizon), 0.0, std::cos(horizon)), antisolar(-sunward.x, 0.0, sunward.z);
  auto luminance = [&](const vec3& channels) { return channels_are_xyz ? channels.y : report::Luminance(channels); };
  SunsetCurves curves;
  for (int i = 0; kSunsetFirstSunDeg + 0.05 * i <= lowest_sun_deg + 1e-9; ++i) {
    const double sun_zenith = kSunsetFirstSunDeg + 0.05 * i;
    const vec3 sun(std::sin(sun_zenith * kDegree), 0.0, std::cos(sun_zenith * kDegree));
    curves.sun_zenith_deg.push_back(sun_zenith);
    curves.zenith.push_back(luminance(twin.SkyRadiance(camera, vec3(0.0, 0.0, 1.0), sun, nullptr)));
    curves.sunward_horizon.push_back(luminance(twin.SkyRadiance(camera, sunward, sun, nullptr)));
    curves.antisolar_horizon.push_back(luminance(twin.SkyRadiance(camera, antisolar, sun, nullptr)));
  }
  return curves;
}

PlotFiles WriteLutPlots(StagedFiles& staged, const LutSet& luts, const std::filesystem::path& dir,
                        const std::string& caption) {
  const Twin twin(MakeTwinTables(luts));
  const ChannelLabels labels = LabelsOf(luts);
  const glsl::AtmosphereParameters& p = twin.parameters();
  const double lowest_sun_deg = LowestSunZenithDeg(p);
  PlotFiles files;

  {
    LinePlot plot;
    plot.title = "Transmittance to the top of the atmosphere";
    plot.caption = caption;
    plot.x = {"view zenith angle (degrees)", false, 0.0, 90.0};
    plot.y = {"transmittance", true, {}, 1.0};
    const double altitudes_km[] = {0.0, 5.0, 20.0};
    const LineStyle styles[] = {LineStyle::kSolid, LineStyle::kDashed, LineStyle::kDotted};
    for (int a = 0; a < 3; ++a) {
      double r = std::min(p.bottom_radius + altitudes_km[a] * 1e3, p.top_radius);
      for (int c = 0; c < 3; ++c) {
        PlotSeries s;
        char name[64];
        std::snprintf(name, sizeof(name), "%s, %g km", labels.names[c].c_str(), altitudes_km[a]);
        s.name = name;
        s.style = styles[a];
        s.color = kChannelColor[c];
        for (int i = 0; i <= 180; ++i) {
          double zenith = 0.5 * i;
          s.x.push_back(zenith);
          s.y.push_back(std::exp(-twin.OpticalDepthToTop(r, std::cos(zenith * kDegree))[c]));
        }
        plot.series.push_back(std::move(s));
      }
    }
    Write(staged, plot, dir, "lut_transmittance", &files);
  }

  // The sky seen from 1 m above the ground, for the sun zeniths a scene's
  // restricted scattering tables cover there.
  const double sky_camera_altitude_m = 1.0;
  std::vector<double> sky_sun_zeniths;
  for (double sun_zenith : {0.0, 45.0, 80.0, 90.0}) {
    const std::string problem = SkyQueryProblem(luts, sky_camera_altitude_m, sun_zenith);
    if (problem.empty()) {
      sky_sun_zeniths.push_back(sun_zenith);
    } else if (twin.has_scattering()) {
      char line[64];
      std::snprintf(line, sizeof(line), "lut_sky_radiance: sun zenith %g deg: ", sun_zenith);
      files.left_out.push_back(line + problem);
    }
  }
  if (!twin.has_scattering()) {
    files.left_out.push_back("lut_sky_radiance: " + MissingTable(luts, "scattering"));
  } else if (!sky_sun_zeniths.empty()) {
    LinePlot plot;
    plot.title = "Sky radiance from the ground in the sun's vertical plane (" + labels.names[1] + ")";
    plot.caption = caption;
    plot.x = {"view zenith angle (degrees; negative: away from the sun)", false, -90.0, 90.0};
    plot.y = {labels.radiance, true, {}, {}};
    const vec3 camera(0.0, 0.0, p.bottom_radius + sky_camera_altitude_m);
    for (double sun_zenith : sky_sun_zeniths) {
      PlotSeries s;
      char name[48];
      std::snprintf(name, sizeof(name), "sun zenith %g deg", sun_zenith);
      s.name = name;
      vec3 sun(std::sin(sun_zenith * kDegree), 0.0, std::cos(sun_zenith * kDegree));
      for (int i = 0; i <= 360; ++i) {
        double zenith = -90.0 + 0.5 * i;
        // Stop just above the horizon, where the ground begins.
        double z = std::clamp(zenith, -89.5, 89.5) * kDegree;
        vec3 view(std::sin(z), 0.0, std::cos(z));
        s.x.push_back(zenith);
        s.y.push_back(twin.SkyRadiance(camera, view, sun, nullptr)[1]);
      }
      plot.series.push_back(std::move(s));
    }
    Write(staged, plot, dir, "lut_sky_radiance", &files);
  }

  if (!twin.has_irradiance()) {
    files.left_out.push_back("lut_irradiance: " + MissingTable(luts, "irradiance"));
  } else {
    LinePlot plot;
    plot.title = "Irradiance on horizontal ground";
    plot.caption = caption;
    plot.x = {"sun zenith angle (degrees)", false, 0.0, lowest_sun_deg};
    plot.y = {labels.irradiance, false, 0.0, {}};
    const vec3 point(0.0, 0.0, p.bottom_radius), normal(0.0, 0.0, 1.0);
    for (int c = 0; c < 3; ++c) {
      PlotSeries sun, sky;
      sun.name = "sun, " + labels.names[c];
      sky.name = "sky, " + labels.names[c];
      sun.color = sky.color = kChannelColor[c];
      sky.style = LineStyle::kDashed;
      for (int i = 0; i <= 200; ++i) {
        double zenith = lowest_sun_deg * i / 200.0;
        vec3 sun_direction(std::sin(zenith * kDegree), 0.0, std::cos(zenith * kDegree));
        vec3 sky_irradiance;
        vec3 sun_irradiance = twin.SunAndSkyIrradiance(point, normal, sun_direction, &sky_irradiance);
        sun.x.push_back(zenith);
        sun.y.push_back(sun_irradiance[c]);
        sky.x.push_back(zenith);
        sky.y.push_back(sky_irradiance[c]);
      }
      plot.series.push_back(std::move(sun));
      plot.series.push_back(std::move(sky));
    }
    Write(staged, plot, dir, "lut_irradiance", &files);
  }

  std::string sunset_problem = twin.has_scattering() ? "" : MissingTable(luts, "scattering");
  for (double sun_zenith : {kSunsetFirstSunDeg, lowest_sun_deg}) {
    if (sunset_problem.empty()) sunset_problem = SkyQueryProblem(luts, kSunsetCameraAltitudeM, sun_zenith);
  }
  if (sunset_problem.empty() && lowest_sun_deg <= kSunsetFirstSunDeg) {
    sunset_problem = "the atmosphere's lowest sun is above 85 deg";
  }
  if (!sunset_problem.empty()) {
    files.left_out.push_back("lut_sunset: " + sunset_problem);
  } else {
    const SunsetCurves curves = ComputeSunsetCurves(twin, luts.colour.has_value());
    LinePlot plot;
    plot.title = "Sky luminance from the ground through sunset and twilight";
    plot.caption = caption;
    plot.x = {"sun zenith angle (degrees)", false, kSunsetFirstSunDeg, lowest_sun_deg};
    plot.y = {labels.luminance, true, {}, {}};
    const std::pair<const char*, const std::vector<double>*> views[] = {
        {"zenith", &curves.zenith},
        {"2 deg above the horizon, toward the sun", &curves.sunward_horizon},
        {"2 deg above the horizon, away from the sun", &curves.antisolar_horizon}};
    for (const auto& [name, values] : views) {
      PlotSeries s;
      s.name = name;
      s.x = curves.sun_zenith_deg;
      s.y = *values;
      plot.series.push_back(std::move(s));
    }
    Write(staged, plot, dir, "lut_sunset", &files);
  }
  return files;
}

}  // namespace skybake::render
