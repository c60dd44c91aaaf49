#include "tests/runtime_queries.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <map>
#include <random>

#include "shaders_runtime/query.h"
#include "shaders_runtime/runtime.h"
#include "tests/test_atmospheres.h"
#include "tests/test_util.h"

namespace skybake::testing {

using glsl::vec3;

BakeSettings RuntimeTestSettings(bool pack_mie) {
  BakeSettings s = SmallBakeSettings();
  // The default sun columns: with as few as the small tables' 8 the bake
  // keeps the columns below the split at the same suns for every ray, and
  // the runtime's lookup along each ray's own columns would go unrun.
  s.scattering_mu_s_size = BakeSettings().scattering_mu_s_size;
  s.pack_single_mie_in_alpha = pack_mie;
  return s;
}

namespace {

const char* const kOutputNames[] = {"sky radiance",       "sky transmittance", "aerial radiance",
                                    "aerial transmittance", "sun irradiance",   "sky irradiance",
                                    "transmittance to sun", "solar radiance",   "aerial radiance in shadow"};

vec3 ToFloat(const vec3& v) { return vec3(float(v.x), float(v.y), float(v.z)); }

}  // namespace

vec3 EvaluateTwin(const LutSet& luts, const RuntimeQuery& item) {
  const glsl::AtmosphereParameters& p = luts.parameters;
  glsl::sampler2D transmittance{&luts.transmittance}, irradiance{&luts.irradiance};
  glsl::sampler3D scattering{&luts.scattering};
  glsl::sampler3D single_mie{luts.single_mie_scattering.empty() ? &luts.scattering : &luts.single_mie_scattering};
  vec3 t, sky, v;
  switch (item.what) {
    case kSkyRadiance:
    case kSkyTransmittance:
      v = glsl::GetSkyRadiance(p, transmittance, scattering, single_mie, item.camera, item.view, item.sun, t);
      return item.what == kSkyRadiance ? v : t;
    case kAerialRadiance:
    case kAerialTransmittance:
      v = glsl::GetSkyRadianceToPoint(p, transmittance, scattering, single_mie, item.camera, item.extra, item.sun, t);
      return item.what == kAerialRadiance ? v : t;
    case kSunIrradiance:
    case kSkyIrradiance:
      v = glsl::GetSunAndSkyIrradiance(p, transmittance, irradiance, item.camera, item.extra, item.sun, sky);
      return item.what == kSunIrradiance ? v : sky;
    case kTransmittanceToSun: {
      double r = glm::length(item.camera);
      return glsl::GetTransmittanceToSun(p, transmittance, r, glm::dot(item.camera, item.sun) / r);
    }
    case kAerialRadianceInShadow:
      return glsl::GetSkyRadianceToPointWithShadow(p, transmittance, scattering, single_mie, item.camera, item.extra,
                                                   item.shadow_length, item.sun, t);
    default:
      return glsl::GetSolarRadiance(p);
  }
}

std::vector<RuntimeQuery> MakeRuntimeQueries(double bottom_radius, double top_radius) {
  std::mt19937 rng(20261123);
  auto uniform = [&](double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); };
  // Items added later draw from their own generator, so the earlier ones stay as they were.
  std::mt19937 more_rng(20261124);
  auto more_uniform = [&](double a, double b) { return std::uniform_real_distribution<double>(a, b)(more_rng); };
  std::vector<RuntimeQuery> items;
  auto add = [&](const char* group, const Query& q, std::initializer_list<int> outputs, float shadow_length = 0.0f) {
    QueryGeometry g = MakeQueryGeometry(q, bottom_radius);
    vec3 extra = q.has_normal ? g.normal : g.camera + g.view * q.distance_m;
    for (int what : outputs) {
      items.push_back({what, group, ToFloat(g.camera), ToFloat(glm::normalize(ToFloat(g.view))),
                       ToFloat(glm::normalize(ToFloat(g.sun))), ToFloat(extra), shadow_length});
    }
  };
  // The ground at altitude h is seen at view zenith 90 + acos(R / (R + h)).
  auto horizon_deg = [&](double h) { return 90.0 + std::acos(bottom_radius / (bottom_radius + h)) * 180.0 / M_PI; };
  for (int i = 0; i < 150; ++i) {
    Query q;
    q.altitude_m = std::round(uniform(10.0, 20000.0));
    q.sun_zenith_deg = uniform(0.0, 85.0);
    q.view_sun_azimuth_deg = uniform(0.0, 180.0);
    q.view_zenith_deg = uniform(0.0, 180.0);
    if (std::abs(q.view_zenith_deg - horizon_deg(q.altitude_m)) < 0.5) continue;  // the horizon group's
    add("daylight", q, {kSkyRadiance, kSkyTransmittance});
    q.sun_zenith_deg = uniform(90.0, 102.0);
    add("twilight", q, {kSkyRadiance, kSkyTransmittance});
    q.altitude_m = std::round(uniform(top_radius - bottom_radius + 1000.0, 1e6));
    q.view_zenith_deg = uniform(horizon_deg(q.altitude_m) - 30.0, 180.0);
    add("space", q, {kSkyRadiance, kSkyTransmittance});
  }
  for (int i = 0; i < 100; ++i) {
    Query q;
    q.altitude_m = std::round(uniform(10.0, 5000.0));
    q.sun_zenith_deg = uniform(0.0, 100.0);
    q.view_sun_azimuth_deg = uniform(0.0, 180.0);
    double h = horizon_deg(q.altitude_m);
    q.view_zenith_deg = h + (i % 2 ? 1.0 : -1.0) * uniform(0.05, 2.0);
    add("horizon", q, {kSkyRadiance, kSkyTransmittance});
    q.view_zenith_deg = uniform(60.0, h - 0.05);
    q.distance_m = std::exp(uniform(std::log(100.0), std::log(30000.0)));
    add("aerial perspective", q, {kAerialRadiance, kAerialTransmittance});
    add("aerial perspective", q, {kAerialRadianceInShadow}, float(q.distance_m * more_uniform(0.1, 0.9)));
    // A point on the ground, as an engine's terrain gives it.
    Query saved = q;
    q.view_zenith_deg = more_uniform(h + 0.5, 180.0);
    double mu = std::cos(q.view_zenith_deg * M_PI / 180.0), r = bottom_radius + q.altitude_m;
    q.distance_m = -r * mu - std::sqrt(r * r * mu * mu - q.altitude_m * (2.0 * bottom_radius + q.altitude_m));
    add("aerial perspective to the ground", q, {kAerialRadiance, kAerialTransmittance});
    q = saved;
    q.distance_m = 0.0;
    q.has_normal = true;
    q.normal_zenith_deg = uniform(0.0, 90.0);
    q.sun_zenith_deg = uniform(0.0, 95.0);
    add("irradiance", q, {kSunIrradiance, kSkyIrradiance, kTransmittanceToSun});
  }
  add("irradiance", Query{}, {kSolarRadiance});
  return items;
}

