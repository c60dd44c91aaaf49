// Scene files: what a renderer uses of a bake (effects, camera and object
// altitudes, sun range, precision, formats), so that the bake writes only the
// tables, channels and shader functions the scene needs and spends the
// scattering table's mu_s texels on the suns the scene can show. The file
// format is documented in examples/scenes/README.md.
//
// Errors are one-line InputErrors (exit 2) naming the file and the key path,
// as for atmosphere files (bake/config.h).
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "bake/atmosphere.h"
#include "shaders_runtime/query.h"

namespace skybake {

struct SceneEffects {
  bool sky = true;
  bool aerial_perspective = true;
  double aerial_perspective_max_distance_m = 0.0;  // > 0 when aerial_perspective
  bool sun_transmittance = true;
  bool ground_irradiance = true;
  bool sharp_sun_halo = true;  // single Mie in its own table (full colour at the sun)
  bool space_views = true;     // cameras above the top of the atmosphere
};

// Pixel type per table, "float" or "half".
struct ScenePrecision {
  bool transmittance_half = false;
  bool irradiance_half = false;
  bool scattering_half = false;
  bool single_mie_scattering_half = false;
};

struct Scene {
  std::string name;
  std::string description;
  SceneEffects effects;
  // Altitudes above the ground, metres; object altitudes are those of the
  // points aerial perspective is computed to.
  double camera_altitude_min_m = 0.0, camera_altitude_max_m = 0.0;
  double object_altitude_min_m = 0.0, object_altitude_max_m = 0.0;
  // Sun zenith angles the scene shows, degrees.
  double sun_zenith_min_deg = 0.0, sun_zenith_max_deg = 180.0;
  ScenePrecision precision;
  std::vector<std::string> formats = {"exr", "ktx2"};
};

// Parses and validates a scene file. `source_name` prefixes error messages.
Scene ParseScene(std::string_view toml_text, const std::string& source_name);
// Reads a scene file: IoError if unreadable, InputError if invalid.
Scene LoadScene(const std::string& path);

// Checks the scene against the planet it is baked for (altitudes inside the
// atmosphere unless space_views, ...): InputError naming the scene.
void ValidateSceneForAtmosphere(const Scene& scene, const Atmosphere& atmosphere, const std::string& source_name);

// A table left out of a scene's bake and why.
struct OmittedTable {
  std::string table;
  std::string reason;
};

// What a scene keeps of a bake, derived from the scene and the atmosphere.
struct ScenePlan {
  bool transmittance = true;
  bool scattering = true;
  bool single_mie_scattering = true;  // a separate table; false: packed into alpha or not needed
  bool pack_single_mie_in_alpha = false;
  bool irradiance = true;
  bool aerial_perspective_functions = true;
  // The lowest sun the bake covers (the atmosphere's mu_s_min): that of the
  // points the scattering orders are computed for.
  double mu_s_min = -1.0;
  // Where the scattering tables are restricted to what the scene shows:
  // the altitudes of the cameras and objects and the sun cosines there
  // (ScatteringRange in bake/bake.h).
  bool restrict_scattering = false;
  double altitude_min_m = 0.0, altitude_max_m = 0.0;
  double table_mu_s_min = -1.0, table_mu_s_max = 1.0;
  bool sun_above_horizon = false;  // the scene's suns never set
  std::vector<OmittedTable> omitted;
};

ScenePlan PlanScene(const Scene& scene, const Atmosphere& atmosphere);

// Points the bake at the plan: the lowest sun (the atmosphere's mu_s_min,
// recorded as such in the manifest), the packing of single Mie and the
// scattering tables' ranges. A restricted table keeps the texel spacing
// along r of `settings`' table over the whole atmosphere (fewer texels over
// fewer altitudes) and all its mu_s texels (finer over fewer suns); the
// orders are computed on a grid over the whole atmosphere (ScatteringRange).
struct BakeSettings;
void ApplyScenePlan(const ScenePlan& plan, Atmosphere* atmosphere, BakeSettings* settings);

// Why `query` lies outside what the scene baked (empty if it is inside):
// an effect the scene left out, or a camera altitude, sun zenith, distance
// or object altitude outside its ranges. With `clamp`, the camera altitude,
// sun zenith and distance are moved into the ranges instead and each move is
// described in `clamped`: an object outside the objects' altitudes moves back
// along the view to where the ray leaves them. A left-out effect, or an
// object the view cannot bring into range (a camera outside the objects'
// altitudes), is still a problem.
std::string SceneQueryProblem(const Scene& scene, double bottom_radius_m, bool clamp, Query* query,
                              std::vector<std::string>* clamped);

// The scene as a JSON object in SI keys, as the manifest records it, and
// back; text rather than a JSON type keeps the JSON header out of bake.h
// (as ToJson in config.h). SceneFromJson throws InputError when malformed.
std::string SceneToJson(const Scene& scene);
Scene SceneFromJson(const std::string& json_text);

}  // namespace skybake
