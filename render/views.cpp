#include "render/views.h"

#include <atomic>
#include <cmath>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/constants.h"
#include "core/errors.h"
#include "shaders_runtime/twin.h"

namespace skybake::render {

namespace {

using glsl::vec3;
constexpr double kDegree = kPi / 180.0;
constexpr double kSpaceDistanceInRadii = 4.0;
constexpr double kAerialPitchDeg = 7.0;

// Distance along the ray to the ground sphere, or -1 if the ray misses it.
double DistanceToGround(const vec3& camera, const vec3& dir, double radius) {
  double b = glsl::dot(camera, dir);
  double c = glsl::dot(camera, camera) - radius * radius;
  double disc = b * b - c;
  if (disc < 0.0) return -1.0;
  double t = -b - std::sqrt(disc);
  return t > 0.0 ? t : -1.0;
}

struct Shader {
  const Twin& twin;
  vec3 sun;
  vec3 albedo;
  vec3 solar_radiance;
  double cos_disc = 1.0;      // cosine of the drawn disc's angular radius
  double disc_scale = 1.0;    // solid angle of the sun / solid angle of the drawn disc

  Shader(const Twin& t, const ViewSettings& s, double pixel_angle)
      : twin(t), albedo(s.ground_albedo), solar_radiance(t.SolarRadiance()) {
    double sz = s.sun_zenith_deg * kDegree, az = s.sun_azimuth_deg * kDegree;
    sun = vec3(std::sin(sz) * std::cos(az), std::sin(sz) * std::sin(az), std::cos(sz));
    double sun_radius = t.parameters().sun_angular_radius;
    double disc_radius = std::max(sun_radius, pixel_angle);
    cos_disc = std::cos(disc_radius);
    disc_scale = (1.0 - std::cos(sun_radius)) / (1.0 - cos_disc);
  }