const char* const kGlslEvaluateQuery = R"(
vec3 EvaluateQuery(vec4 camera_what, vec4 view_ray, vec4 sun_shadow, vec4 extra_point) {
  vec3 camera = camera_what.xyz, view = view_ray.xyz, sun = sun_shadow.xyz, extra = extra_point.xyz;
  float shadow_length = sun_shadow.w;
  int what = int(camera_what.w);
  vec3 t, sky, v = vec3(0.0);
  if (what <= 1) {
#if SKYBAKE_HAS_SCATTERING_TEXTURE
    v = GetSkyRadiance(ATMOSPHERE, transmittance_texture, scattering_texture, single_mie_scattering_texture,
                       camera, view, sun, t);
    if (what == 1) v = t;
#endif
  } else if (what <= 3) {
#if SKYBAKE_HAS_AERIAL_PERSPECTIVE
    v = GetSkyRadianceToPoint(ATMOSPHERE, transmittance_texture, scattering_texture,
                              single_mie_scattering_texture, camera, extra, sun, t);
    if (what == 3) v = t;
#endif
  } else if (what <= 5) {
#if SKYBAKE_HAS_IRRADIANCE_TEXTURE
    v = GetSunAndSkyIrradiance(ATMOSPHERE, transmittance_texture, irradiance_texture, camera, extra, sun, sky);
    if (what == 5) v = sky;
#endif
  } else if (what == 6) {
    v = GetTransmittanceToSun(ATMOSPHERE, transmittance_texture, length(camera), dot(camera, sun) / length(camera));
  } else if (what == 7) {
    v = GetSolarRadiance(ATMOSPHERE);
  } else {
#if SKYBAKE_HAS_AERIAL_PERSPECTIVE
    v = GetSkyRadianceToPointWithShadow(ATMOSPHERE, transmittance_texture, scattering_texture,
                                        single_mie_scattering_texture, camera, extra, shadow_length, sun, t);
#endif
  }
  return v;
}
)";

std::vector<std::array<float, 4>> RuntimeQueryInputs(const std::vector<RuntimeQuery>& queries) {
  std::vector<std::array<float, 4>> inputs;
  for (const RuntimeQuery& item : queries) {
    inputs.push_back({float(item.camera.x), float(item.camera.y), float(item.camera.z), float(item.what)});
    inputs.push_back({float(item.view.x), float(item.view.y), float(item.view.z), 0.0f});
    inputs.push_back({float(item.sun.x), float(item.sun.y), float(item.sun.z), item.shadow_length});
    inputs.push_back({float(item.extra.x), float(item.extra.y), float(item.extra.z), 0.0f});
  }
  return inputs;
}

