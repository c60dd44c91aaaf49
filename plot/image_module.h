// The few things skybake does through OpenImageIO (image files, text),
// compiled into a module of their own, libskybake_images.so, that is loaded
// the first time one of them is needed (plot/image_library.h).
// OpenImageIO brings about 260 shared libraries, whose loading and
// relocation take about half a second on the build host; linked into the
// executable, every command would pay that, a bake that writes no image
// included.
//
// The module and the executable are built together by the same compiler, so
// the table passes C++ types; errors come back as messages, not exceptions.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace skybake::image_module {

// Bumped whenever Functions changes, so a stale module is refused.
inline constexpr int kVersion = 2;

using Attributes = std::vector<std::pair<std::string, std::string>>;

// Where a text's anchor point is along its baseline.
enum class AlignX { kLeft, kRight, kCenter };

// 8-bit RGB pixels, row-major from the top.
struct Rgb8Canvas {
  int width = 0, height = 0;
  std::uint8_t* rgb = nullptr;
};

struct Functions {
  int version;
  // Writes 8-bit RGB pixels already encoded with the sRGB transfer function
  // as a PNG with the sRGB chunk, `attributes` as text chunks. "" on
  // success, else the error.
  std::string (*write_srgb_png)(const std::string& file, int width, int height, const std::uint8_t* rgb,
                                const Attributes& attributes);
  // Writes linear float RGB pixels as a zip-compressed OpenEXR file with
  // channels R, G, B, `attributes` as header attributes.
  std::string (*write_linear_exr)(const std::string& file, int width, int height, const float* rgb,
                                  const Attributes& attributes);
  // Reads the first three channels of an image file as 8-bit RGB.
  std::string (*read_rgb8)(const std::string& file, int* width, int* height, std::vector<std::uint8_t>* rgb);
  // The first TrueType font found of DejaVu Sans, Liberation Sans and
  // FreeSans; "" if none is.
  std::string (*find_font)();
  // The pixel box [x0, y0, x1, y1) `text` covers when drawn at the origin
  // on its baseline; false if the font cannot draw it.
  bool (*text_box)(const std::string& text, int size, const std::string& font, int box[4]);
  // Draws `text` in `color` (linear 0-1 per channel) onto the canvas, its
  // baseline through (x, y), anchored there as `align_x` says.
  void (*draw_text)(const Rgb8Canvas& canvas, int x, int y, const std::string& text, int size,
                    const std::string& font, const float color[3], AlignX align_x);
};

}  // namespace skybake::image_module

// The module's one exported symbol.
extern "C" const skybake::image_module::Functions* SkybakeImageModule();