  // `hits_ground`: whether the ray ends on the ground.
  vec3 Radiance(const vec3& camera, const vec3& dir, bool* hits_ground) const {
    double bottom = twin.parameters().bottom_radius;
    double t = DistanceToGround(camera, dir, bottom);
    *hits_ground = t > 0.0;
    if (t > 0.0) {
      vec3 normal = glsl::normalize(camera + dir * t);
      vec3 point = normal * bottom;
      vec3 sky_irradiance;
      vec3 sun_irradiance = twin.SunAndSkyIrradiance(point, normal, sun, &sky_irradiance);
      vec3 transmittance;
      vec3 inscatter = twin.SkyRadianceToPoint(camera, point, sun, &transmittance);
      return albedo * (1.0 / kPi) * (sun_irradiance + sky_irradiance) * transmittance + inscatter;
    }
    vec3 transmittance;
    vec3 radiance = twin.SkyRadiance(camera, dir, sun, &transmittance);
    if (glsl::dot(dir, sun) > cos_disc) radiance += solar_radiance * transmittance * disc_scale;
    return radiance;
  }
};

}  // namespace

const char* ToString(View view) {
  switch (view) {
    case View::kFisheye: return "fisheye";
    case View::kPanorama: return "panorama";
    case View::kSpace: return "space";
    case View::kAerial: return "aerial";
  }
  return "?";
}

bool ParseView(const std::string& name, View* view) {
  for (View v : {View::kFisheye, View::kPanorama, View::kSpace, View::kAerial}) {
    if (name == ToString(v)) {
      *view = v;
      return true;
    }
  }
  return false;
}

int ViewHeight(View view, int width) {
  switch (view) {
    case View::kPanorama: return std::max(1, width / 2);
    case View::kAerial: return std::max(1, width / 4);
    default: return width;
  }
}

Image RenderView(const Twin& twin, View view, const ViewSettings& settings, const RowProgress& progress) {
  if (settings.width < 1 || settings.width > 16384)
    throw InputError("render: image width " + std::to_string(settings.width) + " is outside 1..16384");
  Image image;
  image.width = settings.width;
  image.height = ViewHeight(view, settings.width);
  image.rgb.assign(std::size_t(3) * image.width * image.height, 0.0f);
  image.sky.assign(std::size_t(image.width) * image.height, 0);
  const double w = image.width, h = image.height;
  const double bottom = twin.parameters().bottom_radius, top = twin.parameters().top_radius;
  const vec3 ground_camera(0.0, 0.0, bottom + settings.camera_altitude_m);

  // Camera, angular pixel size and the ray through image point (px, py);
  // false where the point shows nothing (outside the fisheye's circle).
  vec3 camera = ground_camera;
  double pixel_angle = 0.0;
  std::function<bool(double, double, vec3*)> ray;
  switch (view) {
    case View::kFisheye:
      pixel_angle = kPi / w;
      ray = [w](double px, double py, vec3* dir) {
        // Seen from below, looking up: image up is +y, image right is -x.
        double dx = (w / 2 - px) / (w / 2), dy = (w / 2 - py) / (w / 2);
        double rho = std::sqrt(dx * dx + dy * dy);
        if (rho > 1.0) return false;
        double theta = rho * kPi / 2, phi = std::atan2(dy, dx);
        *dir = vec3(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
        return true;
      };
      break;
    case View::kPanorama:
      pixel_angle = kPi / h;
      ray = [w, h](double px, double py, vec3* dir) {
        // Azimuth decreases left to right, as when turning to the right.
        double az = kPi * (1.0 - 2.0 * px / w), el = kPi / 2 - kPi * py / h;
        *dir = vec3(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
        return true;
      };
      break;
    case View::kSpace: {
      double distance = kSpaceDistanceInRadii * bottom;
      camera = vec3(0.0, 0.0, distance);
      double half_fov = std::asin(std::min(1.0, top / distance)) * 1.05;
      double tan_half = std::tan(half_fov);
      pixel_angle = 2.0 * half_fov / w;
      ray = [w, tan_half](double px, double py, vec3* dir) {
        double u = (2.0 * px / w - 1.0) * tan_half, v = (1.0 - 2.0 * py / w) * tan_half;
        *dir = glsl::normalize(vec3(u, v, -1.0));
        return true;
      };
      break;
    }
    case View::kAerial: {
      double az = settings.sun_azimuth_deg * kDegree, pitch = kAerialPitchDeg * kDegree;
      vec3 level(std::cos(az), std::sin(az), 0.0), right(std::sin(az), -std::cos(az), 0.0), up(0.0, 0.0, 1.0);
      vec3 forward = level * std::cos(pitch) - up * std::sin(pitch);
      vec3 camera_up = level * std::sin(pitch) + up * std::cos(pitch);
      pixel_angle = (kPi / 2) / w;
      ray = [w, h, forward, right, camera_up](double px, double py, vec3* dir) {
        double u = 2.0 * px / w - 1.0, v = (1.0 - 2.0 * py / h) * (h / w);
        *dir = glsl::normalize(forward + right * u + camera_up * v);
        return true;
      };
      break;
    }
  }

  const Shader shader(twin, settings, pixel_angle);
  tbb::parallel_for(tbb::blocked_range<int>(0, image.height), [&](const tbb::blocked_range<int>& rows) {
    for (int y = rows.begin(); y != rows.end(); ++y) {
      for (int x = 0; x < image.width; ++x) {
        vec3 dir;
        if (!ray(x + 0.5, y + 0.5, &dir)) continue;
        bool hits_ground = false;
        vec3 radiance = shader.Radiance(camera, dir, &hits_ground);
        const std::size_t pixel = static_cast<std::size_t>(y) * image.width + x;
        image.sky[pixel] = view == View::kSpace || !hits_ground ? 1 : 0;
        float* p = &image.rgb[3 * pixel];
        p[0] = static_cast<float>(radiance.x);
        p[1] = static_cast<float>(radiance.y);
        p[2] = static_cast<float>(radiance.z);
      }
    }
    if (progress) progress(static_cast<int>(rows.size()));
  });
  return image;
}

}  // namespace skybake::render
