// How an engine uses a baked set: load the tables with the formats library,
// upload them as OpenGL textures (3D for the scattering tables) with the
// sampling modes shaders_runtime/README.md documents, compile the three GLSL
// files the bake wrote into a fragment shader, and draw. It renders, headless
// (EGL on Mesa's surfaceless platform, OpenGL ES 3.0, so no window system or
// GPU is needed), the `fisheye` sky and the `aerial` view of the ground with
// aerial perspective, in the geometry of `skybake render` (render/views.h),
// and writes each as linear EXR and tone-mapped PNG, as `skybake render`
// does: the two programs draw the same pictures, one on the GPU, one on the
// CPU twin.
//
//   skybake_engine_example LUT_DIR OUT_DIR [--sun-zenith DEG] [--sun-azimuth DEG]
//                          [--size N] [--altitude M] [--format ktx2|exr]
//
// writes OUT_DIR/fisheye.{exr,png} (N x N) and OUT_DIR/aerial.{exr,png}
// (N x N/4). Exit codes as skybake's: 1 usage, 2 invalid input, 3 I/O
// (including: no headless OpenGL ES 3.0 context), 4 internal.
#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GLES3/gl3.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>

#include "bake/bake.h"
#include "core/constants.h"
#include "core/errors.h"
#include "core/file_io.h"
#include "formats/lut_files.h"
#include "formats/table_file.h"
#include "render/image_files.h"
#include "render/views.h"

namespace fs = std::filesystem;
using skybake::kPi;
using skybake::glsl::vec3;

namespace {

constexpr double kDegree = kPi / 180.0;
constexpr double kAerialPitchDeg = 7.0;  // as render/views.cpp

// The shader an engine would write around the snippet: one ray per pixel,
// sky (with the sun's disc) where it misses the ground, lit ground seen
// through the atmosphere where it hits it. The pixel-to-ray mappings and the
// shading are those of render/views.cpp.
//
// A scene's bake (examples/scenes/README.md) ships a pruned snippet:
// atmosphere_constants.glsl sets SKYBAKE_HAS_SCATTERING_TEXTURE,
// SKYBAKE_HAS_IRRADIANCE_TEXTURE and SKYBAKE_HAS_AERIAL_PERSPECTIVE, and
// functions.glsl compiles only the functions whose tables exist, so the
// shader calls a function only under its macro and draws what the set holds:
//   no scattering table:  a black sky (the sun's disc still dims through the
//                         air by the transmittance table);
//   no aerial perspective: the ground unveiled (no in-scattering, no
//                         extinction between it and the camera);
//   no irradiance table:  the ground lit by the direct sun only (as
//                         GetSunAndSkyIrradiance computes it, without the sky
//                         term), as an engine that lights it by its own
//                         probes would have them add the rest.
const char* const kFragmentMain = R"(
uniform sampler2D transmittance_texture;
uniform sampler3D scattering_texture;
uniform sampler3D single_mie_scattering_texture;
uniform sampler2D irradiance_texture;
uniform int view;           // 0: fisheye, 1: aerial
uniform vec2 image_size;
uniform float camera_altitude;
uniform vec3 sun_direction;
uniform vec3 forward;       // aerial camera basis
uniform vec3 right;
uniform vec3 camera_up;
uniform vec3 ground_albedo;
uniform float cos_disc;     // the drawn sun disc: at least one pixel wide,
uniform float disc_scale;   // its radiance scaled to keep the sun's irradiance
out vec4 radiance_out;

vec3 Sky(vec3 camera, vec3 dir, out vec3 transmittance) {
#if SKYBAKE_HAS_SCATTERING_TEXTURE
  return GetSkyRadiance(ATMOSPHERE, transmittance_texture, scattering_texture, single_mie_scattering_texture,
                        camera, dir, sun_direction, transmittance);
#else
  float r = ClampRadius(ATMOSPHERE, length(camera));
  transmittance = GetTransmittanceToTopAtmosphereBoundary(ATMOSPHERE, transmittance_texture, r,
                                                          ClampCosine(dot(camera, dir) / length(camera)));
  return vec3(0.0);
#endif
}

vec3 GroundLight(vec3 point, vec3 normal) {
#if SKYBAKE_HAS_IRRADIANCE_TEXTURE
  vec3 sky_irradiance;
  vec3 sun_irradiance = GetSunAndSkyIrradiance(ATMOSPHERE, transmittance_texture, irradiance_texture, point, normal,
                                               sun_direction, sky_irradiance);
  return sun_irradiance + sky_irradiance;
#else
  float r = ClampRadius(ATMOSPHERE, length(point));
  float mu_s = ClampCosine(dot(point, sun_direction) / length(point));
  return ATMOSPHERE.solar_irradiance * GetTransmittanceToSun(ATMOSPHERE, transmittance_texture, r, mu_s) *
         max(dot(normal, sun_direction), 0.0);
#endif
}

vec3 AerialPerspective(vec3 camera, vec3 point, out vec3 transmittance) {
#if SKYBAKE_HAS_AERIAL_PERSPECTIVE
  return GetSkyRadianceToPoint(ATMOSPHERE, transmittance_texture, scattering_texture, single_mie_scattering_texture,
                               camera, point, sun_direction, transmittance);
#else
  transmittance = vec3(1.0);
  return vec3(0.0);
#endif
}

void main() {
  // Pixel centre, measured from the image's top-left corner.
  vec2 p = vec2(gl_FragCoord.x, image_size.y - gl_FragCoord.y);
  vec3 dir;
  if (view == 0) {
    vec2 d = (image_size.x / 2.0 - p) / (image_size.x / 2.0);
    float rho = length(d);
    if (rho > 1.0) {
      radiance_out = vec4(0.0, 0.0, 0.0, 1.0);
      return;
    }
    float theta = rho * PI / 2.0;
    float phi = atan(d.y, d.x);
    dir = vec3(sin(theta) * cos(phi), sin(theta) * sin(phi), cos(theta));
  } else {
    float u = 2.0 * p.x / image_size.x - 1.0;
    float v = (1.0 - 2.0 * p.y / image_size.y) * (image_size.y / image_size.x);
    dir = normalize(forward + right * u + camera_up * v);
  }
  float bottom = ATMOSPHERE.bottom_radius;
  vec3 camera = vec3(0.0, 0.0, bottom + camera_altitude);
  // Distance to the ground, in the form without cancellation: products of
  // radii near 6.4e6 m would lose everything in float.
  float b = camera.z * dir.z;
  float c = camera_altitude * (2.0 * bottom + camera_altitude);
  float disc = b * b - c;
  vec3 radiance;
  if (b < 0.0 && disc >= 0.0) {
    float t = c / (sqrt(disc) - b);
    vec3 normal = normalize(camera + dir * t);
    vec3 point = normal * bottom;
    vec3 transmittance;
    vec3 inscatter = AerialPerspective(camera, point, transmittance);
    radiance = ground_albedo / PI * GroundLight(point, normal) * transmittance + inscatter;
  } else {
    vec3 transmittance;
    radiance = Sky(camera, dir, transmittance);
    if (dot(dir, sun_direction) > cos_disc) radiance += GetSolarRadiance(ATMOSPHERE) * transmittance * disc_scale;
  }
  radiance_out = vec4(radiance, 1.0);
}
)";