void ExpectMatchesTwin(const std::string& description, const LutSet& luts, const std::vector<RuntimeQuery>& items,
                       const std::vector<std::array<float, 4>>& gpu) {
  ASSERT_EQ(gpu.size(), items.size()) << description;
  std::vector<vec3> twin;
  double max_value[kOutputCount] = {};
  for (const RuntimeQuery& item : items) {
    twin.push_back(EvaluateTwin(luts, item));
    for (int c = 0; c < 3; ++c) max_value[item.what] = std::max(max_value[item.what], twin.back()[c]);
  }
  // Relative difference where the value exceeds 1e-6 of its output's
  // maximum: 1e-3, the bound float32 evaluation should meet; llvmpipe stays
  // near 2e-5 for every output but the sky below the split (1.1e-4: the own
  // columns' placement carries the relative error of the driver's atan in
  // the sun's distance to the shadow edge, ShadowEdgeDistance) and aerial
  // perspective. There the table
  // method subtracts two optical-depth lookups and computes
  // S(camera) - T S(point), both of which amplify the 0.5 m float rounding
  // of the point's radius near 6.4e6 m, most on short near-horizontal
  // segments. Segments under 10 km are therefore integrated along the
  // segment, with altitudes taken as the camera's plus the rise along the
  // ray; longer ones (long shadows' sunlit parts, grazing rays to the
  // ground) use the table method, whose transmittance differs by up to
  // about 2e-3, hence 3e-3 for it.
  // The radiance of short segments keeps one cancelling term: its multiple
  // scattering is the table method's S(x) - T S(p) over a 10 km stretch
  // minus that stretch's single scattering, a small difference in float of
  // table values interpolated by the driver. It ranges from about 2e-3 to
  // 1e-2 for the same snippet, depending only on how the driver compiles the
  // test's main() around it; hence 2e-2 for those radiances.
  auto tolerance = [](int what) {
    if (what == kAerialRadiance || what == kAerialRadianceInShadow) return 2e-2;
    return what == kAerialTransmittance ? 3e-3 : 1e-3;
  };
  double worst[kOutputCount] = {};
  std::map<std::string, double> worst_by_group;
  int compared = 0;
  for (size_t i = 0; i < items.size(); ++i) {
    const RuntimeQuery& item = items[i];
    for (int c = 0; c < 3; ++c) {
      double expected = twin[i][c];
      ASSERT_TRUE(std::isfinite(gpu[i][c])) << description << ", " << kOutputNames[item.what];
      if (!(expected > 1e-6 * max_value[item.what])) continue;
      double relative = std::abs(gpu[i][c] / expected - 1.0);
      ++compared;
      worst[item.what] = std::max(worst[item.what], relative);
      worst_by_group[item.group] = std::max(worst_by_group[item.group], relative);
      EXPECT_LE(relative, tolerance(item.what)) << item.group << ", " << kOutputNames[item.what] << " channel " << c
                                      << ": " << description << " " << gpu[i][c] << " twin " << expected << " camera z "
                                      << item.camera.z << " view " << item.view.x << "," << item.view.z
                                      << " sun " << item.sun.x << "," << item.sun.y << "," << item.sun.z
                                      << " extra " << item.extra.x << "," << item.extra.z;
    }
  }
  std::cout << description << ": " << items.size() << " queries, " << compared
            << " values compared; max relative difference vs twin\n";
  for (int w = 0; w < kOutputCount; ++w) std::cout << "  " << kOutputNames[w] << ": " << worst[w] << "\n";
  for (const auto& [group, value] : worst_by_group) std::cout << "  group " << group << ": " << value << "\n";
}


int RunWgslJob(const std::filesystem::path& job_dir, std::string* output) {
  if (std::string(SKYBAKE_NODE_EXECUTABLE).empty()) {
    *output = "node is not installed";
    return 77;
  }
  TempDir dir;
  const std::filesystem::path script = std::filesystem::path(SKYBAKE_SOURCE_DIR) / "tests/runtime_webgpu/run_wgsl.mjs";
  std::string out, err;
  const int status = RunCommand(ShellQuote(SKYBAKE_NODE_EXECUTABLE) + " " + ShellQuote(script) + " --work-dir " +
                                    ShellQuote(SKYBAKE_NPM_WORK_DIR "/runtime_webgpu") + " --job " + ShellQuote(job_dir),
                                dir, &out, &err);
  *output = out + err;
  return status;
}

int CompileWgsl(const std::string& source, std::string* output) {
  TempDir dir;
  WriteText(dir.path() / "shader.wgsl", source);
  WriteText(dir.path() / "job.json", R"({"shader": "shader.wgsl", "compile_only": true})");
  return RunWgslJob(dir.path(), output);
}

}  // namespace skybake::testing
