// Scene files: TOML text -> validated Scene, the plan of what a scene keeps
// of a bake, and the scene as the manifest records it.
#include "bake/scene.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "bake/bake.h"
#include "bake/config.h"
#include "bake/medium.h"
#include "bake/toml_input.h"
#include "core/constants.h"
#include "core/errors.h"
#include "core/file_io.h"
#include "shaders_runtime/runtime.h"

namespace skybake {

namespace {

using namespace toml_input;

constexpr double kDegree = kPi / 180.0;
constexpr Interval kNonNegativeMetres{0.0, std::numeric_limits<double>::infinity(), true, false};
constexpr Interval kPositiveMetres{0.0, std::numeric_limits<double>::infinity(), false, false};
constexpr Interval kZenithDeg{0.0, 180.0, true, true};

// A closed range [min, max] as written and in SI units.
struct Range {
  double min = 0.0, max = 0.0;
};

class SceneReader : public TomlReader {
 public:
  using TomlReader::TomlReader;

  Scene Read(const toml::table& root) {
    CheckKeys(root, "", {"name", "description", "effects", "camera", "objects", "sun", "precision", "output"});
    Scene scene;
    scene.name = RequireString(root, "", "name");
    if (scene.name.empty()) report_.Fail("name", "must not be empty");
    if (const toml::node* node = root.get("description")) scene.description = ReadString(*node, "description");

    ReadEffects(RequireTable(root, "", "effects"), scene.effects);
    const SceneEffects& e = scene.effects;

    Range camera = ReadAltitudeRange(RequireTable(root, "", "camera"), "camera");
    scene.camera_altitude_min_m = camera.min, scene.camera_altitude_max_m = camera.max;
    const toml::table* objects = OptionalTable(root, "", "objects");
    if (e.aerial_perspective) {
      if (!objects) report_.Fail("objects", "missing required table (effects.aerial_perspective needs the objects' altitudes)");
      Range object = ReadAltitudeRange(*objects, "objects");
      scene.object_altitude_min_m = object.min, scene.object_altitude_max_m = object.max;
    } else if (objects) {
      report_.Fail("objects", "only meaningful with effects.aerial_perspective");
    }

    const toml::table& sun = RequireTable(root, "", "sun");
    CheckKeys(sun, "sun", {"zenith_deg"});
    Range zenith = ReadRange(Require(sun, "sun", "zenith_deg"), "sun.zenith_deg", kZenithDeg);
    scene.sun_zenith_min_deg = zenith.min, scene.sun_zenith_max_deg = zenith.max;

    if (const toml::table* precision = OptionalTable(root, "", "precision")) ReadPrecision(*precision, scene);
    if (const toml::table* output = OptionalTable(root, "", "output")) ReadOutput(*output, scene);
    return scene;
  }

 private:
  bool ReadBool(const toml::node& node, const std::string& path) const {
    if (!node.is_boolean()) report_.Fail(path, "expected true or false, got " + TypeName(node));
    return node.as_boolean()->get();
  }

