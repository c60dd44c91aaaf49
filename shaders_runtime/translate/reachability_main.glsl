// A compute main() that calls every entry point of the runtime, so that
// spirv-cross (which emits only the functions reachable from an entry point)
// translates all of them. translate.mjs drops it, and the resources it
// declares, from the translated files. Values come from a buffer so that
// nothing is folded away.
layout(binding = 0) uniform sampler2D transmittance_texture;
layout(binding = 1) uniform sampler3D scattering_texture;
layout(binding = 2) uniform sampler3D single_mie_scattering_texture;
layout(binding = 3) uniform sampler2D irradiance_texture;
layout(binding = 5) uniform sampler2D sky_view_texture;
layout(binding = 6) uniform sampler3D aerial_perspective_radiance;
layout(binding = 7) uniform sampler3D aerial_perspective_optical_depth;
layout(std430, binding = 4) buffer Values { vec4 values[]; };
layout(local_size_x = 1) in;
void main() {
  AtmosphereParameters atmosphere;
  vec3 transmittance = vec3(0.0), sky_irradiance = vec3(0.0), radiance = vec3(0.0);
#if SKYBAKE_HAS_SCATTERING_TEXTURE
  radiance += GetSkyRadiance(atmosphere, transmittance_texture, scattering_texture, single_mie_scattering_texture,
                             values[0].xyz, values[1].xyz, values[2].xyz, transmittance);
  radiance += GetSkyViewRadiance(atmosphere, scattering_texture, single_mie_scattering_texture, values[0].xyz,
                                 values[2].xyz, values[1].xy);
  radiance += GetSkyRadianceFromSkyView(atmosphere, transmittance_texture, sky_view_texture, values[0].xyz,
                                        values[1].xyz, values[2].xyz, transmittance);
#endif
#if SKYBAKE_HAS_AERIAL_PERSPECTIVE
  radiance += GetSkyRadianceToPoint(atmosphere, transmittance_texture, scattering_texture,
                                    single_mie_scattering_texture, values[0].xyz, values[3].xyz, values[2].xyz,
                                    transmittance);
  radiance += GetSkyRadianceToPointWithShadow(atmosphere, transmittance_texture, scattering_texture,
                                              single_mie_scattering_texture, values[0].xyz, values[3].xyz,
                                              values[3].w, values[2].xyz, transmittance);
  vec3 optical_depth;
  radiance += GetAerialPerspectiveVoxel(atmosphere, transmittance_texture, scattering_texture,
                                        single_mie_scattering_texture, values[0].xyz, values[1].xyz, values[3].w,
                                        values[2].xyz, optical_depth);
  radiance += optical_depth;
  radiance += GetSkyRadianceToPointFromVolume(aerial_perspective_radiance, aerial_perspective_optical_depth,
                                              values[1].xy, values[3].w, transmittance);
#endif
#if SKYBAKE_HAS_IRRADIANCE_TEXTURE
  radiance += GetSunAndSkyIrradiance(atmosphere, transmittance_texture, irradiance_texture, values[0].xyz,
                                     values[1].xyz, values[2].xyz, sky_irradiance);
#endif
  radiance += GetTransmittanceToSun(atmosphere, transmittance_texture, values[0].w, values[1].w);
  radiance += GetSolarRadiance(atmosphere);
  radiance += XyzToLinearSrgb(values[5].xyz);
  values[4].xyz = radiance + transmittance + sky_irradiance;
}
