// The GLSL subset in C++: types, built-in functions and texture sampling with
// the names the runtime's GLSL uses, in double precision. Included only through
// runtime.h. Texture sampling follows OpenGL's GL_LINEAR filtering with
// GL_CLAMP_TO_EDGE: texel centres at (i + 0.5) / size.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

#include <glm/common.hpp>
#include <glm/exponential.hpp>
#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "core/constants.h"
#include "core/large_buffer.h"

namespace skybake::glsl {

using Number = double;
using vec2 = glm::dvec2;
using vec3 = glm::dvec3;
using vec4 = glm::dvec4;
using bvec4 = glm::bvec4;

using glm::clamp;
using glm::dot;
using glm::exp;
using glm::length;
using glm::log;
using glm::max;
using glm::min;
using glm::mix;
using glm::normalize;
using glm::pow;
using glm::smoothstep;
using glm::step;
using std::abs;
using std::acos;
using std::cos;
using std::exp;
using std::floor;
using std::log;
using std::sin;
using std::sqrt;
// GLSL's two-argument arc tangent.
inline Number atan(Number y, Number x) { return std::atan2(y, x); }

constexpr Number PI = kPi;
constexpr int PHASE_NONE = 0;
constexpr int PHASE_HENYEY_GREENSTEIN = 1;
constexpr int PHASE_CORNETTE_SHANKS = 2;
constexpr int ALTITUDE_PROFILE_SIZE = 64;

// Same fields, names and meaning as the struct in definitions.glsl.
struct AtmosphereParameters {
  vec3 solar_irradiance{0.0};
  Number sun_angular_radius = 0.0;
  Number bottom_radius = 0.0;
  Number top_radius = 0.0;
  Number mu_s_min = -1.0;
  int mie_phase = PHASE_NONE;
  Number mie_g = 0.0;
  vec3 mie_to_rayleigh_scattering_ratio{0.0};
  int single_mie_in_scattering_alpha = 0;
  int transmittance_is_colour = 0;
  int transmittance_width = 0;
  int transmittance_height = 0;
  int scattering_r_size = 0;
  int scattering_mu_size = 0;
  int scattering_mu_s_size = 0;
  int scattering_nu_size = 0;
  Number scattering_r_min = 0.0;
  Number scattering_r_max = 0.0;
  Number scattering_mu_s_min = -1.0;
  Number scattering_mu_s_max = 1.0;
  int scattering_mu_s_split = 0;
  int irradiance_width = 0;
  int irradiance_height = 0;
  vec3 extinction_profile[ALTITUDE_PROFILE_SIZE] = {};
  vec3 mie_scattering_profile[ALTITUDE_PROFILE_SIZE] = {};
  vec3 rayleigh_scattering_profile[ALTITUDE_PROFILE_SIZE] = {};
};

// An RGBA float texture, x fastest, then y, then z (depth 1 for 2D).
struct Texture {
  int width = 0;
  int height = 0;
  int depth = 1;
  LargeBuffer<float> texels;

  Texture() = default;
  Texture(int w, int h, int d = 1)
      : width(w), height(h), depth(d), texels(std::size_t(4) * w * h * d, 0.0f) {}
  bool empty() const { return texels.empty(); }
  std::size_t Index(int x, int y, int z = 0) const {
    return std::size_t(4) * ((std::size_t(z) * height + y) * width + x);
  }
  vec4 Fetch(int x, int y, int z = 0) const {
    const float* t = &texels[Index(x, y, z)];
    return vec4(t[0], t[1], t[2], t[3]);
  }
  void Store(int x, int y, int z, const vec4& value) {
    float* t = &texels[Index(x, y, z)];
    t[0] = float(value.x);
    t[1] = float(value.y);
    t[2] = float(value.z);
    t[3] = float(value.w);
  }
};

struct sampler2D {
  const Texture* texture = nullptr;
};
struct sampler3D {
  const Texture* texture = nullptr;
};

namespace detail {
// GL_LINEAR weights for one axis under GL_CLAMP_TO_EDGE.
inline void LinearTaps(Number u, int size, int& i0, int& i1, Number& f) {
  Number x = u * size - 0.5;
  Number x0 = std::floor(x);
  f = x - x0;
  int i = static_cast<int>(std::max(-1.0, std::min(x0, Number(size))));
  i0 = std::clamp(i, 0, size - 1);
  i1 = std::clamp(i + 1, 0, size - 1);
}
}  // namespace detail

inline vec4 texture(const sampler2D& sampler, const vec2& uv) {
  const Texture& t = *sampler.texture;
  int x0, x1, y0, y1;
  Number fx, fy;
  detail::LinearTaps(uv.x, t.width, x0, x1, fx);
  detail::LinearTaps(uv.y, t.height, y0, y1, fy);
  return mix(mix(t.Fetch(x0, y0), t.Fetch(x1, y0), fx), mix(t.Fetch(x0, y1), t.Fetch(x1, y1), fx), fy);
}

inline vec4 texture(const sampler3D& sampler, const vec3& uvw) {
  const Texture& t = *sampler.texture;
  int x0, x1, y0, y1, z0, z1;
  Number fx, fy, fz;
  detail::LinearTaps(uvw.x, t.width, x0, x1, fx);
  detail::LinearTaps(uvw.y, t.height, y0, y1, fy);
  detail::LinearTaps(uvw.z, t.depth, z0, z1, fz);
  vec4 c0 = mix(mix(t.Fetch(x0, y0, z0), t.Fetch(x1, y0, z0), fx),
                mix(t.Fetch(x0, y1, z0), t.Fetch(x1, y1, z0), fx), fy);
  vec4 c1 = mix(mix(t.Fetch(x0, y0, z1), t.Fetch(x1, y0, z1), fx),
                mix(t.Fetch(x0, y1, z1), t.Fetch(x1, y1, z1), fx), fy);
  return mix(c0, c1, fz);
}

}  // namespace skybake::glsl