const char* const kVertexShader = R"(#version 300 es
// One triangle that covers the viewport, from gl_VertexID alone.
void main() {
  vec2 p = vec2(float((gl_VertexID & 1) * 4 - 1), float((gl_VertexID & 2) * 2 - 1));
  gl_Position = vec4(p, 0.0, 1.0);
}
)";

struct Arguments {
  std::string lut_dir;
  std::string output_dir;
  double sun_zenith_deg = 30.0;
  double sun_azimuth_deg = 0.0;
  int size = 256;
  double altitude_m = 100.0;
  std::string format;  // empty: what LoadLutSet prefers
};

// A current OpenGL ES 3.0 context on EGL's surfaceless platform (the
// approach of tests/gl_context.cpp); rendering goes to framebuffer objects.
class HeadlessContext {
 public:
  HeadlessContext() {
    auto get_platform_display =
        reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
    if (!get_platform_display) Fail("eglGetPlatformDisplayEXT is unavailable");
    display_ = get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    EGLint major = 0, minor = 0;
    if (display_ == EGL_NO_DISPLAY || !eglInitialize(display_, &major, &minor)) Fail("no surfaceless EGL display");
    if (!eglBindAPI(EGL_OPENGL_ES_API)) Fail("eglBindAPI(EGL_OPENGL_ES_API) failed");
    const EGLint config_attributes[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE, EGL_OPENGL_ES3_BIT,
                                        EGL_NONE};
    EGLConfig config = EGL_NO_CONFIG_KHR;
    EGLint configs = 0;
    if (!eglChooseConfig(display_, config_attributes, &config, 1, &configs) || configs < 1) {
      config = EGL_NO_CONFIG_KHR;  // EGL_KHR_no_config_context, as Mesa offers
    }
    const EGLint context_attributes[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 0, EGL_NONE};
    context_ = eglCreateContext(display_, config, EGL_NO_CONTEXT, context_attributes);
    if (context_ == EGL_NO_CONTEXT) Fail("eglCreateContext (OpenGL ES 3.0) failed");
    if (!eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_)) Fail("eglMakeCurrent failed");
    // Linear filtering of float textures is an extension in ES 3.0.
    const char* extensions = reinterpret_cast<const char*>(glGetString(GL_EXTENSIONS));
    if (!extensions || !std::strstr(extensions, "GL_OES_texture_float_linear"))
      Fail("the driver lacks OES_texture_float_linear");
    if (!std::strstr(extensions, "GL_EXT_color_buffer_float")) Fail("the driver lacks EXT_color_buffer_float");
  }
  ~HeadlessContext() {
    if (context_ != EGL_NO_CONTEXT) {
      eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
      eglDestroyContext(display_, context_);
    }
  }
  HeadlessContext(const HeadlessContext&) = delete;
  HeadlessContext& operator=(const HeadlessContext&) = delete;

 private:
  [[noreturn]] static void Fail(const std::string& why) { throw skybake::IoError("no headless OpenGL ES 3.0: " + why); }
  EGLDisplay display_ = EGL_NO_DISPLAY;
  EGLContext context_ = EGL_NO_CONTEXT;
};

