#include "shaders_runtime/twin.h"

#include "shaders_runtime/runtime.h"

namespace skybake {

using glsl::vec3;
using glsl::vec4;

Twin::Twin(const TwinTables& tables)
    : tables_(tables),
      transmittance_{tables.transmittance},
      scattering_{tables.scattering},
      // When single Mie is packed into alpha the runtime never samples it.
      single_mie_{tables.single_mie_scattering && !tables.single_mie_scattering->empty()
                      ? tables.single_mie_scattering
                      : tables.scattering},
      irradiance_{tables.irradiance} {}

vec3 Twin::SkyRadiance(const vec3& camera, const vec3& view_ray, const vec3& sun_direction,
                       vec3* transmittance) const {
  vec3 t;
  vec3 radiance = glsl::GetSkyRadiance(tables_.parameters, transmittance_, scattering_, single_mie_, camera,
                                       view_ray, sun_direction, t);
  if (transmittance) *transmittance = t;
  return radiance;
}

vec3 Twin::SkyRadianceToPoint(const vec3& camera, const vec3& point, const vec3& sun_direction,
                              vec3* transmittance) const {
  vec3 t;
  vec3 radiance = glsl::GetSkyRadianceToPoint(tables_.parameters, transmittance_, scattering_, single_mie_, camera,
                                              point, sun_direction, t);
  if (transmittance) *transmittance = t;
  return radiance;
}

vec3 Twin::SunAndSkyIrradiance(const vec3& point, const vec3& normal, const vec3& sun_direction,
                               vec3* sky_irradiance) const {
  vec3 sky;
  vec3 sun = glsl::GetSunAndSkyIrradiance(tables_.parameters, transmittance_, irradiance_, point, normal,
                                          sun_direction, sky);
  if (sky_irradiance) *sky_irradiance = sky;
  return sun;
}

vec3 Twin::SolarRadiance() const { return glsl::GetSolarRadiance(tables_.parameters); }

vec4 Twin::Scattering(double r, double mu, double mu_s, double nu, bool ray_intersects_ground) const {
  return glsl::GetScattering(tables_.parameters, scattering_, r, mu, mu_s, nu, ray_intersects_ground);
}

vec3 Twin::OpticalDepthToTop(double r, double mu) const {
  return glsl::GetOpticalDepthToTopAtmosphereBoundary(tables_.parameters, transmittance_, r, mu);
}

vec3 Twin::Irradiance(double r, double mu_s) const {
  return glsl::GetIrradiance(tables_.parameters, irradiance_, r, mu_s);
}

}  // namespace skybake
