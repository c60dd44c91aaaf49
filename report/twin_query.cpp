#include "report/twin_query.h"

namespace skybake::report {

glsl::vec3 QuerySkyRadiance(const Twin& twin, const Query& q, const QueryGeometry& g, glsl::vec3* transmittance) {
  return q.distance_m > 0.0 ? twin.SkyRadianceToPoint(g.camera, g.camera + g.view * q.distance_m, g.sun, transmittance)
                            : twin.SkyRadiance(g.camera, g.view, g.sun, transmittance);
}

}  // namespace skybake::report
