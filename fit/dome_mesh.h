// The sky-dome mesh of Hoffman & Preetham: a tessellated hemisphere around
// the observer whose vertex in each direction lies at the fitted optical
// length of air, R_air(θ) = m_air(θ, h)·R_air(0, h), with the ratio
// R_haze(θ) / R_air(θ) as a per-vertex attribute so a shader can derive the
// haze optical length from the interpolated air one (the two-shell sky).
//
// "air" is the first fitted Rayleigh-phase constituent, "haze" the first
// fitted other scattering one (FitSet::air / haze). Coordinates in metres,
// y up, observer at the origin; triangles wind counter-clockwise seen from
// the observer (front faces point inward). Rings of constant zenith angle
// θ_i = 90°·(3u - u²)/2, u = i/rings, are 2-3 times closer at the horizon,
// where R changes fastest, than at the zenith; the pole is one vertex.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "bake/atmosphere.h"
#include "fit/sky_dome_fit.h"

namespace skybake::fit {

struct DomeOptions {
  double altitude_m = 0.0;  // observer altitude the dome is built for
  int rings = 32;           // zenith-angle steps from the pole to the horizon
  int segments = 64;        // azimuth steps
};

struct DomeMesh {
  std::string air_name;
  std::string haze_name;  // empty: no haze, no ratio attribute
  double altitude_m = 0.0;
  double air_zenith_optical_length_m = 0.0;
  std::vector<float> positions;       // x, y, z per vertex
  std::vector<float> zenith_deg;      // per vertex
  std::vector<float> haze_air_ratio;  // per vertex; empty without haze
  std::vector<std::uint32_t> indices; // triangles
  size_t vertex_count() const { return zenith_deg.size(); }
};

// Empty, with `why_not` set, when there is no air constituent in the set or
// the air density at the dome altitude is zero (its optical length is then
// undefined). A haze whose density is zero there only drops the ratio.
// InputError for a dome altitude outside the atmosphere or too few rings or
// segments.
std::optional<DomeMesh> BuildDomeMesh(const Atmosphere& atmosphere, const FitSet& set,
                                      const DomeOptions& options, std::string* why_not);

// Wavefront OBJ: positions as v, and as vt the haze/air ratio (u) and the
// zenith angle / 90° (v); u = 0 when there is no haze.
std::string ToObj(const DomeMesh& mesh, const std::string& provenance);
// glTF 2.0 JSON with the buffer embedded as a base64 data URI; the ratio is
// the custom attribute _HAZE_AIR_RATIO (float scalar) when there is haze.
std::string ToGltf(const DomeMesh& mesh, const std::string& provenance);

std::string Base64Encode(const std::vector<std::uint8_t>& bytes);

}  // namespace skybake::fit
