#include "report/twin_query.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace skybake::report {

glsl::vec3 QuerySkyRadiance(const Twin& twin, const Query& q, const QueryGeometry& g, glsl::vec3* transmittance) {
  return q.distance_m > 0.0 ? twin.SkyRadianceToPoint(g.camera, g.camera + g.view * q.distance_m, g.sun, transmittance)
                            : twin.SkyRadiance(g.camera, g.view, g.sun, transmittance);
}

std::string SunZenithOutsideTables(const glsl::AtmosphereParameters& parameters, double sun_zenith_deg) {
  const double lowest_sun_deg = std::acos(std::clamp(parameters.mu_s_min, -1.0, 1.0)) * 180.0 / kPi;
  // 1e-9 degrees of slack: the lowest sun is read back from its cosine.
  if (sun_zenith_deg >= 0.0 && sun_zenith_deg <= lowest_sun_deg + 1e-9) return "";
  char text[96];
  std::snprintf(text, sizeof(text), "is outside the tables' range 0..%.2f degrees", lowest_sun_deg);
  return text;
}

}  // namespace skybake::report
