// The per-frame tables (shaders_runtime/per_frame.glsl) in the CPU twin: the
// sky view and the aerial-perspective volume give back the direct lookups
// they hold at their texels, and between texels they stay within stated
// bounds of the direct lookups (GetSkyRadiance, GetSkyRadianceToPoint) on
// the default Earth bake, over the views the runtime's cost is measured on
// (docs/runtime_cost.md): the sky from 1 m and 10 km, aerial perspective from
// 300 m to points 0.1-50 km away, the sun at 30, 80, 88, 93 and 98 degrees.
// The errors are printed per group; docs/runtime_cost.md quotes them.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "bake/bake.h"
#include "bake/config.h"
#include "shaders_runtime/runtime.h"
#include "shaders_runtime/twin.h"

namespace skybake {
namespace {

using glsl::vec2;
using glsl::vec3;

constexpr double kDegree = 3.14159265358979323846 / 180.0;
const double kSunZeniths[] = {30.0, 80.0, 88.0, 93.0, 98.0};

const LutSet& DefaultEarth() {
  static const LutSet luts = Bake(LoadAtmosphere("earth"), BakeSettings());
  return luts;
}

vec3 Direction(double zenith, double azimuth) {
  return vec3(std::sin(zenith) * std::cos(azimuth), std::sin(zenith) * std::sin(azimuth), std::cos(zenith));
}

// Errors of one group of views: the largest absolute difference of any
// channel over the largest value of that channel in the view, and the
// relative differences (RMS and largest) where the direct value is at least
// a hundredth of that largest value (darker pixels are counted by the first).
struct Errors {
  double max_over_view_max = 0.0;
  double sum_squares = 0.0;
  double max_relative = 0.0;
  long counted = 0;

