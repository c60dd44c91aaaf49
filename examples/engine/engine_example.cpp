// How an engine uses a baked set: load the tables with the formats library,
// upload them as OpenGL textures (3D for the scattering tables) with the
// sampling modes shaders_runtime/README.md documents, compile the three GLSL
// files the bake wrote into a fragment shader, and draw. It renders, headless
// (OpenGL ES 3.0 through EGL with no window system: Mesa's surfaceless
// platform, which needs no GPU, or an EGL device, as NVIDIA's driver offers),
// the `fisheye` sky and the `aerial` view of the ground with aerial
// perspective, in the geometry of `skybake render` (render/views.h), and
// writes each as linear EXR and tone-mapped PNG, as `skybake render` does:
// the two programs draw the same pictures, one on the GPU, one on the CPU
// twin.
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
#include "examples/engine/headless_egl.h"
#include "formats/lut_files.h"
#include "formats/table_file.h"
#include "render/image_files.h"
#include "render/views.h"
#include "examples/engine/example_views.h"

namespace fs = std::filesystem;
using skybake::glsl::vec3;
using namespace skybake::engine_example;

namespace {

// The fragment shader an engine would write around the snippet: the view's
// values as uniforms, the shading of pixel_radiance.glsl.
const char* const kFragmentUniforms = R"(
uniform sampler2D transmittance_texture;
uniform sampler3D scattering_texture;
uniform sampler3D single_mie_scattering_texture;
uniform sampler2D irradiance_texture;
uniform int view;
uniform vec2 image_size;
uniform float camera_altitude;
uniform vec3 sun_direction;
uniform vec3 forward;
uniform vec3 right;
uniform vec3 camera_up;
uniform vec3 ground_albedo;
uniform float cos_disc;
uniform float disc_scale;
out vec4 radiance_out;
)";
const char* const kFragmentMain = R"(
void main() {
  radiance_out = vec4(PixelRadiance(vec2(gl_FragCoord.x, image_size.y - gl_FragCoord.y)), 1.0);
}
)";

const char* const kVertexShader = R"(#version 300 es
// One triangle that covers the viewport, from gl_VertexID alone.
void main() {
  vec2 p = vec2(float((gl_VertexID & 1) * 4 - 1), float((gl_VertexID & 2) * 2 - 1));
  gl_Position = vec4(p, 0.0, 1.0);
}
)";

// A current OpenGL ES 3.0 context with no window system (HeadlessEglDisplay,
// as tests/gl_context.cpp); rendering goes to framebuffer objects.
class HeadlessContext {
 public:
  HeadlessContext() {
    display_ = skybake::HeadlessEglDisplay();
    if (display_ == EGL_NO_DISPLAY) Fail("no surfaceless or device EGL display");
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

void Run(const Arguments& args) {
  const LoadedSet set = LoadSet(args);
  const skybake::LutSet& luts = set.luts;
  const std::vector<View> views = MakeViews(args, luts);

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
  GLuint fragment = CompileShader(GL_FRAGMENT_SHADER, "#version 300 es\n" + set.snippet + kFragmentUniforms +
                                                          PixelRadianceGlsl() + kFragmentMain);
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

  auto uniform3 = [&](const char* name, const vec3& v) {
    glUniform3f(glGetUniformLocation(program, name), float(v.x), float(v.y), float(v.z));
  };
  std::vector<skybake::render::Image> rendered;
  for (const View& v : views) {
    const int width = v.width, height = v.height;
    glUniform1i(glGetUniformLocation(program, "view"), v.view);
    glUniform2f(glGetUniformLocation(program, "image_size"), float(width), float(height));
    glUniform1f(glGetUniformLocation(program, "camera_altitude"), v.camera_altitude);
    uniform3("sun_direction", v.sun_direction);
    uniform3("forward", v.forward);
    uniform3("right", v.right);
    uniform3("camera_up", v.camera_up);
    uniform3("ground_albedo", v.ground_albedo);
    glUniform1f(glGetUniformLocation(program, "cos_disc"), v.cos_disc);
    glUniform1f(glGetUniformLocation(program, "disc_scale"), v.disc_scale);

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
        for (int c = 0; c < 3; ++c) image.rgb[3 * (std::size_t(y) * width + x) + c] = in[c];
      }
    }
    rendered.push_back(std::move(image));
  }
  WriteViews(args, luts, views, rendered);
  glDeleteVertexArrays(1, &vao);
  glDeleteProgram(program);
  glDeleteShader(vertex);
  glDeleteShader(fragment);
  for (GLuint texture : textures)
    if (texture != 0) glDeleteTextures(1, &texture);
}

}  // namespace

int main(int argc, char** argv) {
  return RunExample(argc, argv, "skybake_engine_example",
                    "Loads a baked set, uploads it to OpenGL ES 3.0 (headless, EGL surfaceless) and renders the "
                    "fisheye sky and the aerial view of the ground with the shipped GLSL snippet, to EXR and PNG.",
                    Run);
}
