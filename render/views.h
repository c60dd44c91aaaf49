// Preview views of a baked atmosphere, rendered through the CPU twin of the
// GLSL runtime (so they show exactly what an engine using the snippet draws).
//
// Geometry: the planet centre at the origin, the observer above the point
// (0, 0, bottom_radius) with +z up; the sun direction is
// (sin sz cos az, sin sz sin az, cos sz) for sun zenith sz and azimuth az.
// Every view is `width` pixels wide:
//   fisheye   width x width: equidistant fisheye of the whole sky from the
//             ground: zenith at the centre, horizon on the rim (view zenith
//             proportional to the distance from the centre); azimuth 0 (the
//             +x axis) points right, azimuth 90 up in the image.
//   panorama  width x width/2: equirectangular; azimuth -180..180 left to
//             right (0 in the middle), elevation +90 at the top, -90 at the
//             bottom; rays below the horizon see the ground.
//   space     width x width: the planet from space, seen from above the
//             observer's point at 4 ground radii from the centre, framed to
//             hold the whole atmosphere.
//   aerial    width x width/4: aerial perspective: a pinhole camera (90 degree
//             horizontal field of view) looking horizontally toward the sun's
//             azimuth, pitched 7 degrees down, over the Lambertian ground.
// Ground radiance = albedo / pi * (sun + sky irradiance at the ground point)
// * transmittance to the camera + in-scattering between them. Where the sun is
// in view its disc (solar radiance * transmittance) is added; a disc smaller
// than a pixel is widened to one pixel with its radiance scaled down by the
// ratio of solid angles, so it keeps its irradiance and stays visible.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "shaders_runtime/glsl_shim.h"

namespace skybake {
class Twin;
}

namespace skybake::render {

enum class View { kFisheye, kPanorama, kSpace, kAerial };

// "fisheye", "panorama", "space", "aerial".
const char* ToString(View view);
bool ParseView(const std::string& name, View* view);
// Image size of a view `width` pixels wide (at least 1 pixel high).
int ViewHeight(View view, int width);

struct ViewSettings {
  int width = 512;
  double sun_zenith_deg = 30.0;
  double sun_azimuth_deg = 0.0;
  double camera_altitude_m = 100.0;  // ground views (fisheye, panorama, aerial)
  glsl::vec3 ground_albedo{0.1};     // Lambertian ground, per channel
};

// Linear RGB radiance (W m^-2 sr^-1 nm^-1 at the table's three wavelengths),
// row-major from the top row.
struct Image {
  int width = 0, height = 0;
  std::vector<float> rgb;  // 3 * width * height
  // Per pixel, 1 where it shows sky: in the ground views (fisheye,
  // panorama, aerial) where its ray misses the ground (the sun's disc
  // included); from space every pixel, as the planet is seen through its
  // atmosphere. RenderView fills it; other images may leave it empty.
  std::vector<std::uint8_t> sky;
  glsl::vec3 At(int x, int y) const {
    const float* p = &rgb[3 * (static_cast<std::size_t>(y) * width + x)];
    return glsl::vec3(p[0], p[1], p[2]);
  }
};

// Called from worker threads with the number of rows just finished.
using RowProgress = std::function<void(int rows)>;

// Renders `view` with oneTBB over rows. InputError for a width outside
// 1..16384.
Image RenderView(const Twin& twin, View view, const ViewSettings& settings, const RowProgress& progress = nullptr);

}  // namespace skybake::render
