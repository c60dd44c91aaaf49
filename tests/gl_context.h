// A headless OpenGL context for tests that run shaders on a real driver
// (Mesa llvmpipe here, or a GPU) and read the results back.
//
// The context comes from EGL with no window system (HeadlessEglDisplay:
// Mesa's surfaceless platform, which needs no GPU, or an EGL device).
// Every GL entry point is loaded through eglGetProcAddress, which is how
// one helper serves both OpenGL ES 3.0 and desktop OpenGL 3.3 core without
// linking either library.
//
// Typical use:
//   std::string why;
//   auto gl = skybake::testing::GlContext::Create(GlContext::Api::kGles30, &why);
//   if (!gl) GTEST_SKIP() << why;
//   auto out = gl->RunFragmentPass("void main() { skybake_output = skybake_input(0) * 2.0; }", inputs);
#pragma once

#include <array>
#include <cstddef>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace skybake::testing {

using Vec4 = std::array<float, 4>;

class GlContext {
 public:
  enum class Api { kGles30, kDesktop33Core };

  // Empty, with `why_not` set to a one-line reason, if no EGL display or
  // context of that API can be created, or RGBA32F is not renderable.
  static std::unique_ptr<GlContext> Create(Api api, std::string* why_not);
  ~GlContext();
  GlContext(const GlContext&) = delete;
  GlContext& operator=(const GlContext&) = delete;

  Api api() const { return api_; }
  // "#version 300 es" or "#version 330 core".
  std::string VersionLine() const;
  // GL_RENDERER and GL_VERSION, e.g. "llvmpipe (LLVM 15.0.6, 256 bits), OpenGL ES 3.2 Mesa 22.3.6".
  std::string Description() const;

  // Evaluates a fragment shader once per item and returns one vec4 per item.
  // There are inputs.size() / inputs_per_item items; item i reads its inputs
  // i*inputs_per_item ... from an RGBA32F texture and writes an RGBA32F
  // texel. The target is items x 1 texels, wrapped into rows of 1024 for
  // more items. The helper puts before `fragment_source`: the version line,
  // `precision highp float; precision highp int; precision highp sampler2D;`,
  //   uniform sampler2D skybake_inputs;
  //   out vec4 skybake_output;
  //   int skybake_item();               // 0-based index of this item
  //   vec4 skybake_input(int k);        // k-th input of this item
  // so the caller's source holds its functions and a main() that writes
  // skybake_output. Throws std::runtime_error with the driver's log if the
  // shaders do not compile or link, or on any GL error.
  // An RGBA32F texture (depth 1: 2D, else 3D), x fastest, sampled with
  // GL_LINEAR and GL_CLAMP_TO_EDGE, bound for every later fragment pass to
  // the sampler uniform `sampler`, which the caller's source declares.
  // Float linear filtering needs OES_texture_float_linear on ES 3.0.
  // The `values` floats from `rgba`, width * height * depth * 4 of them.
  void SetTexture(const std::string& sampler, int width, int height, int depth, const float* rgba, std::size_t values);

  std::vector<Vec4> RunFragmentPass(const std::string& fragment_source, const std::vector<Vec4>& inputs,
                                    int inputs_per_item = 1);

  // Full-screen passes that are compiled once and drawn many times, for
  // timing a shader (tests/runtime_cost.cpp). The helper puts before
  // `fragment_source` the version line,
  // `precision highp float; precision highp int; precision highp sampler2D; precision highp sampler3D;`
  // and `out vec4 skybake_output;`; the caller's main() derives its pixel
  // from gl_FragCoord and its parameters from uniforms. Returns the program,
  // which lives as long as the context. Throws std::runtime_error with the
  // driver's log if the shaders do not compile or link.
  unsigned CompileFullScreenProgram(const std::string& fragment_source);
  // Draws `program` over a width x height RGBA32F target, with the textures
  // of SetTexture bound and each vec4 uniform of `uniforms` set by name (one
  // the program does not use is ignored), and
  // returns the wall seconds from the draw call until glFinish returns (the
  // set-up before the draw is finished first and not counted). A driver that
  // compiles a shader at its first draw (llvmpipe does) counts that compile
  // in the first call: draw once untimed before timing. The target's texels,
  // row by row from gl_FragCoord.y = 0.5, go to `pixels` if not null.
  double RenderFullScreen(unsigned program, int width, int height,
                          const std::vector<std::pair<std::string, Vec4>>& uniforms, std::vector<Vec4>* pixels);

 private:
  struct Impl;
  explicit GlContext(Api api);
  Api api_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace skybake::testing
