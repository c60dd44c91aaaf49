// WGSL has no combined image samplers: for the WGSL translation the tables
// are separate textures, sampled with one linear clamp-to-edge sampler that
// the engine declares (`var skybake_linear_sampler: sampler`). The tables
// have one level, so level 0 equals GLSL's texture().
layout(binding = 0) uniform sampler skybake_linear_sampler;
#undef TransmittanceTexture
#undef ScatteringTexture
#undef IrradianceTexture
#undef SkyViewTexture
#undef AerialPerspectiveTexture
#undef SampleTexture2D
#undef SampleTexture3D
#define TransmittanceTexture texture2D
#define ScatteringTexture texture3D
#define IrradianceTexture texture2D
#define SkyViewTexture texture2D
#define AerialPerspectiveTexture texture3D
vec4 SampleTexture2D(texture2D table, vec2 uv) {
  return textureLod(sampler2D(table, skybake_linear_sampler), uv, 0.0);
}
vec4 SampleTexture3D(texture3D table, vec3 uvw) {
  return textureLod(sampler3D(table, skybake_linear_sampler), uvw, 0.0);
}
