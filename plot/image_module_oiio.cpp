// libskybake_images.so: plot/image_module.h's functions through OpenImageIO.
#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include "plot/image_module.h"

namespace skybake::image_module {
namespace {

using namespace OIIO;

void Annotate(ImageSpec* spec, const Attributes& attributes) {
  for (const auto& [key, value] : attributes) spec->attribute(key, value);
}

// The file name may lack an image extension (a temporary name), so the
// format is named explicitly.
std::string Write(const ImageBuf& image, const std::string& file, TypeDesc type, const char* format) {
  if (image.write(file, type, format)) return "";
  const std::string error = image.geterror();
  return "cannot write " + std::string(format) + (error.empty() ? "" : ": " + error);
}

std::string WriteSrgbPng(const std::string& file, int width, int height, const std::uint8_t* rgb,
                         const Attributes& attributes) {
  ImageSpec spec(width, height, 3, TypeDesc::UINT8);
  Annotate(&spec, attributes);
  // OpenImageIO's PNG writer turns this colour space into the sRGB chunk.
  spec.attribute("oiio:ColorSpace", "sRGB");
  ImageBuf image(spec);
  image.set_pixels(ROI::All(), TypeDesc::UINT8, rgb);
  return Write(image, file, TypeDesc::UINT8, "png");
}

std::string WriteLinearExr(const std::string& file, int width, int height, const float* rgb,
                           const Attributes& attributes) {
  ImageSpec spec(width, height, 3, TypeDesc::FLOAT);
  spec.channelnames = {"R", "G", "B"};
  spec.attribute("compression", "zip");
  Annotate(&spec, attributes);
  ImageBuf image(spec);
  image.set_pixels(ROI::All(), TypeDesc::FLOAT, rgb);
  return Write(image, file, TypeDesc::FLOAT, "openexr");
}

std::string ReadRgb8(const std::string& file, int* width, int* height, std::vector<std::uint8_t>* rgb) {
  ImageBuf image(file);
  if (!image.read(0, 0, true, TypeDesc::UINT8) || image.spec().nchannels < 3) {
    const std::string error = image.geterror();
    return "cannot read an RGB image" + (error.empty() ? "" : ": " + error);
  }
  *width = image.spec().width;
  *height = image.spec().height;
  rgb->resize(std::size_t(3) * *width * *height);
  image.get_pixels(ROI(0, *width, 0, *height, 0, 1, 0, 3), TypeDesc::UINT8, rgb->data());
  return "";
}

std::string FindFont() {
  for (const char* candidate : {"DejaVuSans", "LiberationSans-Regular", "FreeSans"})
    if (ImageBufAlgo::text_size("0", 12, candidate).defined()) return candidate;
  return "";
}

bool TextBox(const std::string& text, int size, const std::string& font, int box[4]) {
  const ROI roi = ImageBufAlgo::text_size(text, size, font);
  if (!roi.defined()) return false;
  box[0] = roi.xbegin, box[1] = roi.ybegin, box[2] = roi.xend, box[3] = roi.yend;
  return true;
}

void DrawText(const Rgb8Canvas& canvas, int x, int y, const std::string& text, int size, const std::string& font,
              const float color[3], AlignX align_x) {
  // Draws in place: the ImageBuf wraps the canvas's pixels.
  ImageBuf image(ImageSpec(canvas.width, canvas.height, 3, TypeDesc::UINT8), canvas.rgb);
  const auto ax = align_x == AlignX::kLeft    ? ImageBufAlgo::TextAlignX::Left
                  : align_x == AlignX::kRight ? ImageBufAlgo::TextAlignX::Right
                                              : ImageBufAlgo::TextAlignX::Center;
  ImageBufAlgo::render_text(image, x, y, text, size, font, cspan<float>(color, 3), ax,
                            ImageBufAlgo::TextAlignY::Baseline);
}

constexpr Functions kFunctions{kVersion, WriteSrgbPng, WriteLinearExr, ReadRgb8, FindFont, TextBox, DrawText};

}  // namespace
}  // namespace skybake::image_module

extern "C" __attribute__((visibility("default"))) const skybake::image_module::Functions* SkybakeImageModule() {
  return &skybake::image_module::kFunctions;
}