  void Add(const std::vector<vec3>& per_frame, const std::vector<vec3>& direct) {
    vec3 view_max(0.0);
    for (const vec3& v : direct) view_max = glm::max(view_max, v);
    for (std::size_t i = 0; i < direct.size(); ++i) {
      for (int c = 0; c < 3; ++c) {
        if (view_max[c] <= 0.0) continue;
        double difference = std::abs(per_frame[i][c] - direct[i][c]);
        max_over_view_max = std::max(max_over_view_max, difference / view_max[c]);
        if (direct[i][c] >= 0.01 * view_max[c]) {
          double relative = difference / direct[i][c];
          sum_squares += relative * relative;
          max_relative = std::max(max_relative, relative);
          ++counted;
        }
      }
    }
  }
  double Rms() const { return counted ? std::sqrt(sum_squares / counted) : 0.0; }
  void Print(const char* what) const {
    std::printf("%-44s RMS %.2e  max %.2e  max |difference| / view max %.2e\n", what, Rms(), max_relative,
                max_over_view_max);
  }
};

TEST(SkyView, RaysOfItsTexelsMapBackToThem) {
  const glsl::AtmosphereParameters& p = DefaultEarth().parameters;
  const vec3 sun = Direction(60.0 * kDegree, 0.0);
  for (double altitude : {1.0, 10000.0, 59000.0}) {
    const vec3 camera(0.0, 0.0, p.bottom_radius + altitude);
    for (int y = 0; y < glsl::SKY_VIEW_HEIGHT; ++y) {
      for (int x = 0; x < glsl::SKY_VIEW_WIDTH; x += 7) {
        const vec2 uv((x + 0.5) / glsl::SKY_VIEW_WIDTH, (y + 0.5) / glsl::SKY_VIEW_HEIGHT);
        bool ground;
        const vec3 ray = glsl::GetSkyViewRay(p, camera, sun, uv, ground);
        ASSERT_NEAR(glm::length(ray), 1.0, 1e-12);
        ASSERT_EQ(ground, y < glsl::SKY_VIEW_HEIGHT / 2) << "altitude " << altitude << " row " << y;
        // The outer rows are the horizon, which either half may claim.
        const double r = glm::length(camera), mu = glm::dot(camera, ray) / r;
        if (y != 0 && y != glsl::SKY_VIEW_HEIGHT - 1) {
          ASSERT_EQ(glsl::RayIntersectsGround(p, r, mu), ground) << "altitude " << altitude << " row " << y;
        }
        double theta, phi;
        glsl::GetSkyViewAngles(camera, ray, sun, theta, phi);
        const vec2 back = glsl::GetSkyViewUvFromAngles(p, r, theta, phi, ground);
        // The rows next to the middle are the nadir and the zenith, where
        // the azimuth is undefined.
        if (std::abs(y + 0.5 - glsl::SKY_VIEW_HEIGHT / 2) > 1.0) {
          EXPECT_NEAR(back.x, uv.x, 1e-9) << "altitude " << altitude << " texel " << x << ", " << y;
        }
        EXPECT_NEAR(back.y, uv.y, 1e-9) << "altitude " << altitude << " texel " << x << ", " << y;
      }
    }
  }
}

// Between texels the sky view is bilinear in (azimuth, the mu axis's unit
// x) where the direct lookup follows the sky; at the horizon the two halves
// are never blended.
TEST(SkyView, StaysCloseToTheDirectLookup) {
  const LutSet& luts = DefaultEarth();
  const Twin twin(MakeTwinTables(luts));
  const double bottom = luts.parameters.bottom_radius;
  Errors all;
  for (double altitude : {1.0, 10000.0}) {
    for (double sun_zenith : kSunZeniths) {
      const vec3 camera(0.0, 0.0, bottom + altitude);
      const vec3 sun = Direction(sun_zenith * kDegree, 0.0);
      const glsl::Texture sky_view = twin.SkyView(camera, sun);
      std::vector<vec3> per_frame, direct;
      // Directions off the texels' own: 181 zeniths x 97 azimuths.
      for (int i = 0; i < 181; ++i) {
        for (int j = 0; j < 97; ++j) {
          const vec3 ray = Direction((i + 0.37) / 181.0 * 180.0 * kDegree, (j + 0.61) / 97.0 * 360.0 * kDegree);
          vec3 t_frame, t_direct;
          per_frame.push_back(twin.SkyRadianceFromSkyView(sky_view, camera, ray, sun, &t_frame));
          direct.push_back(twin.SkyRadiance(camera, ray, sun, &t_direct));
          ASSERT_EQ(t_frame, t_direct);
        }
      }
      Errors view;
      view.Add(per_frame, direct);
      all.Add(per_frame, direct);
      char what[96];
      std::snprintf(what, sizeof what, "sky view, %5.0f m, sun %2.0f deg:", altitude, sun_zenith);
      view.Print(what);
      // Measured when this was written (docs/runtime_cost.md): RMS up to
      // 1.5e-2, the largest difference 1.9e-2 of the view's largest value;
      // the bounds give a margin of about 1.5.
      EXPECT_LT(view.Rms(), 0.022) << what;
      EXPECT_LT(view.max_over_view_max, 0.03) << what;
    }
  }
  all.Print("sky view, all:");
}

// A 90-degree frustum pitched 10 degrees down from the horizontal at
// azimuth `azimuth` from the sun's, for a camera on the z axis: the unit ray
// through screen point uv in [0, 1]^2.
vec3 FrustumRay(double azimuth, const vec2& uv) {
  const double pitch = -10.0 * kDegree;
  const vec3 forward = Direction(90.0 * kDegree - pitch, azimuth);
  const vec3 right = glm::normalize(glm::cross(forward, vec3(0.0, 0.0, 1.0)));
  const vec3 up = glm::cross(right, forward);
  return glm::normalize(forward + (2.0 * uv.x - 1.0) * right + (2.0 * uv.y - 1.0) * up);
}

TEST(AerialPerspectiveVolume, StaysCloseToTheDirectLookup) {
  const LutSet& luts = DefaultEarth();
  const Twin twin(MakeTwinTables(luts));
  const glsl::AtmosphereParameters& p = luts.parameters;
  const vec3 camera(0.0, 0.0, p.bottom_radius + 300.0);
  const int froxels = 32, slices = glsl::AERIAL_PERSPECTIVE_SLICES;
  Errors all;
  for (double sun_zenith : kSunZeniths) {
    const vec3 sun = Direction(sun_zenith * kDegree, 0.0);
    for (double azimuth : {0.0, 120.0 * kDegree}) {
      glsl::Texture radiance(froxels, froxels, slices), optical_depth(froxels, froxels, slices);
      for (int z = 0; z < slices; ++z) {
        for (int y = 0; y < froxels; ++y) {
          for (int x = 0; x < froxels; ++x) {
            const vec3 ray = FrustumRay(azimuth, vec2((x + 0.5) / froxels, (y + 0.5) / froxels));
            vec3 depth;
            radiance.Store(x, y, z, glsl::vec4(twin.AerialPerspectiveVoxel(camera, ray, (z + 0.5) / slices, sun, &depth), 1.0));
            optical_depth.Store(x, y, z, glsl::vec4(depth, 1.0));
          }
        }
      }
      // Pixels of a 61 x 61 screen, each at a distance from 100 m to 50 km
      // (log-spaced through the pixels), on the ground where that is nearer.
      std::vector<vec3> per_frame, direct, t_frame, t_direct, per_frame_ground, direct_ground, per_frame_air, direct_air;
      for (int i = 0; i < 61 * 61; ++i) {
        const vec2 uv((i % 61 + 0.5) / 61.0, (i / 61 + 0.5) / 61.0);
        const vec3 ray = FrustumRay(azimuth, uv);
        double distance = 100.0 * std::pow(500.0, std::fmod(i * 0.618034, 1.0));
        const double r = glm::length(camera), mu = glm::dot(camera, ray) / r;
        if (glsl::RayIntersectsGround(p, r, mu))
          distance = std::min(distance, glsl::DistanceToBottomAtmosphereBoundary(p, r, mu));
        vec3 t1, t2;
        per_frame.push_back(Twin::SkyRadianceToPointFromVolume(radiance, optical_depth, uv, distance, &t1));
        direct.push_back(twin.SkyRadianceToPoint(camera, camera + ray * distance, sun, &t2));
        const bool on_ground = glsl::RayIntersectsGround(p, r, mu);
        (on_ground ? per_frame_ground : per_frame_air).push_back(per_frame.back());
        (on_ground ? direct_ground : direct_air).push_back(direct.back());
        t_frame.push_back(t1);
        t_direct.push_back(t2);
      }
      Errors view, transmittance, ground, air;
      view.Add(per_frame, direct);
      ground.Add(per_frame_ground, direct_ground);
      air.Add(per_frame_air, direct_air);
      transmittance.Add(t_frame, t_direct);
      all.Add(per_frame, direct);
      char what[96];
      std::snprintf(what, sizeof what, "aerial volume, sun %2.0f deg, azimuth %3.0f:", sun_zenith, azimuth / kDegree);
      view.Print(what);
      ground.Print("  points on the ground:");
      air.Print("  points in the air:");
      transmittance.Print("  transmittance:");
      // Measured when this was written (docs/runtime_cost.md): RMS up to
      // 3.4e-2, the largest difference 0.24 of the view's largest value, the
      // transmittance within 2.2e-2; the bounds give a margin of about 1.3.
      EXPECT_LT(view.Rms(), 0.045) << what;
      EXPECT_LT(view.max_over_view_max, 0.3) << what;
      EXPECT_LT(transmittance.max_relative, 0.03) << what;
    }
  }
  all.Print("aerial volume, all:");
}

}  // namespace
}  // namespace skybake
