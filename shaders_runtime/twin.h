// The CPU twin of the GLSL runtime: its run-time functions, compiled from
// the same sources, sampling tables held in
// memory. It is the reference behaviour for the GLSL snippet and what
// `skybake eval` answers with.
#pragma once

#include "shaders_runtime/glsl_shim.h"

namespace skybake {

// A scene's bake leaves tables out (bake/scene.h): a null or empty
// scattering or irradiance table is absent, and the twin refuses, with an
// InternalError, the functions that would sample it (as the GLSL snippet
// compiles them out), so a caller checks has_scattering() / has_irradiance().
struct TwinTables {
  glsl::AtmosphereParameters parameters;
  const glsl::Texture* transmittance = nullptr;
  const glsl::Texture* scattering = nullptr;
  const glsl::Texture* single_mie_scattering = nullptr;  // may be empty when packed into alpha
  const glsl::Texture* irradiance = nullptr;
};

class Twin {
 public:
  explicit Twin(const TwinTables& tables);

  const glsl::AtmosphereParameters& parameters() const { return tables_.parameters; }
  // SkyRadiance, SkyRadianceToPoint and Scattering need the scattering table;
  // SunAndSkyIrradiance and Irradiance the irradiance table.
  bool has_scattering() const { return scattering_.texture != nullptr; }
  bool has_irradiance() const { return irradiance_.texture != nullptr; }

  // Positions relative to the planet centre in metres; directions unit length.
  glsl::vec3 SkyRadiance(const glsl::vec3& camera, const glsl::vec3& view_ray, const glsl::vec3& sun_direction,
                         glsl::vec3* transmittance) const;
  glsl::vec3 SkyRadianceToPoint(const glsl::vec3& camera, const glsl::vec3& point,
                                const glsl::vec3& sun_direction, glsl::vec3* transmittance) const;
  glsl::vec3 SunAndSkyIrradiance(const glsl::vec3& point, const glsl::vec3& normal,
                                 const glsl::vec3& sun_direction, glsl::vec3* sky_irradiance) const;
  glsl::vec3 SolarRadiance() const;

  // The per-frame tables (per_frame.glsl) for one camera and sun: the sky
  // view, SKY_VIEW_WIDTH x SKY_VIEW_HEIGHT texels of GetSkyViewRadiance, and
  // its lookup; a texel of the aerial-perspective volume (radiance, and its
  // optical depth) along a froxel's ray at slice coordinate w, and the
  // volume's lookup.
  glsl::Texture SkyView(const glsl::vec3& camera, const glsl::vec3& sun_direction) const;
  glsl::vec3 SkyRadianceFromSkyView(const glsl::Texture& sky_view, const glsl::vec3& camera,
                                    const glsl::vec3& view_ray, const glsl::vec3& sun_direction,
                                    glsl::vec3* transmittance) const;
  glsl::vec3 AerialPerspectiveVoxel(const glsl::vec3& camera, const glsl::vec3& view_ray, double w,
                                    const glsl::vec3& sun_direction, glsl::vec3* optical_depth) const;
  static glsl::vec3 SkyRadianceToPointFromVolume(const glsl::Texture& radiance, const glsl::Texture& optical_depth,
                                                 const glsl::vec2& screen_uv, double distance,
                                                 glsl::vec3* transmittance);

  // Raw table lookups in the table's own coordinates.
  glsl::vec4 Scattering(double r, double mu, double mu_s, double nu, bool ray_intersects_ground) const;
  // The scattering table's rgb and single Mie's, whether the set keeps single
  // Mie in its own table or packed into alpha (GetCombinedScattering).
  glsl::vec3 CombinedScattering(double r, double mu, double mu_s, double nu, bool ray_intersects_ground,
                                glsl::vec3* single_mie_scattering) const;
  glsl::vec3 OpticalDepthToTop(double r, double mu) const;
  glsl::vec3 Irradiance(double r, double mu_s) const;

 private:
  TwinTables tables_;
  glsl::sampler2D transmittance_;
  glsl::sampler3D scattering_;
  glsl::sampler3D single_mie_;
  glsl::sampler2D irradiance_;
};

}  // namespace skybake
