#include "tests/gl_context.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <stdexcept>

#if SKYBAKE_HAVE_EGL
#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GLES3/gl3.h>

#include "examples/engine/headless_egl.h"
#endif

namespace skybake::testing {

#if SKYBAKE_HAVE_EGL

namespace {

constexpr int kRowWidth = 1024;

// The GL entry points the helper uses, loaded with eglGetProcAddress.
struct GlFunctions {
#define SKYBAKE_GL_FUNCTIONS(X)                                                                              \
  X(GLuint, CreateShader, (GLenum))                                                                          \
  X(void, ShaderSource, (GLuint, GLsizei, const GLchar* const*, const GLint*))                               \
  X(void, CompileShader, (GLuint))                                                                           \
  X(void, GetShaderiv, (GLuint, GLenum, GLint*))                                                             \
  X(void, GetShaderInfoLog, (GLuint, GLsizei, GLsizei*, GLchar*))                                            \
  X(void, DeleteShader, (GLuint))                                                                            \
  X(GLuint, CreateProgram, ())                                                                               \
  X(void, AttachShader, (GLuint, GLuint))                                                                    \
  X(void, LinkProgram, (GLuint))                                                                             \
  X(void, GetProgramiv, (GLuint, GLenum, GLint*))                                                            \
  X(void, GetProgramInfoLog, (GLuint, GLsizei, GLsizei*, GLchar*))                                           \
  X(void, UseProgram, (GLuint))                                                                              \
  X(void, DeleteProgram, (GLuint))                                                                           \
  X(GLint, GetUniformLocation, (GLuint, const GLchar*))                                                      \
  X(void, Uniform1i, (GLint, GLint))                                                                         \
  X(void, Uniform4f, (GLint, GLfloat, GLfloat, GLfloat, GLfloat))                                            \
  X(void, GenTextures, (GLsizei, GLuint*))                                                                   \
  X(void, DeleteTextures, (GLsizei, const GLuint*))                                                          \
  X(void, BindTexture, (GLenum, GLuint))                                                                     \
  X(void, ActiveTexture, (GLenum))                                                                           \
  X(void, TexImage2D, (GLenum, GLint, GLint, GLsizei, GLsizei, GLint, GLenum, GLenum, const void*))          \
  X(void, TexImage3D, (GLenum, GLint, GLint, GLsizei, GLsizei, GLsizei, GLint, GLenum, GLenum, const void*))   \
  X(void, TexParameteri, (GLenum, GLenum, GLint))                                                            \
  X(void, GenFramebuffers, (GLsizei, GLuint*))                                                               \
  X(void, DeleteFramebuffers, (GLsizei, const GLuint*))                                                      \
  X(void, BindFramebuffer, (GLenum, GLuint))                                                                 \
  X(void, FramebufferTexture2D, (GLenum, GLenum, GLenum, GLuint, GLint))                                     \
  X(GLenum, CheckFramebufferStatus, (GLenum))                                                                \
  X(void, GenVertexArrays, (GLsizei, GLuint*))                                                               \
  X(void, DeleteVertexArrays, (GLsizei, const GLuint*))                                                      \
  X(void, BindVertexArray, (GLuint))                                                                         \
  X(void, Viewport, (GLint, GLint, GLsizei, GLsizei))                                                        \
  X(void, DrawArrays, (GLenum, GLint, GLsizei))                                                              \
  X(void, PixelStorei, (GLenum, GLint))                                                                      \
  X(void, ReadPixels, (GLint, GLint, GLsizei, GLsizei, GLenum, GLenum, void*))                               \
  X(void, GetIntegerv, (GLenum, GLint*))                                                                     \
  X(const GLubyte*, GetString, (GLenum))                                                                     \
  X(GLenum, GetError, ())                                                                                    \
  X(void, Finish, ())
#define SKYBAKE_GL_MEMBER(ret, name, args) ret(GL_APIENTRY* name) args = nullptr;
  SKYBAKE_GL_FUNCTIONS(SKYBAKE_GL_MEMBER)
#undef SKYBAKE_GL_MEMBER