void CheckGl(const char* where) {
  GLenum error = glGetError();
  if (error != GL_NO_ERROR) {
    char buffer[96];
    std::snprintf(buffer, sizeof(buffer), "GL error 0x%04x in %s", static_cast<unsigned>(error), where);
    throw skybake::InternalError(buffer);
  }
}

// A table as the runtime expects it: RGBA32F, GL_LINEAR, GL_CLAMP_TO_EDGE on
// every axis, one mip level (shaders_runtime/README.md, "Textures").
GLuint UploadTable(const skybake::glsl::Texture& table) {
  const GLenum target = table.depth == 1 ? GL_TEXTURE_2D : GL_TEXTURE_3D;
  GLuint id = 0;
  glGenTextures(1, &id);
  glBindTexture(target, id);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  if (target == GL_TEXTURE_2D) {
    glTexImage2D(target, 0, GL_RGBA32F, table.width, table.height, 0, GL_RGBA, GL_FLOAT, table.texels.data());
  } else {
    glTexImage3D(target, 0, GL_RGBA32F, table.width, table.height, table.depth, 0, GL_RGBA, GL_FLOAT,
                 table.texels.data());
    glTexParameteri(target, GL_TEXTURE_WRAP_R, GL_CLAMP_TO_EDGE);
  }
  glTexParameteri(target, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(target, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(target, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(target, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  glTexParameteri(target, GL_TEXTURE_MAX_LEVEL, 0);
  CheckGl("uploading a table");
  return id;
}

GLuint CompileShader(GLenum type, const std::string& source) {
  GLuint shader = glCreateShader(type);
  const char* text = source.c_str();
  glShaderSource(shader, 1, &text, nullptr);
  glCompileShader(shader);
  GLint ok = 0;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[2048] = {};
    glGetShaderInfoLog(shader, sizeof(log), nullptr, log);
    std::string first_line(log, strcspn(log, "\n"));
    throw skybake::InputError(std::string(type == GL_VERTEX_SHADER ? "vertex" : "fragment") +
                              " shader does not compile: " + first_line);
  }
  return shader;
}

// The snippet exactly as the bake shipped it, in the documented order.
std::string ShippedSnippet(const fs::path& lut_dir) {
  std::string source;
  for (const char* file : {"definitions.glsl", "atmosphere_constants.glsl", "functions.glsl"})
    source += skybake::ReadFileText(lut_dir / file);
  return source;
}

void Run(const Arguments& args) {
  if (args.size < 4 || args.size > 4096) throw skybake::UsageError("--size must be in 4..4096");
  if (!(args.altitude_m >= 0.0 && args.altitude_m <= 1e5)) throw skybake::UsageError("--altitude must be in 0..1e5 m");
  if (!(args.sun_zenith_deg >= 0.0 && args.sun_zenith_deg <= 180.0))
    throw skybake::UsageError("--sun-zenith must be in 0..180 degrees");
  if (!std::isfinite(args.sun_azimuth_deg)) throw skybake::UsageError("--sun-azimuth must be a finite angle");
  skybake::LoadOptions load_options;
  if (!args.format.empty()) {
    load_options.format = skybake::ParseFileFormat(args.format);
    if (!load_options.format) throw skybake::UsageError("--format must be ktx2 or exr, not '" + args.format + "'");
  }
  const fs::path lut_dir(args.lut_dir);
  const skybake::LutSet luts = skybake::LoadLutSet(lut_dir, load_options);
  const std::string snippet = ShippedSnippet(lut_dir);

  // What a scene's bake leaves out, and so what the shader draws without
  // (kFragmentMain); the snippet's macros say the same.
  const bool aerial_perspective = !luts.scene || luts.scene->effects.aerial_perspective;
  if (luts.scattering.empty()) std::fputs("skybake_engine_example: no scattering table: the sky is black\n", stderr);
  if (!aerial_perspective)
    std::fputs("skybake_engine_example: no aerial-perspective functions: the ground is drawn unveiled\n", stderr);
  if (luts.irradiance.empty())
    std::fputs("skybake_engine_example: no irradiance table: the ground is lit by the direct sun only\n", stderr);

  HeadlessContext context;
  const skybake::glsl::Texture& single_mie =
      luts.single_mie_scattering.empty() ? luts.scattering : luts.single_mie_scattering;
  struct Binding {
    const char* sampler;
    const skybake::glsl::Texture* table;
    GLenum target;
  };
  const Binding bindings[] = {{"transmittance_texture", &luts.transmittance, GL_TEXTURE_2D},
                              {"scattering_texture", &luts.scattering, GL_TEXTURE_3D},
                              {"single_mie_scattering_texture", &single_mie, GL_TEXTURE_3D},
                              {"irradiance_texture", &luts.irradiance, GL_TEXTURE_2D}};
  // A table the set leaves out is not uploaded: the snippet has no function
  // that samples it.
  std::vector<GLuint> textures;
  for (const Binding& b : bindings) textures.push_back(b.table->empty() ? 0 : UploadTable(*b.table));

  GLuint vertex = CompileShader(GL_VERTEX_SHADER, kVertexShader);
  GLuint fragment = CompileShader(GL_FRAGMENT_SHADER, "#version 300 es\n" + snippet + kFragmentMain);
  GLuint program = glCreateProgram();
  glAttachShader(program, vertex);
  glAttachShader(program, fragment);
  glLinkProgram(program);
  GLint linked = 0;
  glGetProgramiv(program, GL_LINK_STATUS, &linked);
  if (!linked) throw skybake::InternalError("the shaders do not link");
  glUseProgram(program);
  // Each sampler on its own unit, whether or not its table exists: samplers
  // of different types must not share a unit.
  for (int unit = 0; unit < 4; ++unit) {
    glActiveTexture(GL_TEXTURE0 + unit);
    if (textures[unit] != 0) glBindTexture(bindings[unit].target, textures[unit]);
    glUniform1i(glGetUniformLocation(program, bindings[unit].sampler), unit);
  }
  GLuint vao = 0;
  glGenVertexArrays(1, &vao);
  glBindVertexArray(vao);

  const double sz = args.sun_zenith_deg * kDegree, az = args.sun_azimuth_deg * kDegree;
  const vec3 sun(std::sin(sz) * std::cos(az), std::sin(sz) * std::sin(az), std::cos(sz));
  const double pitch = kAerialPitchDeg * kDegree;
  const vec3 level(std::cos(az), std::sin(az), 0.0), up(0.0, 0.0, 1.0);
  const vec3 forward = level * std::cos(pitch) - up * std::sin(pitch);
  const vec3 right(std::sin(az), -std::cos(az), 0.0);
  const vec3 camera_up = level * std::sin(pitch) + up * std::cos(pitch);
  auto uniform3 = [&](const char* name, const vec3& v) {
    glUniform3f(glGetUniformLocation(program, name), float(v.x), float(v.y), float(v.z));
  };
  uniform3("sun_direction", sun);
  uniform3("forward", forward);
  uniform3("right", right);
  uniform3("camera_up", camera_up);
  uniform3("ground_albedo", vec3(luts.atmosphere.ground_albedo));
  glUniform1f(glGetUniformLocation(program, "camera_altitude"), float(args.altitude_m));

  const skybake::render::ToneMap tone{3.3, skybake::render::WhiteBalance(luts.parameters.solar_irradiance)};
  const fs::path out_dir(args.output_dir);
  skybake::EnsureWritableDirectory(out_dir);
  struct ViewSpec {
    const char* name;
    int view;
    int height;
    double pixel_angle;  // as render/views.cpp, for the drawn sun disc
  };
  const ViewSpec views[] = {{"fisheye", 0, args.size, kPi / args.size},
                            {"aerial", 1, std::max(1, args.size / 4), (kPi / 2) / args.size}};
  std::vector<skybake::render::Image> rendered;
  for (const ViewSpec& v : views) {
    const int width = args.size, height = v.height;
    double sun_radius = luts.parameters.sun_angular_radius;
    double cos_disc = std::cos(std::max(sun_radius, v.pixel_angle));
    glUniform1i(glGetUniformLocation(program, "view"), v.view);
    glUniform2f(glGetUniformLocation(program, "image_size"), float(width), float(height));
    glUniform1f(glGetUniformLocation(program, "cos_disc"), float(cos_disc));
    glUniform1f(glGetUniformLocation(program, "disc_scale"), float((1.0 - std::cos(sun_radius)) / (1.0 - cos_disc)));

    // The render target is created on a unit of its own: units 0-3 hold the tables.
    GLuint target = 0, framebuffer = 0;
    glActiveTexture(GL_TEXTURE4);
    glGenTextures(1, &target);
    glBindTexture(GL_TEXTURE_2D, target);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, width, height, 0, GL_RGBA, GL_FLOAT, nullptr);
    glGenFramebuffers(1, &framebuffer);
    glBindFramebuffer(GL_FRAMEBUFFER, framebuffer);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, target, 0);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
      throw skybake::InternalError("an RGBA32F framebuffer is incomplete");
    glViewport(0, 0, width, height);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    std::vector<float> rgba(std::size_t(4) * width * height);
    glReadPixels(0, 0, width, height, GL_RGBA, GL_FLOAT, rgba.data());
    CheckGl("rendering");
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glDeleteFramebuffers(1, &framebuffer);
    glDeleteTextures(1, &target);

    // GL's rows start at the bottom; images here start at the top.
    skybake::render::Image image;
    image.width = width;
    image.height = height;
    image.rgb.resize(std::size_t(3) * width * height);
    for (int y = 0; y < height; ++y) {
      for (int x = 0; x < width; ++x) {
        const float* in = &rgba[4 * (std::size_t(height - 1 - y) * width + x)];
        for (int c = 0; c < 3; ++c) {
          if (!std::isfinite(in[c])) throw skybake::InternalError(std::string(v.name) + ": a pixel is not finite");
          image.rgb[3 * (std::size_t(y) * width + x) + c] = in[c];
        }
      }
    }
    rendered.push_back(std::move(image));
  }
  // Written only once every view has rendered, each file atomically.
  for (std::size_t i = 0; i < rendered.size(); ++i) {
    const skybake::render::Attributes attributes = {{"skybake:view", views[i].name}};
    skybake::render::WriteLinearExr(out_dir / (std::string(views[i].name) + ".exr"), rendered[i], attributes);
    skybake::render::WritePng(out_dir / (std::string(views[i].name) + ".png"),
                              skybake::render::ToneMapToSrgb(rendered[i], tone), attributes);
  }
  glDeleteVertexArrays(1, &vao);
  glDeleteProgram(program);
  glDeleteShader(vertex);
  glDeleteShader(fragment);
  for (GLuint texture : textures)
    if (texture != 0) glDeleteTextures(1, &texture);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Loads a baked set, uploads it to OpenGL ES 3.0 (headless, EGL surfaceless) and renders the "
               "fisheye sky and the aerial view of the ground with the shipped GLSL snippet, to EXR and PNG."};
  app.name("skybake_engine_example");
  Arguments args;
  app.add_option("LUT_DIR", args.lut_dir, "A directory written by skybake bake")->required();
  app.add_option("OUT_DIR", args.output_dir, "Where to write fisheye.{exr,png} and aerial.{exr,png}")->required();
  app.add_option("--sun-zenith", args.sun_zenith_deg, "Sun zenith angle, degrees")->capture_default_str();
  app.add_option("--sun-azimuth", args.sun_azimuth_deg, "Sun azimuth (the aerial view looks toward it), degrees")
      ->capture_default_str();
  app.add_option("--size", args.size, "Image width in pixels (the aerial view is a quarter as high)")
      ->capture_default_str();
  app.add_option("--altitude", args.altitude_m, "Camera altitude, metres")->capture_default_str();
  app.add_option("--format", args.format, "Table files to read: ktx2 or exr (default: KTX2 if listed)");
  try {
    app.parse(argc, argv);
    Run(args);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "skybake_engine_example: %s (see --help)\n", e.what());
    return static_cast<int>(skybake::ExitCode::kUsage);
  } catch (const skybake::Error& e) {
    std::fprintf(stderr, "skybake_engine_example: %s\n", e.what());
    return static_cast<int>(e.code());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "skybake_engine_example: internal error: %s\n", e.what());
    return static_cast<int>(skybake::ExitCode::kInternal);
  }
  return 0;
}
