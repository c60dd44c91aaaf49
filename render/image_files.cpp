#include "render/image_files.h"

#include <algorithm>
#include <cmath>

#include "core/file_io.h"
#include "plot/image_library.h"
#include "plot/plot.h"
#include "report/error_stats.h"

namespace skybake::render {

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
  // The part the sun lights: at least kAutoExposureLitFraction of Y_99.
  auto y99 = chosen.begin() + std::min(chosen.size() - 1, std::size_t(0.99 * double(chosen.size())));
  std::nth_element(chosen.begin(), y99, chosen.end());
  const double lit_floor = kAutoExposureLitFraction * *y99;
  chosen.erase(std::remove_if(chosen.begin(), chosen.end(), [&](double y) { return y < lit_floor; }), chosen.end());
  auto median = chosen.begin() + chosen.size() / 2;
  std::nth_element(chosen.begin(), median, chosen.end());
  return std::log2(-std::log(1.0 - kAutoExposureMidGrey) / *median);
}

double SrgbEncode(double linear) {
  return linear <= 0.0031308 ? 12.92 * linear : 1.055 * std::pow(linear, 1.0 / 2.4) - 0.055;
}

Rgb8 ToneMapToSrgb(const Image& image, const ToneMap& tone) {
  const double scale = std::exp2(tone.exposure_ev);
  Rgb8 out{image.width, image.height, std::vector<std::uint8_t>(image.rgb.size())};
  for (std::size_t i = 0; i < image.rgb.size(); ++i) {
    const double x = std::max(0.0, double(image.rgb[i])) * scale / tone.white[static_cast<int>(i % 3)];
    const double display = 1.0 - std::exp(-x);
    out.rgb[i] = static_cast<std::uint8_t>(std::lround(std::clamp(SrgbEncode(display), 0.0, 1.0) * 255.0));
  }
  return out;
}

void WriteLinearExr(StagedFiles& files, const std::filesystem::path& path, const Image& image,
                    const Attributes& attributes) {
  const image_module::Functions& images = ImageModule();
  files.Write(path, [&](const std::filesystem::path& temp) {
    ThrowIfImageError(path,
                      images.write_linear_exr(temp.string(), image.width, image.height, image.rgb.data(), attributes));
  });
}

void WritePng(StagedFiles& files, const std::filesystem::path& path, const Rgb8& image, const Attributes& attributes) {
  WriteSrgbPng(files, path, image.width, image.height, image.rgb.data(), attributes);
}

Rgb8 ReadPng(const std::filesystem::path& path) {
  Rgb8 out;
  ThrowIfImageError(path, ImageModule().read_rgb8(path.string(), &out.width, &out.height, &out.rgb));
  return out;
}

Rgb8 ContactSheet(const std::vector<std::vector<const Rgb8*>>& columns, const std::vector<std::string>& labels,
                  int gap) {
  const image_module::Functions& images = ImageModule();
  const std::string font = labels.empty() ? "" : images.find_font();
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
  const std::uint8_t background = 20;  // 0.08 of full scale
  const float ink[3] = {0.9f, 0.9f, 0.9f};
  Rgb8 sheet{width, std::max(height, 1), {}};
  sheet.rgb.assign(std::size_t(3) * sheet.width * sheet.height, background);
  int x = gap;
  for (std::size_t c = 0; c < columns.size(); ++c) {
    int y = gap + label_height, column_width = 0;
    for (const Rgb8* image : columns[c]) {
      for (int row = 0; row < image->height; ++row) {
        const std::uint8_t* from = &image->rgb[3 * std::size_t(row) * image->width];
        std::copy(from, from + 3 * image->width, &sheet.rgb[3 * (std::size_t(y + row) * sheet.width + x)]);
      }
      y += image->height + gap;
      column_width = std::max(column_width, image->width);
    }
    if (!font.empty() && c < labels.size()) {
      images.draw_text({sheet.width, sheet.height, sheet.rgb.data()}, x + column_width / 2, gap + label_height - 6,
                       labels[c], 14, font, ink, image_module::AlignX::kCenter);
    }
    x += column_width + gap;
  }
  return sheet;
}

}  // namespace skybake::render
