// The independent reference: a Monte Carlo path tracer in the spherical
// atmosphere, answering the queries of `skybake eval` (shaders_runtime/query.h)
// with the quantities the tables are meant to hold, each with its error.
//
// * Sky radiance along a ray: light scattered into the ray between the camera
//   and the top of the atmosphere or the ground (or the point at distance d),
//   all orders (or up to max_order), including light reflected by the ground
//   somewhere before being scattered into the ray; not the radiance of the
//   ground point the ray itself ends on, not the sun's disc.
// * Transmittance of the ray (0 if it hits the ground and no distance is
//   given), by quadrature.
// * Sun irradiance on a surface (deterministic) and sky irradiance: radiance
//   from the hemisphere around the normal, ground included where the
//   hemisphere sees it.
//
// Method, validation and how to read the errors: docs/reference.md.
#pragma once

#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

#include <glm/vec3.hpp>

#include "bake/atmosphere.h"
#include "reference/direction_guide.h"
#include "reference/layered_medium.h"
#include "reference/sunlight_table.h"
#include "shaders_runtime/query.h"

namespace skybake::reference {

// How next-event estimation attenuates sunlight: exact optical depth by
// quadrature (no noise, the default), or ratio tracking (unbiased, noisy,
// cheaper per vertex).
enum class SunTransmittanceMethod { kQuadrature, kRatioTracking };

// Paths are traced in blocks: the first vertex of the paths of a block is
// stratified (1D along the view ray, 2D over the irradiance hemisphere), and
// standard errors come from the spread of the block means.
constexpr int kPathsPerBlock = 64;

// Safety stop for all-orders runs in media where paths could scatter almost
// forever (optical depth >> 1 and single-scattering albedo ~ 1); such paths
// are counted in Statistics::truncated.
constexpr int kMaxEventsPerPath = 100000;

struct Settings {
  // Paths per wavelength for each Monte Carlo estimate, rounded up to whole
  // blocks (at least two, so that a standard error exists).
  int64_t paths = 1 << 16;
  // Highest scattering order: the number of scattering events in the medium
  // plus ground reflections along a path, the final in-scattering into the
  // view ray included (single scattering is order 1; sunlight reflected by
  // the ground then scattered into the view is order 2, as in Bruneton's
  // scheme). 0: all orders.
  int max_order = 0;
  uint64_t seed = 1;
  int threads = 0;  // 0: all cores; results do not depend on it
  SunTransmittanceMethod sun_transmittance = SunTransmittanceMethod::kQuadrature;

  int64_t Blocks() const;
  // InputError naming the setting if a value is out of range.
  void Validate() const;
};

// A Monte Carlo estimate per wavelength and its standard error (the standard
// deviation of the estimate itself, not of one path).
struct Estimate {
  Spectrum mean{0.0};
  Spectrum standard_error{0.0};
};

struct Statistics {
  int64_t paths = 0;      // all estimators and wavelengths
  int64_t vertices = 0;   // scattering and ground-reflection vertices
  int64_t truncated = 0;  // paths stopped by kMaxEventsPerPath
  double seconds = 0.0;
};

struct Result {
  Estimate radiance;
  Spectrum transmittance{0.0};
  Spectrum transmittance_error{0.0};  // estimated bound from the quadrature
  bool has_irradiance = false;
  Spectrum sun_irradiance{0.0};
  Spectrum sun_irradiance_error{0.0};  // estimated bound from the quadrature
  Estimate sky_irradiance;
  Statistics statistics;
};

// A query in world terms: positions relative to the planet centre in metres,
// unit directions. The sun is a directional source.
struct RayQuery {
  glm::dvec3 camera{0.0};
  glm::dvec3 view{0.0, 0.0, 1.0};
  glm::dvec3 sun{0.0, 0.0, 1.0};
  // 0: the whole ray; > 0: the segment to the point at this distance
  // (clipped where the ray leaves the atmosphere or meets the ground).
  double distance_m = 0.0;
  bool has_normal = false;
  glm::dvec3 normal{0.0, 0.0, 1.0};
};

// The geometry of MakeQueryGeometry, with a camera below the ground moved up
// onto it (as `skybake eval` does).
RayQuery MakeRayQuery(const Query& query, double bottom_radius_m);

class PathTracer {
 public:
  // InputError if the atmosphere is not valid.
  explicit PathTracer(const Atmosphere& atmosphere);

  const LayeredMedium& medium() const { return medium_; }

  // `stream` separates the random numbers of queries evaluated with the same
  // seed (the CLI passes the row number); the result is a pure function of
  // (atmosphere, query, settings without threads, stream).
  Result Evaluate(const Query& query, const Settings& settings, uint64_t stream = 0) const;
  Result Evaluate(const RayQuery& query, const Settings& settings, uint64_t stream = 0) const;

  // Direct sunlight: solar irradiance x visible fraction of the disc x
  // transmittance to the top along the sun direction (along the horizon ray
  // for a disc centre below the horizon), for a camera anywhere.
  Spectrum SunTransmittance(const glm::dvec3& point, const glm::dvec3& sun, Spectrum* error) const;

 private:
  // The twilight direction guides per wavelength, built at the first query
  // that needs them.
  struct GuideFields {
    std::once_flag built;
    std::vector<DirectionGuideField> per_wavelength;
  };
  const std::vector<DirectionGuideField>& TwilightGuides() const;

  LayeredMedium medium_;
  SunlightTable sunlight_;  // where to look for sunlit scattering
  std::shared_ptr<GuideFields> guides_ = std::make_shared<GuideFields>();
};

}  // namespace skybake::reference