  void ReadEffects(const toml::table& effects, SceneEffects& e) const {
    CheckKeys(effects, "effects",
              {"sky", "aerial_perspective", "sun_transmittance", "ground_irradiance", "sharp_sun_halo", "space_views"});
    // A scene names what it uses: an effect not written is not needed.
    auto flag = [&](std::string_view key) {
      const toml::node* node = effects.get(key);
      return node ? ReadBool(*node, Join("effects", key)) : false;
    };
    e.sky = flag("sky");
    e.sun_transmittance = flag("sun_transmittance");
    e.ground_irradiance = flag("ground_irradiance");
    e.sharp_sun_halo = flag("sharp_sun_halo");
    e.space_views = flag("space_views");
    e.aerial_perspective = false;
    if (const toml::node* node = effects.get("aerial_perspective")) {
      const std::string path = "effects.aerial_perspective";
      if (node->is_boolean()) {
        if (node->as_boolean()->get())
          report_.Fail(path, "needs a maximum distance: write aerial_perspective = { max_distance_km = ... }");
      } else if (const toml::table* table = node->as_table()) {
        CheckKeys(*table, path, {"max_distance_km", "max_distance_m"});
        auto [which, value] = ExactlyOne(*table, path, {"max_distance_km", "max_distance_m"});
        double written = ReadNumber(*value, Join(path, which == 0 ? "max_distance_km" : "max_distance_m"),
                                    kPositiveMetres);
        e.aerial_perspective = true;
        e.aerial_perspective_max_distance_m = which == 0 ? written * 1000.0 : written;
      } else {
        report_.Fail(path, "expected false or a table { max_distance_km }, got " + TypeName(*node));
      }
    }
    if (!e.sky && !e.aerial_perspective && !e.sun_transmittance && !e.ground_irradiance)
      report_.Fail("effects", "names no effect (use one of sky, aerial_perspective, sun_transmittance, ground_irradiance)");
    if (e.sharp_sun_halo && !e.sky && !e.aerial_perspective)
      report_.Fail("effects.sharp_sun_halo", "needs sky or aerial_perspective (it is part of their scattering)");
    if (e.space_views && !e.sky) report_.Fail("effects.space_views", "needs sky");
  }

  Range ReadRange(const toml::node& node, const std::string& path, const Interval& interval) const {
    const toml::array* array = node.as_array();
    if (!array || array->size() != 2) report_.Fail(path, "expected [min, max], got " + TypeName(node));
    Range range{ReadNumber(*array->get(0), Index(path, 0), interval),
                ReadNumber(*array->get(1), Index(path, 1), interval)};
    if (range.min > range.max)
      report_.Fail(path, "minimum " + FormatNumber(range.min) + " exceeds maximum " + FormatNumber(range.max));
    return range;
  }

  // altitude_km = [min, max] or altitude_m = [min, max], in metres.
  Range ReadAltitudeRange(const toml::table& table, const std::string& path) const {
    CheckKeys(table, path, {"altitude_km", "altitude_m"});
    auto [which, node] = ExactlyOne(table, path, {"altitude_km", "altitude_m"});
    Range range = ReadRange(*node, Join(path, which == 0 ? "altitude_km" : "altitude_m"), kNonNegativeMetres);
    if (which == 0) range.min *= 1000.0, range.max *= 1000.0;
    return range;
  }

  void ReadPrecision(const toml::table& precision, Scene& scene) const {
    CheckKeys(precision, "precision", {"transmittance", "irradiance", "scattering", "single_mie_scattering"});
    auto half = [&](std::string_view key, bool& value) {
      const toml::node* node = precision.get(key);
      if (!node) return;
      const std::string path = Join("precision", key);
      std::string text = ReadString(*node, path);
      if (text != "half" && text != "float") {
        report_.Fail(path, "unknown precision " + TomlString(text) + " (expected \"half\" or \"float\")");
      }
      value = text == "half";
    };
    half("transmittance", scene.precision.transmittance_half);
    half("irradiance", scene.precision.irradiance_half);
    half("scattering", scene.precision.scattering_half);
    half("single_mie_scattering", scene.precision.single_mie_scattering_half);
  }