  // False (with the missing name) if an entry point is unavailable.
  bool Load(std::string* missing) {
#define SKYBAKE_GL_LOAD(ret, name, args)                                              \
  name = reinterpret_cast<ret(GL_APIENTRY*) args>(eglGetProcAddress("gl" #name)); \
  if (!name) {                                                                        \
    *missing = "gl" #name;                                                            \
    return false;                                                                     \
  }
    SKYBAKE_GL_FUNCTIONS(SKYBAKE_GL_LOAD)
#undef SKYBAKE_GL_LOAD
    return true;
  }
};

std::string EglErrorText(const char* what) {
  char buffer[96];
  std::snprintf(buffer, sizeof(buffer), "%s failed (EGL error 0x%04x)", what, static_cast<unsigned>(eglGetError()));
  return buffer;
}

}  // namespace

struct GlContext::Impl {
  EGLDisplay display = EGL_NO_DISPLAY;
  EGLContext context = EGL_NO_CONTEXT;
  GlFunctions gl;
  struct BoundTexture {
    std::string sampler;
    GLenum target;
    GLuint id;
  };
  std::vector<BoundTexture> textures;  // from SetTexture, units 1, 2, ...
  std::vector<GLuint> programs;        // from CompileFullScreenProgram

  // Binds the textures of SetTexture to their units and samplers of `program`.
  void BindTextures(GLuint program) {
    for (size_t t = 0; t < textures.size(); ++t) {
      gl.ActiveTexture(GLenum(GL_TEXTURE1 + t));
      gl.BindTexture(textures[t].target, textures[t].id);
      gl.Uniform1i(gl.GetUniformLocation(program, textures[t].sampler.c_str()), GLint(1 + t));
    }
    gl.ActiveTexture(GL_TEXTURE0);
  }

  void Check(const char* where) {
    GLenum error = gl.GetError();
    if (error != GL_NO_ERROR) {
      char buffer[128];
      std::snprintf(buffer, sizeof(buffer), "GL error 0x%04x after %s", static_cast<unsigned>(error), where);
      throw std::runtime_error(buffer);
    }
  }

  GLuint Compile(GLenum type, const std::string& source) {
    GLuint shader = gl.CreateShader(type);
    const char* text = source.c_str();
    gl.ShaderSource(shader, 1, &text, nullptr);
    gl.CompileShader(shader);
    GLint ok = 0;
    gl.GetShaderiv(shader, GL_COMPILE_STATUS, &ok);
    if (!ok) {
      char log[4096] = {};
      gl.GetShaderInfoLog(shader, sizeof(log), nullptr, log);
      gl.DeleteShader(shader);
      throw std::runtime_error(std::string(type == GL_VERTEX_SHADER ? "vertex" : "fragment") +
                               " shader does not compile:\n" + log + "\n--- source ---\n" + source);
    }
    return shader;
  }

