// The runtime's texture() calls per evaluation, counted, not estimated:
// the runtime's sources compiled a further time with samplers that count their
// calls (texture lookups are the one thing the GLSL shim stands in for).
#include <glm/geometric.hpp>

#include "report/run_time_models.h"
#include "shaders_runtime/glsl_shim.h"
#include "shaders_runtime/primitives.h"

namespace skybake::glsl {
namespace {

struct CountingSampler2D {
  sampler2D sampler;
  long* calls;
};
struct CountingSampler3D {
  sampler3D sampler;
  long* calls;
};

vec4 texture(const CountingSampler2D& s, const vec2& uv) {
  ++*s.calls;
  return glsl::texture(s.sampler, uv);
}
vec4 texture(const CountingSampler3D& s, const vec3& uvw) {
  ++*s.calls;
  return glsl::texture(s.sampler, uvw);
}

#define IN(type) const type&
#define OUT(type) type&
#define TransmittanceTexture CountingSampler2D
#define ScatteringTexture CountingSampler3D
#define IrradianceTexture CountingSampler2D
#define SampleTexture2D texture
#define SampleTexture3D texture
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#include "shaders_runtime/geometry.glsl"
#include "shaders_runtime/table_mappings.glsl"
#include "shaders_runtime/shadow_edge.glsl"
#include "shaders_runtime/lookups.glsl"
#include "shaders_runtime/sky.glsl"
#include "shaders_runtime/aerial_perspective.glsl"
#pragma GCC diagnostic pop
#undef IN
#undef OUT
#undef TransmittanceTexture
#undef ScatteringTexture
#undef IrradianceTexture
#undef SampleTexture2D
#undef SampleTexture3D

}  // namespace
}  // namespace skybake::glsl

namespace skybake::report {

long CountTwinTextureCalls(const LutSet& luts, const ReferenceCase& c) {
  long calls = 0;
  const glsl::Texture* single_mie = luts.single_mie_scattering.empty() ? &luts.scattering : &luts.single_mie_scattering;
  glsl::CountingSampler2D transmittance{{&luts.transmittance}, &calls};
  glsl::CountingSampler2D irradiance{{&luts.irradiance}, &calls};
  glsl::CountingSampler3D scattering{{&luts.scattering}, &calls};
  glsl::CountingSampler3D mie{{single_mie}, &calls};
  QueryGeometry g = MakeQueryGeometry(c.query, luts.parameters.bottom_radius);
  glsl::vec3 transmittance_out, sky;
  if (c.query.has_normal) {
    glsl::GetSunAndSkyIrradiance(luts.parameters, transmittance, irradiance, g.camera, g.normal, g.sun, sky);
  } else if (c.query.distance_m > 0.0) {
    glsl::GetSkyRadianceToPoint(luts.parameters, transmittance, scattering, mie, g.camera,
                                g.camera + g.view * c.query.distance_m, g.sun, transmittance_out);
  } else {
    glsl::GetSkyRadiance(luts.parameters, transmittance, scattering, mie, g.camera, g.view, g.sun,
                         transmittance_out);
  }
  return calls;
}

}  // namespace skybake::report
