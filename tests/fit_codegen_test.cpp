// Tests of what the sky-dome fit generates: the GLSL (glslangValidator, Mesa
// llvmpipe) against its C++ twin, and the dome mesh files.
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include <nlohmann/json.hpp>

#include "bake/atmosphere.h"
#include "bake/config.h"
#include "core/constants.h"
#include "core/errors.h"
#include "core/file_io.h"
#include "fit/codegen.h"
#include "fit/dome_mesh.h"
#include "fit/forms.h"
#include "fit/optical_path.h"
#include "fit/outputs.h"
#include "fit/quadrature.h"
#include "fit/query.h"
#include "fit/sky_dome_fit.h"
#include "fit/solver.h"
#include "fit_test_util.h"
#include "test_util.h"
#include "tests/gl_context.h"

namespace skybake::fit {
namespace {

namespace fs = std::filesystem;

// ---- small utilities ----

using testing::Lines;
using testing::RunCommand;
using testing::ShellQuote;
using testing::TempDir;
using testing::WriteText;

// ---- generated code ----

// Earth fitted with each form, merged into one set so both code paths are generated.
FitSet BothForms() {
  FitOptions chord_only, kasten_only;
  chord_only.forms = {FormKind::kChapmanChord};
  kasten_only.forms = {FormKind::kKasten};
  Atmosphere earth = Earth();
  FitSet set = FitAtmosphere(earth, {}, chord_only);
  FitSet kasten = FitAtmosphere(earth, {"rayleigh", "mie"}, kasten_only);
  for (ConstituentFit& c : kasten.constituents) {
    c.identifier += "_kasten";
    set.constituents.push_back(c);
  }
  return set;
}

std::vector<std::pair<double, double>> EvaluationPoints() {
  std::vector<std::pair<double, double>> points;  // (mu, altitude)
  for (double zenith : {0.0, 10.0, 45.0, 70.0, 80.0, 85.0, 88.0, 89.5, 90.0})
    for (double h : {0.0, 1234.5, 5000.0, 10000.0, 20000.0}) points.push_back({Mu(zenith), h});
  points.push_back({-0.3, 100.0});  // below the horizon: clamped
  return points;
}

TEST(Codegen, GlslCompilesWithGlslangInBothDialects) {
  if (std::string(SKYBAKE_GLSLANG_VALIDATOR).empty()) GTEST_SKIP() << "glslangValidator not found at configure time";
  FitSet set = BothForms();
  std::string glsl = GenerateGlsl(set, "skybake test");
  std::string calls;
  for (const ConstituentFit& c : set.constituents)
    if (c.fitted) calls += " + " + FunctionName(c) + "(0.5, 1000.0)";
  std::string main = "out vec4 color;\nvoid main() { color = vec4(0.0" + calls + "); }\n";
  TempDir dir;
  for (auto [name, prologue] : {std::pair{"core.frag", "#version 330 core\n"},
                                std::pair{"es.frag", "#version 300 es\nprecision highp float;\n"}}) {
    WriteText(dir.path() / name, std::string(prologue) + glsl + main);
    std::string out;
    int code = RunCommand(ShellQuote(SKYBAKE_GLSLANG_VALIDATOR) + " " + ShellQuote(dir.path() / name), dir, &out);
    EXPECT_EQ(code, 0) << name << ":\n" << out;
  }
}

// Compiles the generated C++ twin with the project's compiler and evaluates
// it at `points`; returns one value per point.
std::vector<double> EvaluateCppTwin(const FitSet& set, const ConstituentFit& fit,
                                    const std::vector<std::pair<double, double>>& points, const TempDir& dir) {
  WriteText(dir.path() / "sky_dome_fit.h", GenerateCppTwin(set, "skybake test"));
  std::ostringstream main;
  main << "#include <cstdio>\n#include \"sky_dome_fit.h\"\nint main() {\n  float mu, h;\n"
       << "  while (std::scanf(\"%f %f\", &mu, &h) == 2)\n"
       << "    std::printf(\"%.9g\\n\", skybake_sky_dome_fit::" << FunctionName(fit) << "(mu, h));\n}\n";
  WriteText(dir.path() / "main.cpp", main.str());
  std::ostringstream input;
  input.precision(9);
  for (auto [mu, h] : points) input << mu << " " << h << "\n";
  WriteText(dir.path() / "input.txt", input.str());
  std::string err;
  int code = RunCommand(ShellQuote(SKYBAKE_CXX_COMPILER) + " -std=c++17 -O2 -Wall -Wextra -Werror -o " +
                     ShellQuote(dir.path() / "twin") + " " + ShellQuote(dir.path() / "main.cpp"),
                 dir, nullptr, &err);
  EXPECT_EQ(code, 0) << err;
  std::string out;
  RunCommand(ShellQuote(dir.path() / "twin") + " <" + ShellQuote(dir.path() / "input.txt"), dir, &out);
  std::vector<double> values;
  for (const std::string& line : Lines(out)) values.push_back(std::stod(line));
  return values;
}

TEST(Codegen, CppTwinMatchesTheFittedSurface) {
  // The twin evaluates in float: ~20 roundings of 6e-8 plus exp() turning an
  // absolute argument error of ~15 * 6e-8 into a relative one keep it within
  // ~3e-6 of the double-precision surface; 1e-5 leaves room for libm.
  FitSet set = BothForms();
  std::vector<std::pair<double, double>> points = EvaluationPoints();
  TempDir dir;
  for (const ConstituentFit& c : set.constituents) {
    if (!c.fitted) continue;
    std::vector<double> twin = EvaluateCppTwin(set, c, points, dir);
    ASSERT_EQ(twin.size(), points.size()) << c.identifier;
    double worst = 0.0;
    for (size_t i = 0; i < points.size(); ++i) {
      double expected = c.surface.RelativeOpticalPath(static_cast<float>(points[i].first),
                                                      static_cast<float>(points[i].second));
      EXPECT_NEAR(twin[i] / expected, 1.0, 1e-5)
          << c.identifier << " mu=" << points[i].first << " h=" << points[i].second;
      worst = std::max(worst, std::abs(twin[i] / expected - 1.0));
    }
    std::cout << c.identifier << ": C++ twin vs surface, max relative difference " << worst << "\n";
  }
}

class GlslOnMesa : public ::testing::TestWithParam<testing::GlContext::Api> {};

TEST_P(GlslOnMesa, MatchesTheCppTwin) {
  std::string why_not;
  std::unique_ptr<testing::GlContext> gl = testing::GlContext::Create(GetParam(), &why_not);
  if (!gl) GTEST_SKIP() << why_not;
  FitSet set = BothForms();
  std::vector<std::pair<double, double>> points = EvaluationPoints();
  std::vector<testing::Vec4> inputs;
  for (auto [mu, h] : points) inputs.push_back({static_cast<float>(mu), static_cast<float>(h), 0.0f, 0.0f});
  TempDir dir;
  for (const ConstituentFit& c : set.constituents) {
    if (!c.fitted) continue;
    std::string shader = GenerateGlsl(set, "skybake test") + "void main() {\n  vec4 in0 = skybake_input(0);\n" +
                         "  skybake_output = vec4(" + FunctionName(c) + "(in0.x, in0.y), 0.0, 0.0, 1.0);\n}\n";
    std::vector<testing::Vec4> gpu = gl->RunFragmentPass(shader, inputs);
    std::vector<double> twin = EvaluateCppTwin(set, c, points, dir);
    ASSERT_EQ(gpu.size(), points.size());
    ASSERT_EQ(twin.size(), points.size());
    // GLSL ES 3.00 allows exp (3 + 2|x|) ulp, ~30 ulp = 4e-6 for the
    // arguments here, three of them plus pow in a function: 2e-5 is what
    // any conforming driver may differ by. llvmpipe measures ~6e-7.
    double worst = 0.0;
    for (size_t i = 0; i < points.size(); ++i) {
      EXPECT_NEAR(gpu[i][0] / twin[i], 1.0, 2e-5) << gl->Description() << " " << c.identifier << " mu="
                                                   << points[i].first << " h=" << points[i].second;
      worst = std::max(worst, std::abs(gpu[i][0] / twin[i] - 1.0));
    }
    std::cout << c.identifier << ": GLSL on " << gl->Description() << " vs C++ twin, max relative difference "
              << worst << "\n";
  }
}

INSTANTIATE_TEST_SUITE_P(Apis, GlslOnMesa,
                         ::testing::Values(testing::GlContext::Api::kGles30, testing::GlContext::Api::kDesktop33Core),
                         [](const auto& info) {
                           return info.param == testing::GlContext::Api::kGles30 ? "Gles30" : "Desktop33Core";
                         });

TEST(GlContext, RunsAFragmentPassOverManyItems) {
  // The helper itself: more items than one row, two inputs per item.
  std::string why_not;
  auto gl = testing::GlContext::Create(testing::GlContext::Api::kGles30, &why_not);
  if (!gl) GTEST_SKIP() << why_not;
  std::vector<testing::Vec4> inputs;
  const int items = 2500;
  for (int i = 0; i < items; ++i) {
    inputs.push_back({float(i), 1.0f, 2.0f, 3.0f});
    inputs.push_back({0.5f, float(-i), 0.0f, 0.0f});
  }
  auto out = gl->RunFragmentPass(
      "void main() {\n"
      "  vec4 a = skybake_input(0), b = skybake_input(1);\n"
      "  skybake_output = vec4(a.x + b.x, a.y * b.y, float(skybake_item()), a.w);\n"
      "}\n",
      inputs, 2);
  ASSERT_EQ(out.size(), size_t(items));
  for (int i = 0; i < items; ++i) {
    EXPECT_EQ(out[i][0], float(i) + 0.5f);
    EXPECT_EQ(out[i][1], float(-i));
    EXPECT_EQ(out[i][2], float(i));
    EXPECT_EQ(out[i][3], 3.0f);
  }
  EXPECT_THROW(gl->RunFragmentPass("void main() { skybake_output = undefined_thing; }", inputs, 2),
               std::runtime_error);
}

// ---- the dome mesh ----

std::vector<std::uint8_t> Base64Decode(const std::string& text) {
  auto value = [](char c) -> int {
    if (c >= 'A' && c <= 'Z') return c - 'A';
    if (c >= 'a' && c <= 'z') return c - 'a' + 26;
    if (c >= '0' && c <= '9') return c - '0' + 52;
    return c == '+' ? 62 : c == '/' ? 63 : -1;
  };
  std::vector<std::uint8_t> out;
  unsigned buffer = 0;
  int bits = 0;
  for (char c : text) {
    int v = value(c);
    if (v < 0) break;  // '=' padding
    buffer = (buffer << 6) | unsigned(v);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out.push_back(static_cast<std::uint8_t>((buffer >> bits) & 0xff));
    }
  }
  return out;
}

TEST(DomeMesh, VerticesLieAtTheFittedOpticalLengthOfAir) {
  Atmosphere earth = Earth();
  FitSet set = FitAtmosphere(earth, {}, FitOptions{});
  DomeOptions options;
  options.altitude_m = 500.0;
  options.rings = 12;
  options.segments = 24;
  std::string why_not;
  std::optional<DomeMesh> mesh = BuildDomeMesh(earth, set, options, &why_not);
  ASSERT_TRUE(mesh) << why_not;
  EXPECT_EQ(mesh->air_name, "rayleigh");
  EXPECT_EQ(mesh->haze_name, "mie");
  EXPECT_EQ(mesh->vertex_count(), 1u + 12u * 24u);
  EXPECT_EQ(mesh->indices.size(), 3u * (24u + 2u * 24u * 11u));

  // Zenith optical lengths from the closed form H(1 - e^-(T-h)/H).
  double air_length = -8000.0 * std::expm1(-(60e3 - 500.0) / 8000.0);
  double mie_length = -1200.0 * std::expm1(-(60e3 - 500.0) / 1200.0);
  const Surface& air = set.constituents[0].surface;
  const Surface& mie = set.constituents[1].surface;
  for (size_t v = 0; v < mesh->vertex_count(); ++v) {
    double x = mesh->positions[3 * v], y = mesh->positions[3 * v + 1], z = mesh->positions[3 * v + 2];
    double radius = std::sqrt(x * x + y * y + z * z), mu = std::max(0.0, y / radius);
    double expected = air.RelativeOpticalPath(mu, 500.0) * air_length;
    EXPECT_NEAR(radius / expected, 1.0, 1e-5) << "vertex " << v;
    double ratio = mie.RelativeOpticalPath(mu, 500.0) * mie_length / expected;
    EXPECT_NEAR(mesh->haze_air_ratio[v] / ratio, 1.0, 1e-4) << "vertex " << v;
    EXPECT_GE(y, -1e-3);
  }
  // Every face points at the observer, so the dome is seen from inside.
  for (size_t t = 0; t < mesh->indices.size(); t += 3) {
    const float* p = mesh->positions.data();
    std::uint32_t a = mesh->indices[t], b = mesh->indices[t + 1], c = mesh->indices[t + 2];
    ASSERT_LT(std::max({a, b, c}), mesh->vertex_count());
    auto vertex = [p](std::uint32_t i) { return glm::dvec3(p[3 * i], p[3 * i + 1], p[3 * i + 2]); };
    const glm::dvec3 normal = glm::cross(vertex(b) - vertex(a), vertex(c) - vertex(a));
    EXPECT_LT(glm::dot(normal, vertex(a) + vertex(b) + vertex(c)), 0.0) << "triangle " << t / 3;
  }
}

TEST(DomeMesh, GltfAndObjCarryTheSameMesh) {
  Atmosphere earth = Earth();
  FitSet set = FitAtmosphere(earth, {}, FitOptions{});
  std::string why_not;
  DomeOptions options;
  options.rings = 6;
  options.segments = 8;
  std::optional<DomeMesh> mesh = BuildDomeMesh(earth, set, options, &why_not);
  ASSERT_TRUE(mesh);

  nlohmann::json gltf = nlohmann::json::parse(ToGltf(*mesh, "skybake test"));
  EXPECT_EQ(gltf["asset"]["version"], "2.0");
  EXPECT_EQ(gltf["asset"]["extras"]["generated_by"], "skybake test");
  std::string uri = gltf["buffers"][0]["uri"];
  const std::string prefix = "data:application/octet-stream;base64,";
  ASSERT_EQ(uri.rfind(prefix, 0), 0u);
  std::vector<std::uint8_t> buffer = Base64Decode(uri.substr(prefix.size()));
  ASSERT_EQ(buffer.size(), gltf["buffers"][0]["byteLength"].get<size_t>());
  const auto& primitive = gltf["meshes"][0]["primitives"][0];
  EXPECT_EQ(primitive["mode"], 4);
  auto read_floats = [&](int accessor_index) {
    const auto& accessor = gltf["accessors"][accessor_index];
    const auto& view = gltf["bufferViews"][accessor["bufferView"].get<int>()];
    size_t offset = view["byteOffset"], length = view["byteLength"];
    EXPECT_EQ(offset % 4, 0u);
    EXPECT_LE(offset + length, buffer.size());
    std::vector<float> values(length / 4);
    std::memcpy(values.data(), buffer.data() + offset, length);
    return values;
  };
  int position_accessor = primitive["attributes"]["POSITION"];
  std::vector<float> positions = read_floats(position_accessor);
  EXPECT_EQ(positions, mesh->positions);
  const auto& position_info = gltf["accessors"][position_accessor];
  EXPECT_EQ(position_info["count"].get<size_t>(), mesh->vertex_count());
  for (size_t v = 0; v < mesh->vertex_count(); ++v)
    for (int k = 0; k < 3; ++k) {
      EXPECT_GE(positions[3 * v + k], position_info["min"][k].get<float>());
      EXPECT_LE(positions[3 * v + k], position_info["max"][k].get<float>());
    }
  ASSERT_TRUE(primitive["attributes"].contains("_HAZE_AIR_RATIO"));
  EXPECT_EQ(read_floats(primitive["attributes"]["_HAZE_AIR_RATIO"]), mesh->haze_air_ratio);
  const auto& index_accessor = gltf["accessors"][primitive["indices"].get<int>()];
  EXPECT_EQ(index_accessor["componentType"], 5125);
  EXPECT_EQ(index_accessor["count"].get<size_t>(), mesh->indices.size());

  // OBJ: the same vertices, the ratio as texture u, 1-based faces.
  size_t v_count = 0, vt_count = 0, f_count = 0;
  for (const std::string& line : Lines(ToObj(*mesh, "skybake test"))) {
    std::istringstream in(line);
    std::string tag;
    in >> tag;
    if (tag == "v") {
      float x, y, z;
      in >> x >> y >> z;
      EXPECT_NEAR(x, mesh->positions[3 * v_count], 1e-3f * (1.0f + std::abs(x)));
      ++v_count;
    } else if (tag == "vt") {
      float u, w;
      in >> u >> w;
      EXPECT_NEAR(u, mesh->haze_air_ratio[vt_count], 1e-6f);
      EXPECT_NEAR(w * 90.0f, mesh->zenith_deg[vt_count], 1e-4f);
      ++vt_count;
    } else if (tag == "f") {
      for (int k = 0; k < 3; ++k) {
        std::string corner;
        in >> corner;
        unsigned index = std::stoul(corner.substr(0, corner.find('/')));
        EXPECT_EQ(index, mesh->indices[f_count * 3 + k] + 1);
      }
      ++f_count;
    }
  }
  EXPECT_EQ(v_count, mesh->vertex_count());
  EXPECT_EQ(vt_count, mesh->vertex_count());
  EXPECT_EQ(f_count * 3, mesh->indices.size());
}

TEST(DomeMesh, NeedsAnAirConstituentWithDensityAtTheObserver) {
  Atmosphere ozone_only = Planet("ozone-only", kEarthRadius, kEarthTop);
  ozone_only.constituents = {MakeConstituent("ozone", OzoneTent(), Spectrum(1e-6), Spectrum(0.0), PhaseKind::kRayleigh)};
  FitSet set = FitAtmosphere(ozone_only, {}, FitOptions{});
  ASSERT_EQ(set.air, 0);
  std::string why_not;
  EXPECT_FALSE(BuildDomeMesh(ozone_only, set, DomeOptions{}, &why_not));
  EXPECT_NE(why_not.find("zero"), std::string::npos) << why_not;
}

}  // namespace
}  // namespace skybake::fit