  // The program of the two shaders; throws with the driver's log if they do not compile or link.
  GLuint Link(const std::string& vertex, const std::string& fragment) {
    GLuint vs = Compile(GL_VERTEX_SHADER, vertex);
    GLuint fs = 0;
    try {
      fs = Compile(GL_FRAGMENT_SHADER, fragment);
    } catch (...) {
      gl.DeleteShader(vs);
      throw;
    }
    GLuint program = gl.CreateProgram();
    gl.AttachShader(program, vs);
    gl.AttachShader(program, fs);
    gl.LinkProgram(program);
    gl.DeleteShader(vs);
    gl.DeleteShader(fs);
    GLint linked = 0;
    gl.GetProgramiv(program, GL_LINK_STATUS, &linked);
    if (!linked) {
      char log[4096] = {};
      gl.GetProgramInfoLog(program, sizeof(log), nullptr, log);
      gl.DeleteProgram(program);
      throw std::runtime_error(std::string("shaders do not link:\n") + log);
    }
    return program;
  }
};

// A triangle that covers the viewport, from gl_VertexID alone (no buffers).
constexpr char kCoveringTriangle[] =
    "void main() {\n"
    "  vec2 p = vec2(float((gl_VertexID & 1) * 4 - 1), float((gl_VertexID & 2) * 2 - 1));\n"
    "  gl_Position = vec4(p, 0.0, 1.0);\n"
    "}\n";

GlContext::GlContext(Api api) : api_(api), impl_(std::make_unique<Impl>()) {}

GlContext::~GlContext() {
  if (impl_ && impl_->context != EGL_NO_CONTEXT) {
    for (const Impl::BoundTexture& t : impl_->textures) impl_->gl.DeleteTextures(1, &t.id);
    for (GLuint program : impl_->programs) impl_->gl.DeleteProgram(program);
    eglMakeCurrent(impl_->display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    eglDestroyContext(impl_->display, impl_->context);
    // No eglTerminate: the headless display is shared by every context of
    // the process, and terminating it would pull contexts from other tests.
  }
}

std::unique_ptr<GlContext> GlContext::Create(Api api, std::string* why_not) {
  auto fail = [&](const std::string& reason) -> std::unique_ptr<GlContext> {
    *why_not = "no headless GL: " + reason;
    return nullptr;
  };
  EGLDisplay display = HeadlessEglDisplay();
  if (display == EGL_NO_DISPLAY) return fail("no surfaceless or device EGL display");

  bool es = api == Api::kGles30;
  if (!eglBindAPI(es ? EGL_OPENGL_ES_API : EGL_OPENGL_API)) return fail(EglErrorText("eglBindAPI"));
  // The default EGL_SURFACE_TYPE is EGL_WINDOW_BIT, which a headless
  // display has none of; ask for pbuffer configs, and fall back to
  // EGL_KHR_no_config_context where there are none.
  const EGLint config_attributes[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE,
                                      es ? EGL_OPENGL_ES3_BIT : EGL_OPENGL_BIT, EGL_NONE};
  EGLConfig config = nullptr;
  EGLint configs = 0;
  if (!eglChooseConfig(display, config_attributes, &config, 1, &configs) || configs < 1) {
    const char* extensions = eglQueryString(display, EGL_EXTENSIONS);
    if (!extensions || !std::strstr(extensions, "EGL_KHR_no_config_context"))
      return fail("no EGL config for " + std::string(es ? "OpenGL ES 3" : "OpenGL") + " on the headless display");
    config = EGL_NO_CONFIG_KHR;
  }
  const EGLint es_attributes[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 0, EGL_NONE};
  const EGLint gl_attributes[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 3,
                                  EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
  EGLContext context = eglCreateContext(display, config, EGL_NO_CONTEXT, es ? es_attributes : gl_attributes);
  if (context == EGL_NO_CONTEXT) return fail(EglErrorText("eglCreateContext"));

  std::unique_ptr<GlContext> result(new GlContext(api));
  result->impl_->display = display;
  result->impl_->context = context;
  // Surfaceless: all rendering goes to framebuffer objects.
  if (!eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context)) return fail(EglErrorText("eglMakeCurrent"));
  std::string missing;
  if (!result->impl_->gl.Load(&missing)) return fail(missing + " cannot be loaded");

  // RGBA32F must be renderable (core in desktop 3.3; EXT_color_buffer_float in ES 3.0).
  GlFunctions& gl = result->impl_->gl;
  GLuint texture = 0, framebuffer = 0;
  gl.GenTextures(1, &texture);
  gl.BindTexture(GL_TEXTURE_2D, texture);
  gl.TexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, 1, 1, 0, GL_RGBA, GL_FLOAT, nullptr);
  gl.GenFramebuffers(1, &framebuffer);
  gl.BindFramebuffer(GL_FRAMEBUFFER, framebuffer);
  gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, texture, 0);
  bool complete = gl.CheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
  gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
  gl.DeleteFramebuffers(1, &framebuffer);
  gl.DeleteTextures(1, &texture);
  gl.GetError();
  if (!complete) return fail("RGBA32F is not renderable on " + result->Description());
  return result;
}

std::string GlContext::VersionLine() const {
  return api_ == Api::kGles30 ? "#version 300 es" : "#version 330 core";
}

std::string GlContext::Description() const {
  auto text = [&](GLenum name) {
    const GLubyte* s = impl_->gl.GetString(name);
    return s ? std::string(reinterpret_cast<const char*>(s)) : std::string("?");
  };
  return text(GL_RENDERER) + ", " + text(GL_VERSION);
}

void GlContext::SetTexture(const std::string& sampler, int width, int height, int depth, const float* rgba,
                           std::size_t values) {
  if (values != std::size_t(4) * width * height * depth) throw std::runtime_error("SetTexture: size mismatch");
  GlFunctions& gl = impl_->gl;
  GLenum target = depth == 1 ? GL_TEXTURE_2D : GL_TEXTURE_3D;
  GLuint id = 0;
  gl.GenTextures(1, &id);
  gl.ActiveTexture(GL_TEXTURE1);
  gl.BindTexture(target, id);
  gl.PixelStorei(GL_UNPACK_ALIGNMENT, 4);
  if (depth == 1) {
    gl.TexImage2D(target, 0, GL_RGBA32F, width, height, 0, GL_RGBA, GL_FLOAT, rgba);
  } else {
    gl.TexImage3D(target, 0, GL_RGBA32F, width, height, depth, 0, GL_RGBA, GL_FLOAT, rgba);
    gl.TexParameteri(target, GL_TEXTURE_WRAP_R, GL_CLAMP_TO_EDGE);
  }
  gl.TexParameteri(target, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  gl.TexParameteri(target, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  gl.TexParameteri(target, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  gl.TexParameteri(target, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  gl.ActiveTexture(GL_TEXTURE0);
  impl_->Check("SetTexture");
  impl_->textures.push_back({sampler, target, id});
}

std::vector<Vec4> GlContext::RunFragmentPass(const std::string& fragment_source, const std::vector<Vec4>& inputs,
                                             int inputs_per_item) {
  if (inputs_per_item < 1 || inputs.size() % inputs_per_item != 0)
    throw std::runtime_error("RunFragmentPass: inputs must hold a whole number of items");
  size_t items = inputs.size() / inputs_per_item;
  if (items == 0) return {};
  Impl& s = *impl_;
  GlFunctions& gl = s.gl;
  GLint max_size = 0;
  gl.GetIntegerv(GL_MAX_TEXTURE_SIZE, &max_size);
  int width = static_cast<int>(std::min<size_t>(items, std::max(1, std::min(kRowWidth, max_size / inputs_per_item))));
  int height = static_cast<int>((items + width - 1) / width);
  if (height > max_size) throw std::runtime_error("RunFragmentPass: too many items for one pass");

  std::string prologue = VersionLine() + "\n" +
                         "precision highp float;\nprecision highp int;\nprecision highp sampler2D;\n";
  std::string vertex = prologue + kCoveringTriangle;
  std::string fragment = prologue + "uniform sampler2D skybake_inputs;\n" +
                         "uniform int skybake_row_width;\n"
                         "uniform int skybake_inputs_per_item;\n"
                         "out vec4 skybake_output;\n"
                         "int skybake_item() {\n"
                         "  return int(gl_FragCoord.y) * skybake_row_width + int(gl_FragCoord.x);\n"
                         "}\n"
                         "vec4 skybake_input(int k) {\n"
                         "  ivec2 texel = ivec2(int(gl_FragCoord.x) * skybake_inputs_per_item + k, int(gl_FragCoord.y));\n"
                         "  return texelFetch(skybake_inputs, texel, 0);\n"
                         "}\n" +
                         "#line 1\n" + fragment_source;

  GLuint program = s.Link(vertex, fragment);

  // Inputs, padded to whole rows.
  std::vector<float> texels(static_cast<size_t>(width) * inputs_per_item * height * 4, 0.0f);
  for (size_t i = 0; i < inputs.size(); ++i)
    for (int c = 0; c < 4; ++c) texels[i * 4 + c] = inputs[i][c];
  GLuint textures[2] = {0, 0}, framebuffer = 0, vao = 0;
  gl.GenTextures(2, textures);
  gl.ActiveTexture(GL_TEXTURE0);
  gl.BindTexture(GL_TEXTURE_2D, textures[0]);
  gl.PixelStorei(GL_UNPACK_ALIGNMENT, 4);
  gl.TexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, width * inputs_per_item, height, 0, GL_RGBA, GL_FLOAT, texels.data());
  // Float textures are not filterable in ES 3.0; texelFetch ignores filtering
  // but the texture must still be complete.
  gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  gl.BindTexture(GL_TEXTURE_2D, textures[1]);
  gl.TexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, width, height, 0, GL_RGBA, GL_FLOAT, nullptr);
  gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  gl.GenFramebuffers(1, &framebuffer);
  gl.BindFramebuffer(GL_FRAMEBUFFER, framebuffer);
  gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, textures[1], 0);
  GLenum status = gl.CheckFramebufferStatus(GL_FRAMEBUFFER);
  std::vector<float> pixels(static_cast<size_t>(width) * height * 4, 0.0f);
  try {
    if (status != GL_FRAMEBUFFER_COMPLETE) throw std::runtime_error("RGBA32F framebuffer is incomplete");
    gl.BindTexture(GL_TEXTURE_2D, textures[0]);
    gl.UseProgram(program);
    gl.Uniform1i(gl.GetUniformLocation(program, "skybake_inputs"), 0);
    gl.Uniform1i(gl.GetUniformLocation(program, "skybake_row_width"), width);
    gl.Uniform1i(gl.GetUniformLocation(program, "skybake_inputs_per_item"), inputs_per_item);
    s.BindTextures(program);
    gl.GenVertexArrays(1, &vao);  // core profiles draw nothing without a bound VAO
    gl.BindVertexArray(vao);
    gl.Viewport(0, 0, width, height);
    gl.DrawArrays(GL_TRIANGLES, 0, 3);
    gl.PixelStorei(GL_PACK_ALIGNMENT, 4);
    gl.ReadPixels(0, 0, width, height, GL_RGBA, GL_FLOAT, pixels.data());
    gl.Finish();
    s.Check("the fragment pass");
  } catch (...) {
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    gl.DeleteFramebuffers(1, &framebuffer);
    gl.DeleteTextures(2, textures);
    gl.DeleteVertexArrays(1, &vao);
    gl.DeleteProgram(program);
    throw;
  }
  gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
  gl.DeleteFramebuffers(1, &framebuffer);
  gl.DeleteTextures(2, textures);
  gl.DeleteVertexArrays(1, &vao);
  gl.DeleteProgram(program);

  std::vector<Vec4> outputs(items);
  for (size_t i = 0; i < items; ++i)
    for (int c = 0; c < 4; ++c) outputs[i][c] = pixels[i * 4 + c];
  return outputs;
}

unsigned GlContext::CompileFullScreenProgram(const std::string& fragment_source) {
  const std::string prologue = VersionLine() + "\n" +
                               "precision highp float;\nprecision highp int;\nprecision highp sampler2D;\n"
                               "precision highp sampler3D;\n";
  const GLuint program =
      impl_->Link(prologue + kCoveringTriangle, prologue + "out vec4 skybake_output;\n#line 1\n" + fragment_source);
  impl_->programs.push_back(program);
  return program;
}

double GlContext::RenderFullScreen(unsigned program, int width, int height,
                                   const std::vector<std::pair<std::string, Vec4>>& uniforms,
                                   std::vector<Vec4>* pixels) {
  Impl& s = *impl_;
  GlFunctions& gl = s.gl;
  if (std::find(s.programs.begin(), s.programs.end(), program) == s.programs.end())
    throw std::runtime_error("RenderFullScreen: not a program of CompileFullScreenProgram");
  GLuint target = 0, framebuffer = 0, vao = 0;
  auto release = [&] {
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    gl.DeleteFramebuffers(1, &framebuffer);
    gl.DeleteTextures(1, &target);
    gl.DeleteVertexArrays(1, &vao);
  };
  double seconds = 0.0;
  try {
    gl.GenTextures(1, &target);
    gl.ActiveTexture(GL_TEXTURE0);
    gl.BindTexture(GL_TEXTURE_2D, target);
    gl.TexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, width, height, 0, GL_RGBA, GL_FLOAT, nullptr);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    gl.BindTexture(GL_TEXTURE_2D, 0);
    gl.GenFramebuffers(1, &framebuffer);
    gl.BindFramebuffer(GL_FRAMEBUFFER, framebuffer);
    gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, target, 0);
    if (gl.CheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
      throw std::runtime_error("RGBA32F framebuffer is incomplete");
    gl.UseProgram(program);
    s.BindTextures(program);
    // A uniform the compiler found unused has location -1, which glUniform ignores.
    for (const auto& [name, value] : uniforms)
      gl.Uniform4f(gl.GetUniformLocation(program, name.c_str()), value[0], value[1], value[2], value[3]);
    gl.GenVertexArrays(1, &vao);  // core profiles draw nothing without a bound VAO
    gl.BindVertexArray(vao);
    gl.Viewport(0, 0, width, height);
    gl.Finish();
    s.Check("the full-screen pass's set-up");
    const auto start = std::chrono::steady_clock::now();
    gl.DrawArrays(GL_TRIANGLES, 0, 3);
    gl.Finish();
    seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    s.Check("the full-screen pass");
    if (pixels) {
      std::vector<float> texels(static_cast<size_t>(width) * height * 4);
      gl.PixelStorei(GL_PACK_ALIGNMENT, 4);
      gl.ReadPixels(0, 0, width, height, GL_RGBA, GL_FLOAT, texels.data());
      s.Check("reading the full-screen pass back");
      pixels->resize(static_cast<size_t>(width) * height);
      for (size_t i = 0; i < pixels->size(); ++i)
        for (int c = 0; c < 4; ++c) (*pixels)[i][c] = texels[i * 4 + c];
    }
  } catch (...) {
    release();
    throw;
  }
  release();
  return seconds;
}

#else  // !SKYBAKE_HAVE_EGL

struct GlContext::Impl {};
GlContext::GlContext(Api api) : api_(api) {}
GlContext::~GlContext() = default;
std::unique_ptr<GlContext> GlContext::Create(Api, std::string* why_not) {
  *why_not = "no headless GL: the tests were built without EGL and GLES 3 headers";
  return nullptr;
}
std::string GlContext::VersionLine() const { return api_ == Api::kGles30 ? "#version 300 es" : "#version 330 core"; }
std::string GlContext::Description() const { return "none"; }
void GlContext::SetTexture(const std::string&, int, int, int, const float*, std::size_t) {
  throw std::runtime_error("no headless GL");
}
std::vector<Vec4> GlContext::RunFragmentPass(const std::string&, const std::vector<Vec4>&, int) {
  throw std::runtime_error("no headless GL");
}
unsigned GlContext::CompileFullScreenProgram(const std::string&) { throw std::runtime_error("no headless GL"); }
double GlContext::RenderFullScreen(unsigned, int, int, const std::vector<std::pair<std::string, Vec4>>&,
                                   std::vector<Vec4>*) {
  throw std::runtime_error("no headless GL");
}

#endif

}  // namespace skybake::testing