  void ReadOutput(const toml::table& output, Scene& scene) const {
    CheckKeys(output, "output", {"formats"});
    const toml::node& node = Require(output, "output", "formats");
    const toml::array* array = node.as_array();
    if (!array || array->empty()) report_.Fail("output.formats", "expected a non-empty array of \"exr\", \"ktx2\"");
    scene.formats.clear();
    for (size_t i = 0; i < array->size(); ++i) {
      const std::string path = Index("output.formats", i);
      std::string format = ReadString(*array->get(i), path);
      if (format != "exr" && format != "ktx2") {
        report_.Fail(path, "unknown format " + TomlString(format) + " (expected \"exr\" or \"ktx2\")");
      }
      if (std::find(scene.formats.begin(), scene.formats.end(), format) != scene.formats.end())
        report_.Fail(path, "repeats \"" + format + "\"");
      scene.formats.push_back(format);
    }
  }
};

// Single Mie can ride in the scattering table's alpha only when the Mie and
// the other constituents both scatter red light (MakeAtmosphereParameters).
bool CanPackSingleMie(const Atmosphere& atmosphere) {
  const Medium medium(atmosphere);
  Spectrum mie(0.0), other(0.0);
  for (int g = 0; g < static_cast<int>(medium.groups().size()); ++g) {
    for (int c : medium.groups()[g].constituents) {
      const Constituent& constituent = atmosphere.constituents[c];
      (g == medium.mie_group() ? mie : other) += constituent.scattering_per_m * constituent.density.At(0.0);
    }
  }
  return mie.x > 0.0 && other.x > 0.0 && other.y > 0.0 && other.z > 0.0;
}

// The part of the scattering table's r axis, which maps the distance to the
// horizon rho = sqrt(r^2 - bottom^2), that the altitudes [low, high] span.
double RhoSpan(const Atmosphere& atmosphere, double low, double high) {
  const double rg = atmosphere.bottom_radius_m;
  auto rho = [&](double altitude) { return std::sqrt(altitude * (2.0 * rg + altitude)); };
  return (rho(high) - rho(low)) / rho(atmosphere.top_radius_m - rg);
}

// The scattering tables are looked up at the camera (the sky, from the top
// of the atmosphere for a camera above it) and for aerial perspective at
// the objects, at the end of the sunlit part of a partly shadowed segment
// (which can dip below both ends) and, for segments shorter than
// DIRECT_SEGMENT_LENGTH, that far along the ray as long as it stays inside
// the table's radii (aerial_perspective.glsl); with the sun as seen from there: the
// scene's suns, moved by up to the central angle of the longest of these
// distances (a camera in space sees every sun). Restricts plan's tables to
// those altitudes and suns.
void PlanScatteringRange(const Scene& scene, const Atmosphere& atmosphere, ScenePlan* plan) {
  const SceneEffects& e = scene.effects;
  const double rg = atmosphere.bottom_radius_m, height = atmosphere.top_radius_m - rg;
  double low = scene.camera_altitude_min_m, high = std::min(height, scene.camera_altitude_max_m);
  double angle = 0.0;
  if (e.aerial_perspective) {
    const double reach = std::max(e.aerial_perspective_max_distance_m, glsl::DIRECT_SEGMENT_LENGTH);
    angle = 2.0 * std::asin(std::min(1.0, reach / (2.0 * rg)));
    // The lowest point of a chord of that length between two points at or
    // above the lowest camera or object.
    const double r_low = rg + std::min(low, scene.object_altitude_min_m);
    const double half_chord = 0.5 * e.aerial_perspective_max_distance_m;
    low = std::max(0.0, std::sqrt(std::max(0.0, r_low * r_low - half_chord * half_chord)) - rg);
    high = std::max(high, scene.object_altitude_max_m);
  }
  // A table needs two distinct ends: at least 100 m and half a degree.
  constexpr double kMinAltitudeSpan = 100.0, kMinSunSpan = 0.5 * kDegree;
  if (high - low < kMinAltitudeSpan) {
    low = std::clamp(0.5 * (low + high - kMinAltitudeSpan), 0.0, height - kMinAltitudeSpan);
    high = low + kMinAltitudeSpan;
  }
  double sun_low = std::max(0.0, scene.sun_zenith_min_deg * kDegree - angle);
  double sun_high = std::min(kPi, scene.sun_zenith_max_deg * kDegree + angle);
  if (sun_high - sun_low < kMinSunSpan) {
    sun_low = std::clamp(0.5 * (sun_low + sun_high - kMinSunSpan), 0.0, kPi - kMinSunSpan);
    sun_high = sun_low + kMinSunSpan;
  }
  double mu_s_min = std::max(plan->mu_s_min, std::cos(sun_high)), mu_s_max = std::cos(sun_low);
  if (e.space_views) mu_s_min = plan->mu_s_min, mu_s_max = 1.0;
  // Worth it where the altitudes are a small part of the r axis (a third of
  // its rho span, so that ApplyScenePlan's table has at most half the
  // texels): the orders then cost a second grid, which a wider span repays
  // neither in time nor in accuracy (docs/accuracy.md, "Scenes").
  plan->restrict_scattering = RhoSpan(atmosphere, low, high) <= 1.0 / 3.0;
  if (!plan->restrict_scattering) return;
  plan->altitude_min_m = low, plan->altitude_max_m = high;
  plan->sun_above_horizon = scene.sun_zenith_max_deg <= 90.0;
  plan->table_mu_s_min = mu_s_min, plan->table_mu_s_max = mu_s_max;
}

// Optical depth from the ground straight up to the top, per channel.
Spectrum VerticalOpticalDepth(const Atmosphere& atmosphere) {
  constexpr int kSamples = 256;
  return Medium(atmosphere).OpticalDepth(atmosphere.bottom_radius_m, 1.0,
                                         atmosphere.top_radius_m - atmosphere.bottom_radius_m, kSamples);
}

double Max(const Spectrum& v) { return std::max({v.x, v.y, v.z}); }

Scene SceneFromJsonObject(const nlohmann::json& j) {
  Scene scene;
  scene.name = j.at("name").get<std::string>();
  scene.description = j.at("description").get<std::string>();
  const nlohmann::json& e = j.at("effects");
  scene.effects.sky = e.at("sky").get<bool>();
  scene.effects.aerial_perspective = e.at("aerial_perspective").get<bool>();
  scene.effects.aerial_perspective_max_distance_m = e.at("aerial_perspective_max_distance_m").get<double>();
  scene.effects.sun_transmittance = e.at("sun_transmittance").get<bool>();
  scene.effects.ground_irradiance = e.at("ground_irradiance").get<bool>();
  scene.effects.sharp_sun_halo = e.at("sharp_sun_halo").get<bool>();
  scene.effects.space_views = e.at("space_views").get<bool>();
  scene.camera_altitude_min_m = j.at("camera_altitude_m").at(0).get<double>();
  scene.camera_altitude_max_m = j.at("camera_altitude_m").at(1).get<double>();
  scene.object_altitude_min_m = j.at("object_altitude_m").at(0).get<double>();
  scene.object_altitude_max_m = j.at("object_altitude_m").at(1).get<double>();
  scene.sun_zenith_min_deg = j.at("sun_zenith_deg").at(0).get<double>();
  scene.sun_zenith_max_deg = j.at("sun_zenith_deg").at(1).get<double>();
  const nlohmann::json& p = j.at("precision");
  scene.precision.transmittance_half = p.at("transmittance").get<std::string>() == "half";
  scene.precision.irradiance_half = p.at("irradiance").get<std::string>() == "half";
  scene.precision.scattering_half = p.at("scattering").get<std::string>() == "half";
  scene.precision.single_mie_scattering_half = p.at("single_mie_scattering").get<std::string>() == "half";
  scene.formats = j.at("formats").get<std::vector<std::string>>();
  return scene;
}

}  // namespace

Scene ParseScene(std::string_view toml_text, const std::string& source_name) {
  return SceneReader(source_name).Read(ParseDocument(toml_text, source_name));
}

Scene LoadScene(const std::string& path) {
  std::filesystem::path file(path);
  return ParseScene(ReadFileText(file, "a scene file"), InputName(path));
}

void ValidateSceneForAtmosphere(const Scene& scene, const Atmosphere& atmosphere, const std::string& source_name) {
  const double height = atmosphere.top_radius_m - atmosphere.bottom_radius_m;
  Reporter report(source_name);
  auto km = [](double metres) { return FormatNumber(metres / 1000.0) + " km"; };
  if (!scene.effects.space_views && scene.camera_altitude_max_m > height) {
    report.Fail("camera.altitude", "maximum " + km(scene.camera_altitude_max_m) + " is above the top of " +
                                       atmosphere.name + "'s atmosphere (" + km(height) +
                                       "); enable effects.space_views for cameras in space");
  }
  if (scene.effects.aerial_perspective && scene.object_altitude_max_m > height) {
    report.Fail("objects.altitude", "maximum " + km(scene.object_altitude_max_m) + " is above the top of " +
                                        atmosphere.name + "'s atmosphere (" + km(height) + ")");
  }
}

ScenePlan PlanScene(const Scene& scene, const Atmosphere& atmosphere) {
  const SceneEffects& e = scene.effects;
  ScenePlan plan;
  plan.transmittance = true;  // every effect attenuates by it
  plan.scattering = e.sky || e.aerial_perspective;
  if (!plan.scattering) {
    plan.omitted.push_back({"scattering", "neither sky nor aerial_perspective (still computed: multiple scattering "
                                          "feeds the ground irradiance)"});
  }
  plan.aerial_perspective_functions = e.aerial_perspective;
  plan.single_mie_scattering = plan.scattering && e.sharp_sun_halo;
  if (plan.scattering && !e.sharp_sun_halo) {
    if (CanPackSingleMie(atmosphere)) {
      plan.pack_single_mie_in_alpha = true;
      plan.omitted.push_back({"single_mie_scattering", "no sharp_sun_halo: single Mie's red channel is packed into "
                                                       "the scattering table's alpha"});
    } else {
      // Without a Mie constituent scattering red, or with nothing else to
      // take the colour from, alpha cannot stand for it: keep the table.
      plan.single_mie_scattering = true;
    }
  } else if (!plan.scattering) {
    plan.omitted.push_back({"single_mie_scattering", "neither sky nor aerial_perspective"});
  }
  plan.irradiance = e.ground_irradiance;
  if (!plan.irradiance) {
    plan.omitted.push_back({"irradiance", "no ground_irradiance (still computed where the ground reflects: it lights "
                                          "the next scattering order)"});
  }

  // The scattering table is looked up at the camera (the sky), at the
  // objects (aerial perspective) and, inside the bake, along every ray from
  // them (multiple scattering). A point on a ray from the camera is at most
  // the central angle of a horizon ray away: to the tangent point, then out
  // to the top. The sun seen from it is lower by up to that angle, so the
  // table must reach the scene's lowest sun plus that angle. A camera in
  // space sees the whole atmosphere: keep the atmosphere's own range.
  if (e.space_views) {
    plan.mu_s_min = atmosphere.mu_s_min;
  } else {
    const double rg = atmosphere.bottom_radius_m, rt = atmosphere.top_radius_m;
    const double r_camera = std::min(rt, rg + scene.camera_altitude_max_m);
    const double reach = std::acos(std::min(1.0, rg / r_camera)) + std::acos(rg / rt);
    const double lowest_zenith = std::min(kPi, scene.sun_zenith_max_deg * kDegree + reach);
    plan.mu_s_min = std::max(-1.0, std::cos(lowest_zenith));
  }
  if (plan.scattering) PlanScatteringRange(scene, atmosphere, &plan);
  // A table that is not restricted is the orders' grid itself: reaching
  // suns below the atmosphere's lowest would spread its mu_s texels over
  // suns the scene never shows, and the full bake's gather already follows
  // the light below its lowest sun (the flight simulator's sky irradiance
  // on its cases: 1.00 % RMS, 3.18 % at most with its table to 108
  // degrees; as the full bake's, 0.94 % and 2.71 %, at the atmosphere's 102).
  if (!plan.restrict_scattering) plan.mu_s_min = std::max(plan.mu_s_min, atmosphere.mu_s_min);
  return plan;
}

void ApplyScenePlan(const ScenePlan& plan, Atmosphere* atmosphere, BakeSettings* settings) {
  atmosphere->mu_s_min = plan.mu_s_min;
  settings->pack_single_mie_in_alpha = plan.pack_single_mie_in_alpha;
  if (!plan.restrict_scattering) return;
  ScatteringRange range;
  range.altitude_min_m = plan.altitude_min_m, range.altitude_max_m = plan.altitude_max_m;
  range.mu_s_min = plan.table_mu_s_min, range.mu_s_max = plan.table_mu_s_max;
  range.atmosphere_r_size = settings->scattering_r_size;
  range.atmosphere_mu_size = settings->scattering_mu_size;
  // Half the mu_s texels while the sun stays above the horizon; in twilight
  // the light changes fastest with mu_s, so a scene that reaches it keeps
  // them all (docs/accuracy.md, "Scenes").
  range.atmosphere_mu_s_size =
      plan.sun_above_horizon ? std::max(2, settings->scattering_mu_s_size / 2) : settings->scattering_mu_s_size;
  // Its single scattering feeds the next order only through integrals over
  // the sphere: a quarter of the table's intervals while the sun stays up.
  // After sunset the light of a low sun along a ray falls with the sun's
  // optical depth, which a quarter of them integrates too coarsely: the
  // sunset scene's sky read 1-3 % darker than the full bake's
  // (examples/scenes/README.md).
  range.atmosphere_ray_samples = plan.sun_above_horizon
                                     ? std::min(settings->ray_samples, std::max(16, settings->ray_samples / 4))
                                     : settings->ray_samples;
  // Each order's radiance on half the r and mu texels where the atmosphere
  // is optically thin: optically thick ones lose light order after order on
  // it (BakeSettings::higher_order_divisor).
  if (Max(VerticalOpticalDepth(*atmosphere)) < 1.0) {
    settings->higher_order_divisor = std::max(settings->higher_order_divisor, 2);
  }
  // Half again as many r texels as the whole table has over these
  // altitudes (rho spans, as the r axis maps rho): part of the texels saved
  // goes to precision (on earth's ground-level daytime scene, 7 texels gave
  // the full bake's mean error and 10 a tenth less, examples/scenes/README.md).
  const double span = RhoSpan(*atmosphere, range.altitude_min_m, range.altitude_max_m);
  const int intervals = static_cast<int>(std::ceil(1.5 * span * (settings->scattering_r_size - 1)));
  settings->scattering_r_size = std::clamp(intervals + 1, 2, settings->scattering_r_size);
  settings->scattering_range = range;
}

std::string SceneQueryProblem(const Scene& scene, double bottom_radius_m, bool clamp, Query* q,
                              std::vector<std::string>* clamped) {
  const SceneEffects& e = scene.effects;
  if (q->distance_m > 0.0 && !e.aerial_perspective) return "aerial perspective (distance_m) is not in the scene";
  if (q->distance_m <= 0.0 && !e.sky) return "sky radiance (no distance_m) is not in the scene";
  if (q->has_normal && !e.ground_irradiance) return "irradiance (normal_zenith_deg) is not in the scene";
  // Moves `value` into [lo, hi] under --clamp; otherwise the problem.
  auto range = [&](const char* name, double* value, double lo, double hi, double unit, const char* unit_name) {
    if (*value >= lo && *value <= hi) return std::string();
    const std::string where = std::string(name) + " = " + FormatNumber(*value / unit) + " is outside the scene's [" +
                              FormatNumber(lo / unit) + ", " + FormatNumber(hi / unit) + "]" + unit_name;
    if (!clamp) return where;
    const double moved = std::clamp(*value, lo, hi);
    clamped->push_back(where + ", clamped to " + FormatNumber(moved / unit));
    *value = moved;
    return std::string();
  };
  std::string problem = range("altitude_m", &q->altitude_m, scene.camera_altitude_min_m,
                              scene.camera_altitude_max_m, 1.0, "");
  if (problem.empty()) {
    problem = range("sun_zenith_deg", &q->sun_zenith_deg, scene.sun_zenith_min_deg, scene.sun_zenith_max_deg, 1.0,
                    " deg");
  }
  if (problem.empty() && q->distance_m > 0.0) {
    problem = range("distance_m", &q->distance_m, 0.0, e.aerial_perspective_max_distance_m, 1.0, "");
  }
  if (problem.empty() && q->distance_m > 0.0) {
    const QueryGeometry g = MakeQueryGeometry(*q, bottom_radius_m);
    const double r = glm::length(g.camera), mu = glm::dot(g.camera, g.view) / r;
    const double object_altitude = glm::length(g.camera + g.view * q->distance_m) - bottom_radius_m;
    const double lo = scene.object_altitude_min_m, hi = scene.object_altitude_max_m;
    // A metre of slack: the altitude is recomputed from the geometry in double.
    if (object_altitude < lo - 1.0 || object_altitude > hi + 1.0) {
      problem = "the object's altitude " + FormatNumber(std::round(object_altitude)) +
                " m is outside the scene's objects [" + FormatNumber(lo) + ", " + FormatNumber(hi) + "]";
      const double camera_altitude = r - bottom_radius_m;
      if (clamp && camera_altitude >= lo - 1.0 && camera_altitude <= hi + 1.0) {
        // The object moves back along the view to where the ray first leaves
        // the objects' shell: the root of |camera + d view| = bottom + bound,
        // d^2 + 2 r mu d + r^2 - (bottom + bound)^2 = 0, nearest the camera.
        const double bound = bottom_radius_m + (object_altitude > hi ? hi : lo);
        const double discriminant = std::max(0.0, r * r * (mu * mu - 1.0) + bound * bound);
        const double moved = object_altitude > hi ? -r * mu + std::sqrt(discriminant)
                                                  : -r * mu - std::sqrt(discriminant);
        clamped->push_back(problem + ", distance_m " + FormatNumber(q->distance_m) + " clamped to " +
                           FormatNumber(std::max(0.0, moved)));
        q->distance_m = std::max(0.0, moved);
        problem.clear();
      }
    }
  }
  return problem;
}

std::string SceneToJson(const Scene& scene) {
  const SceneEffects& e = scene.effects;
  auto precision = [](bool half) { return half ? "half" : "float"; };
  const nlohmann::ordered_json j = {
      {"name", scene.name},
      {"description", scene.description},
      {"effects",
       {{"sky", e.sky},
        {"aerial_perspective", e.aerial_perspective},
        {"aerial_perspective_max_distance_m", e.aerial_perspective_max_distance_m},
        {"sun_transmittance", e.sun_transmittance},
        {"ground_irradiance", e.ground_irradiance},
        {"sharp_sun_halo", e.sharp_sun_halo},
        {"space_views", e.space_views}}},
      {"camera_altitude_m", {scene.camera_altitude_min_m, scene.camera_altitude_max_m}},
      {"object_altitude_m", {scene.object_altitude_min_m, scene.object_altitude_max_m}},
      {"sun_zenith_deg", {scene.sun_zenith_min_deg, scene.sun_zenith_max_deg}},
      {"precision",
       {{"transmittance", precision(scene.precision.transmittance_half)},
        {"irradiance", precision(scene.precision.irradiance_half)},
        {"scattering", precision(scene.precision.scattering_half)},
        {"single_mie_scattering", precision(scene.precision.single_mie_scattering_half)}}},
      {"formats", scene.formats}};
  return j.dump();
}

Scene SceneFromJson(const std::string& json_text) {
  try {
    return SceneFromJsonObject(nlohmann::json::parse(json_text));
  } catch (const nlohmann::json::exception& e) {
    throw InputError(std::string("malformed scene: ") + e.what());
  }
}

}  // namespace skybake
