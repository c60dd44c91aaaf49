#include "render/image_files.h"

#include <algorithm>
#include <cmath>

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include "core/errors.h"
#include "core/file_io.h"
#include "plot/plot.h"
#include "report/error_stats.h"

namespace skybake::render {

namespace {

void Annotate(OIIO::ImageSpec* spec, const Attributes& attributes) {
  for (const auto& [key, value] : attributes) spec->attribute(key, value);
}

void WriteAtomically(const std::filesystem::path& path, const OIIO::ImageBuf& image, OIIO::TypeDesc type,
                     const char* format) {
  WriteFileAtomically(path, [&](const std::filesystem::path& temp) {
    // The temporary name has no image extension, so name the format explicitly.
    if (!image.write(temp.string(), type, format))
      throw IoError(path.string() + ": cannot write " + format + ": " + image.geterror());
  });
}

std::string FindFont() {
  for (const char* candidate : {"DejaVuSans", "LiberationSans-Regular", "FreeSans"})
    if (OIIO::ImageBufAlgo::text_size("0", 12, candidate).defined()) return candidate;
  return "";
}

}  // namespace

glsl::vec3 WhiteBalance(const glsl::vec3& solar_irradiance) {
  double mean = (solar_irradiance.x + solar_irradiance.y + solar_irradiance.z) / 3.0;
  if (!(mean > 0.0)) return glsl::vec3(1.0);
  return solar_irradiance / mean;
}

double AutoExposureEv(const Image& image) {
  const std::size_t pixels = std::size_t(image.width) * image.height;
  std::vector<double> sky, lit;
  for (std::size_t i = 0; i < pixels; ++i) {
    const double y = report::Luminance(glm::dvec3(image.rgb[3 * i], image.rgb[3 * i + 1], image.rgb[3 * i + 2]));
    if (!(y > 0.0)) continue;
    lit.push_back(y);
    if (i < image.sky.size() && image.sky[i]) sky.push_back(y);
  }
  std::vector<double>& chosen = sky.empty() ? lit : sky;
  if (chosen.empty()) return 0.0;
  auto median = chosen.begin() + chosen.size() / 2;
  std::nth_element(chosen.begin(), median, chosen.end());
  return std::log2(-std::log(1.0 - kAutoExposureMidGrey) / *median);
}

Rgb8 ToneMapToSrgb(const Image& image, const ToneMap& tone) {
  using namespace OIIO;
  double scale = std::exp2(tone.exposure_ev);
  std::vector<float> display(image.rgb.size());
  for (std::size_t i = 0; i < display.size(); ++i) {
    double x = std::max(0.0, double(image.rgb[i])) * scale / tone.white[static_cast<int>(i % 3)];
    display[i] = static_cast<float>(1.0 - std::exp(-x));
  }
  ImageBuf linear(ImageSpec(image.width, image.height, 3, TypeDesc::FLOAT), display.data());
  ImageBuf srgb;
  if (!ImageBufAlgo::colorconvert(srgb, linear, "linear", "sRGB"))
    throw InternalError("render: colour conversion linear -> sRGB failed: " + srgb.geterror());
  Rgb8 out{image.width, image.height, std::vector<std::uint8_t>(display.size())};
  std::vector<float> encoded(display.size());
  srgb.get_pixels(ROI::All(), TypeDesc::FLOAT, encoded.data());
  for (std::size_t i = 0; i < encoded.size(); ++i)
    out.rgb[i] = static_cast<std::uint8_t>(std::lround(std::clamp(encoded[i], 0.0f, 1.0f) * 255.0f));
  return out;
}

void WriteLinearExr(const std::filesystem::path& path, const Image& image, const Attributes& attributes) {
  using namespace OIIO;
  ImageSpec spec(image.width, image.height, 3, TypeDesc::FLOAT);
  spec.channelnames = {"R", "G", "B"};
  spec.attribute("compression", "zip");
  Annotate(&spec, attributes);
  ImageBuf buffer(spec);
  buffer.set_pixels(ROI::All(), TypeDesc::FLOAT, image.rgb.data());
  WriteAtomically(path, buffer, TypeDesc::FLOAT, "openexr");
}

void WritePng(const std::filesystem::path& path, const Rgb8& image, const Attributes& attributes) {
  WriteSrgbPng(path, image.width, image.height, image.rgb.data(), attributes);
}

Rgb8 ReadPng(const std::filesystem::path& path) {
  using namespace OIIO;
  ImageBuf buffer(path.string());
  if (!buffer.read(0, 0, true, TypeDesc::UINT8) || buffer.spec().nchannels < 3)
    throw IoError(path.string() + ": cannot read an RGB PNG: " + buffer.geterror());
  Rgb8 out{buffer.spec().width, buffer.spec().height, {}};
  out.rgb.resize(std::size_t(3) * out.width * out.height);
  buffer.get_pixels(ROI(0, out.width, 0, out.height, 0, 1, 0, 3), TypeDesc::UINT8, out.rgb.data());
  return out;
}

Rgb8 ContactSheet(const std::vector<std::vector<const Rgb8*>>& columns, const std::vector<std::string>& labels,
                  int gap) {
  using namespace OIIO;
  std::string font = labels.empty() ? "" : FindFont();
  const int label_height = font.empty() ? 0 : 22;
  int width = gap, height = 0;
  for (const auto& column : columns) {
    int column_width = 0, column_height = label_height + gap;
    for (const Rgb8* image : column) {
      column_width = std::max(column_width, image->width);
      column_height += image->height + gap;
    }
    width += column_width + gap;
    height = std::max(height, column_height);
  }
  const float background[3] = {0.08f, 0.08f, 0.08f}, ink[3] = {0.9f, 0.9f, 0.9f};
  ImageBuf sheet(ImageSpec(width, std::max(height, 1), 3, TypeDesc::FLOAT));
  ImageBufAlgo::fill(sheet, background);
  int x = gap;
  for (std::size_t c = 0; c < columns.size(); ++c) {
    int y = gap + label_height, column_width = 0;
    for (const Rgb8* image : columns[c]) {
      ImageBuf tile(ImageSpec(image->width, image->height, 3, TypeDesc::UINT8));
      tile.set_pixels(ROI::All(), TypeDesc::UINT8, image->rgb.data());
      ImageBufAlgo::paste(sheet, x, y, 0, 0, tile);
      y += image->height + gap;
      column_width = std::max(column_width, image->width);
    }
    if (!font.empty() && c < labels.size())
      ImageBufAlgo::render_text(sheet, x + column_width / 2, gap + label_height - 6, labels[c], 14, font,
                                cspan<float>(ink, 3), ImageBufAlgo::TextAlignX::Center);
    x += column_width + gap;
  }
  Rgb8 out{sheet.spec().width, sheet.spec().height, {}};
  out.rgb.resize(std::size_t(3) * out.width * out.height);
  sheet.get_pixels(ROI::All(), TypeDesc::UINT8, out.rgb.data());
  return out;
}

}  // namespace skybake::render
