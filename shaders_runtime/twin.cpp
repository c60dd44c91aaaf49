#include "shaders_runtime/twin.h"

#include <string>

#include "core/errors.h"
#include "shaders_runtime/runtime.h"

namespace skybake {

using glsl::vec3;
using glsl::vec4;

namespace {

// A table the set does not hold is null: sampling an empty texture would
// read outside its (empty) texel array.
const glsl::Texture* Present(const glsl::Texture* table) { return table && !table->empty() ? table : nullptr; }

template <typename Sampler>
void Require(const Sampler& sampler, const char* table, const char* function) {
  if (!sampler.texture)
    throw InternalError(std::string("the CPU twin has no ") + table + " table for " + function +
                        " (the set leaves it out)");
}

}  // namespace

Twin::Twin(const TwinTables& tables)
    : tables_(tables),
      transmittance_{tables.transmittance},
      scattering_{Present(tables.scattering)},
      // When single Mie is packed into alpha the runtime never samples it.
      single_mie_{Present(tables.single_mie_scattering) ? tables.single_mie_scattering : Present(tables.scattering)},
      irradiance_{Present(tables.irradiance)} {
  if (!Present(tables.transmittance)) throw InternalError("the CPU twin needs the transmittance table");
}

vec3 Twin::SkyRadiance(const vec3& camera, const vec3& view_ray, const vec3& sun_direction,
                       vec3* transmittance) const {
  Require(scattering_, "scattering", "GetSkyRadiance");
  vec3 t;
  vec3 radiance = glsl::GetSkyRadiance(tables_.parameters, transmittance_, scattering_, single_mie_, camera,
                                       view_ray, sun_direction, t);
  if (transmittance) *transmittance = t;
  return radiance;
}

vec3 Twin::SkyRadianceToPoint(const vec3& camera, const vec3& point, const vec3& sun_direction,
                              vec3* transmittance) const {
  Require(scattering_, "scattering", "GetSkyRadianceToPoint");
  vec3 t;
  vec3 radiance = glsl::GetSkyRadianceToPoint(tables_.parameters, transmittance_, scattering_, single_mie_, camera,
                                              point, sun_direction, t);
  if (transmittance) *transmittance = t;
  return radiance;
}

vec3 Twin::SunAndSkyIrradiance(const vec3& point, const vec3& normal, const vec3& sun_direction,
                               vec3* sky_irradiance) const {
  Require(irradiance_, "irradiance", "GetSunAndSkyIrradiance");
  vec3 sky;
  vec3 sun = glsl::GetSunAndSkyIrradiance(tables_.parameters, transmittance_, irradiance_, point, normal,
                                          sun_direction, sky);
  if (sky_irradiance) *sky_irradiance = sky;
  return sun;
}

vec3 Twin::SolarRadiance() const { return glsl::GetSolarRadiance(tables_.parameters); }

glsl::Texture Twin::SkyView(const vec3& camera, const vec3& sun_direction) const {
  Require(scattering_, "scattering", "GetSkyViewRadiance");
  glsl::Texture sky_view(glsl::SKY_VIEW_WIDTH, glsl::SKY_VIEW_HEIGHT);
  for (int y = 0; y < sky_view.height; ++y) {
    for (int x = 0; x < sky_view.width; ++x) {
      glsl::vec2 uv((x + 0.5) / sky_view.width, (y + 0.5) / sky_view.height);
      vec3 radiance =
          glsl::GetSkyViewRadiance(tables_.parameters, scattering_, single_mie_, camera, sun_direction, uv);
      sky_view.Store(x, y, 0, vec4(radiance, 1.0));
    }
  }
  return sky_view;
}

vec3 Twin::SkyRadianceFromSkyView(const glsl::Texture& sky_view, const vec3& camera, const vec3& view_ray,
                                  const vec3& sun_direction, vec3* transmittance) const {
  vec3 t;
  vec3 radiance = glsl::GetSkyRadianceFromSkyView(tables_.parameters, transmittance_, glsl::sampler2D{&sky_view},
                                                  camera, view_ray, sun_direction, t);
  if (transmittance) *transmittance = t;
  return radiance;
}

vec3 Twin::AerialPerspectiveVoxel(const vec3& camera, const vec3& view_ray, double w, const vec3& sun_direction,
                                  vec3* optical_depth) const {
  Require(scattering_, "scattering", "GetAerialPerspectiveVoxel");
  vec3 depth;
  vec3 radiance = glsl::GetAerialPerspectiveVoxel(tables_.parameters, transmittance_, scattering_, single_mie_,
                                                  camera, view_ray, w, sun_direction, depth);
  if (optical_depth) *optical_depth = depth;
  return radiance;
}

vec3 Twin::SkyRadianceToPointFromVolume(const glsl::Texture& radiance, const glsl::Texture& optical_depth,
                                        const glsl::vec2& screen_uv, double distance, vec3* transmittance) {
  vec3 t;
  vec3 value = glsl::GetSkyRadianceToPointFromVolume(glsl::sampler3D{&radiance}, glsl::sampler3D{&optical_depth},
                                                     screen_uv, distance, t);
  if (transmittance) *transmittance = t;
  return value;
}

vec4 Twin::Scattering(double r, double mu, double mu_s, double nu, bool ray_intersects_ground) const {
  Require(scattering_, "scattering", "GetScattering");
  return glsl::GetScattering(tables_.parameters, scattering_, r, mu, mu_s, nu, ray_intersects_ground);
}

vec3 Twin::CombinedScattering(double r, double mu, double mu_s, double nu, bool ray_intersects_ground,
                              vec3* single_mie_scattering) const {
  Require(scattering_, "scattering", "GetCombinedScattering");
  return glsl::GetCombinedScattering(tables_.parameters, scattering_, single_mie_, r, mu, mu_s, nu,
                                     ray_intersects_ground, *single_mie_scattering);
}

vec3 Twin::OpticalDepthToTop(double r, double mu) const {
  return glsl::GetOpticalDepthToTopAtmosphereBoundary(tables_.parameters, transmittance_, r, mu);
}

vec3 Twin::Irradiance(double r, double mu_s) const {
  Require(irradiance_, "irradiance", "GetIrradiance");
  return glsl::GetIrradiance(tables_.parameters, irradiance_, r, mu_s);
}

}  // namespace skybake
