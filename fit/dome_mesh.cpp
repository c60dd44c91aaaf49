#include "fit/dome_mesh.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <sstream>

#include <nlohmann/json.hpp>

#include "core/constants.h"
#include "core/errors.h"
#include "core/version.h"
#include "fit/optical_path.h"

namespace skybake::fit {

namespace {


const Constituent* FindConstituent(const Atmosphere& atmosphere, const std::string& name) {
  for (const Constituent& c : atmosphere.constituents)
    if (c.name == name) return &c;
  return nullptr;
}

std::optional<double> ZenithLength(const Atmosphere& atmosphere, const Constituent& constituent,
                                          double altitude_m) {
  ColumnIntegrator integrator(constituent.density, atmosphere.bottom_radius_m, atmosphere.top_radius_m);
  return integrator.Sample(altitude_m, 1.0).OpticalLength();
}

template <typename T>
void AppendBytes(std::vector<std::uint8_t>* buffer, const std::vector<T>& values) {
  // glTF buffers are little-endian, as is every platform skybake builds on.
  size_t offset = buffer->size();
  buffer->resize(offset + values.size() * sizeof(T));
  if (!values.empty()) std::memcpy(buffer->data() + offset, values.data(), values.size() * sizeof(T));
}

}  // namespace

std::string Base64Encode(const std::vector<std::uint8_t>& bytes) {
  static const char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  for (size_t i = 0; i < bytes.size(); i += 3) {
    std::uint32_t n = std::uint32_t(bytes[i]) << 16;
    if (i + 1 < bytes.size()) n |= std::uint32_t(bytes[i + 1]) << 8;
    if (i + 2 < bytes.size()) n |= bytes[i + 2];
    out += kAlphabet[(n >> 18) & 63];
    out += kAlphabet[(n >> 12) & 63];
    out += i + 1 < bytes.size() ? kAlphabet[(n >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? kAlphabet[n & 63] : '=';
  }
  return out;
}

std::optional<DomeMesh> BuildDomeMesh(const Atmosphere& atmosphere, const FitSet& set,
                                      const DomeOptions& options, std::string* why_not) {
  if (options.rings < 1 || options.segments < 3)
    throw InputError("the dome needs at least 1 ring and 3 segments");
  if (set.air < 0) {
    *why_not = "no fitted Rayleigh-phase (air) constituent";
    return std::nullopt;
  }
  double thickness = atmosphere.top_radius_m - atmosphere.bottom_radius_m;
  if (!(options.altitude_m >= 0.0 && options.altitude_m < thickness))
  {
    char message[160];
    std::snprintf(message, sizeof(message), "dome altitude %g m is outside the atmosphere [0, %g) m",
                  options.altitude_m, thickness);
    throw InputError(message);
  }
  const ConstituentFit& air = set.constituents[set.air];
  const Constituent* air_constituent = FindConstituent(atmosphere, air.name);
  std::optional<double> air_length =
      air_constituent ? ZenithLength(atmosphere, *air_constituent, options.altitude_m) : std::nullopt;
  if (!air_length || !(*air_length > 0.0)) {
    *why_not = "the density of '" + air.name + "' is zero at the dome altitude, so its optical length is undefined";
    return std::nullopt;
  }
  DomeMesh mesh;
  mesh.air_name = air.name;
  mesh.altitude_m = options.altitude_m;
  mesh.air_zenith_optical_length_m = *air_length;

  const ConstituentFit* haze = set.haze >= 0 ? &set.constituents[set.haze] : nullptr;
  std::optional<double> haze_length;
  if (haze) {
    const Constituent* haze_constituent = FindConstituent(atmosphere, haze->name);
    if (haze_constituent) haze_length = ZenithLength(atmosphere, *haze_constituent, options.altitude_m);
    if (haze_length) mesh.haze_name = haze->name;
  }

  auto add_vertex = [&](double zenith_deg, double azimuth_rad) {
    double theta = zenith_deg * kPi / 180.0;
    double mu = zenith_deg >= 90.0 ? 0.0 : std::cos(theta);
    double air_m = air.surface.RelativeOpticalPath(mu, options.altitude_m);
    double radius = air_m * *air_length;
    double s = std::sin(theta);
    mesh.positions.push_back(static_cast<float>(radius * s * std::cos(azimuth_rad)));
    mesh.positions.push_back(static_cast<float>(radius * mu));
    mesh.positions.push_back(static_cast<float>(radius * s * std::sin(azimuth_rad)));
    mesh.zenith_deg.push_back(static_cast<float>(zenith_deg));
    if (!mesh.haze_name.empty()) {
      double haze_m = haze->surface.RelativeOpticalPath(mu, options.altitude_m);
      mesh.haze_air_ratio.push_back(static_cast<float>(haze_m * *haze_length / radius));
    }
  };
  add_vertex(0.0, 0.0);
  for (int i = 1; i <= options.rings; ++i) {
    double u = static_cast<double>(i) / options.rings;
    double zenith = i == options.rings ? 90.0 : 90.0 * (3.0 * u - u * u) / 2.0;
    for (int j = 0; j < options.segments; ++j) add_vertex(zenith, 2.0 * kPi * j / options.segments);
  }

  auto ring_vertex = [&](int ring, int j) -> std::uint32_t {
    return static_cast<std::uint32_t>(1 + (ring - 1) * options.segments + (j % options.segments));
  };
  auto add_triangle = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    // Wind so the face normal points at the observer (the origin).
    const float* p = mesh.positions.data();
    double e1[3], e2[3], centroid[3];
    for (int k = 0; k < 3; ++k) {
      e1[k] = p[3 * b + k] - p[3 * a + k];
      e2[k] = p[3 * c + k] - p[3 * a + k];
      centroid[k] = p[3 * a + k] + p[3 * b + k] + p[3 * c + k];
    }
    double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
    if (n[0] * centroid[0] + n[1] * centroid[1] + n[2] * centroid[2] > 0.0) std::swap(b, c);
    mesh.indices.insert(mesh.indices.end(), {a, b, c});
  };
  for (int j = 0; j < options.segments; ++j) add_triangle(0, ring_vertex(1, j), ring_vertex(1, j + 1));
  for (int i = 1; i < options.rings; ++i) {
    for (int j = 0; j < options.segments; ++j) {
      add_triangle(ring_vertex(i, j), ring_vertex(i + 1, j), ring_vertex(i + 1, j + 1));
      add_triangle(ring_vertex(i, j), ring_vertex(i + 1, j + 1), ring_vertex(i, j + 1));
    }
  }
  return mesh;
}

std::string ToObj(const DomeMesh& mesh, const std::string& provenance) {
  std::ostringstream o;
  std::string line = provenance;
  std::replace(line.begin(), line.end(), '\n', ' ');
  o << "# sky dome generated by skybake fit: " << line << "\n"
    << "# v: metres, y up, observer at the origin, at the fitted optical length of '" << mesh.air_name
    << "' (zenith optical length " << mesh.air_zenith_optical_length_m << " m at altitude " << mesh.altitude_m
    << " m)\n"
    << "# vt: u = haze/air optical length ratio"
    << (mesh.haze_name.empty() ? " (no haze: 0)" : " ('" + mesh.haze_name + "' / '" + mesh.air_name + "')")
    << ", v = zenith angle / 90 degrees\n"
    << "# faces wind counter-clockwise seen from the observer\n"
    << "o sky_dome\n";
  char buffer[128];
  for (size_t v = 0; v < mesh.vertex_count(); ++v) {
    std::snprintf(buffer, sizeof(buffer), "v %.9g %.9g %.9g\n", mesh.positions[3 * v], mesh.positions[3 * v + 1],
                  mesh.positions[3 * v + 2]);
    o << buffer;
  }
  for (size_t v = 0; v < mesh.vertex_count(); ++v) {
    double ratio = mesh.haze_air_ratio.empty() ? 0.0 : mesh.haze_air_ratio[v];
    std::snprintf(buffer, sizeof(buffer), "vt %.9g %.9g\n", ratio, mesh.zenith_deg[v] / 90.0);
    o << buffer;
  }
  for (size_t t = 0; t < mesh.indices.size(); t += 3) {
    std::uint32_t a = mesh.indices[t] + 1, b = mesh.indices[t + 1] + 1, c = mesh.indices[t + 2] + 1;
    o << "f " << a << "/" << a << " " << b << "/" << b << " " << c << "/" << c << "\n";
  }
  return o.str();
}

std::string ToGltf(const DomeMesh& mesh, const std::string& provenance) {
  using json = nlohmann::ordered_json;
  std::vector<std::uint8_t> buffer;
  AppendBytes(&buffer, mesh.positions);
  size_t positions_bytes = buffer.size();
  AppendBytes(&buffer, mesh.haze_air_ratio);
  size_t ratio_bytes = buffer.size() - positions_bytes;
  AppendBytes(&buffer, mesh.indices);
  size_t index_bytes = buffer.size() - positions_bytes - ratio_bytes;

  std::vector<float> lo(3, HUGE_VALF), hi(3, -HUGE_VALF);
  for (size_t v = 0; v < mesh.vertex_count(); ++v) {
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], mesh.positions[3 * v + k]);
      hi[k] = std::max(hi[k], mesh.positions[3 * v + k]);
    }
  }
  constexpr int kFloat = 5126, kUnsignedInt = 5125, kArrayBuffer = 34962, kElementArrayBuffer = 34963;
  json views = json::array(), accessors = json::array(), attributes;
  views.push_back({{"buffer", 0}, {"byteOffset", 0}, {"byteLength", positions_bytes}, {"target", kArrayBuffer}});
  accessors.push_back({{"bufferView", 0}, {"componentType", kFloat}, {"count", mesh.vertex_count()},
                       {"type", "VEC3"}, {"min", lo}, {"max", hi}});
  attributes["POSITION"] = 0;
  if (!mesh.haze_air_ratio.empty()) {
    views.push_back({{"buffer", 0}, {"byteOffset", positions_bytes}, {"byteLength", ratio_bytes},
                     {"target", kArrayBuffer}});
    accessors.push_back({{"bufferView", views.size() - 1}, {"componentType", kFloat},
                         {"count", mesh.vertex_count()}, {"type", "SCALAR"}});
    attributes["_HAZE_AIR_RATIO"] = accessors.size() - 1;
  }
  views.push_back({{"buffer", 0}, {"byteOffset", positions_bytes + ratio_bytes}, {"byteLength", index_bytes},
                   {"target", kElementArrayBuffer}});
  accessors.push_back({{"bufferView", views.size() - 1}, {"componentType", kUnsignedInt},
                       {"count", mesh.indices.size()}, {"type", "SCALAR"}});

  json extras = {{"air", mesh.air_name},
                 {"haze", mesh.haze_name.empty() ? json(nullptr) : json(mesh.haze_name)},
                 {"altitude_m", mesh.altitude_m},
                 {"air_zenith_optical_length_m", mesh.air_zenith_optical_length_m}};
  json gltf = {
      {"asset", {{"version", "2.0"}, {"generator", "skybake " SKYBAKE_VERSION}, {"extras", {{"generated_by", provenance}}}}},
      {"scene", 0},
      {"scenes", {{{"nodes", {0}}}}},
      {"nodes", {{{"mesh", 0}, {"name", "sky_dome"}}}},
      {"meshes",
       {{{"name", "sky_dome"},
         {"primitives", {{{"attributes", attributes}, {"indices", accessors.size() - 1}, {"mode", 4}}}},
         {"extras", extras}}}},
      {"buffers",
       {{{"byteLength", buffer.size()},
         {"uri", "data:application/octet-stream;base64," + Base64Encode(buffer)}}}},
      {"bufferViews", views},
      {"accessors", accessors}};
  return gltf.dump(1) + "\n";
}

}  // namespace skybake::fit
