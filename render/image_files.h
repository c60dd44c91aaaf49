// Render outputs: linear OpenEXR, tone-mapped sRGB PNG and contact sheets.
//
// Tone mapping (PNG only; the EXR keeps the radiance):
//   1. white balance: each channel is divided by the solar irradiance at the
//      top of the atmosphere relative to its channel mean, so unattenuated
//      sunlight is neutral;
//   2. exposure: multiplied by 2^EV (EV 3.3, about x10, suits a daylight sky
//      in W m^-2 sr^-1 nm^-1: Bruneton's demo uses the same factor);
//   3. tone curve: d = 1 - exp(-x) per channel (monotonic, linear near black,
//      saturates highlights such as the sun smoothly instead of clipping);
//   4. d, taken as linear sRGB (the three wavelengths stand for the primaries),
//      is encoded with the sRGB transfer function (SrgbEncode) and rounded
//      to 8 bits.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "core/file_io.h"
#include "render/views.h"

namespace skybake::render {

struct ToneMap {
  double exposure_ev = 3.3;
  glsl::vec3 white{1.0};  // per-channel white balance divisor (see WhiteBalance)
};

// Auto exposure (`render --exposure auto`) exposes for the part of the sky
// the sun lights. With Y = 0.2126 R + 0.7152 G + 0.0722 B the luminance of a
// pixel's linear radiance, take the n pixels with Y > 0 that show sky
// (Image::sky: rays that miss the ground; from space, the whole planet),
// Y_99 the floor(0.99 n)-th smallest of their Y (from 0; below the few
// pixels of the sun's disc), and Y_med the median (the floor(m/2)-th
// smallest) of Y over the m of them lit, Y >= Y_99 / 100. The exposure is
//   EV = log2(-ln(1 - 0.18) / Y_med),
// so that a grey pixel of luminance Y_med leaves the tone curve at
// 1 - exp(-Y_med 2^EV) = 0.18, mid-grey, before the sRGB transfer function.
// In daylight, and in twilight seen from the ground down to a sun about 95
// degrees from the zenith, no sky pixel is 100 times darker than Y_99, so
// Y_med is the median of the whole sky. Lower suns leave the darkest sky
// out (from the ground at 98 to 102 degrees, 0.2 to 0.8 EV less); from
// space at twilight, the planet's night half, orders of magnitude darker,
// which the median of every pixel exposed for (EV 10 instead of 3 at sun
// 95 degrees, the lit limb white). Where no pixel shows sky (or the image
// has no sky mask) the pixels with Y > 0 are taken instead; an image
// without any gets EV 0.
inline constexpr double kAutoExposureMidGrey = 0.18;
inline constexpr double kAutoExposureLitFraction = 0.01;
double AutoExposureEv(const Image& image);

// The white-balance divisor for a solar irradiance spectrum: irradiance / mean.
glsl::vec3 WhiteBalance(const glsl::vec3& solar_irradiance);

// 8-bit RGB, row-major from the top.
struct Rgb8 {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgb;
};

// The sRGB transfer function of IEC 61966-2-1, linear 0-1 to encoded 0-1:
//   12.92 v                   for v <= 0.0031308,
//   1.055 v^(1/2.4) - 0.055   above.
double SrgbEncode(double linear);

Rgb8 ToneMapToSrgb(const Image& image, const ToneMap& tone);

// Text attributes stored in the files (e.g. the command line).
using Attributes = std::vector<std::pair<std::string, std::string>>;

// Both staged into `files` (core/file_io.h), which the caller commits;
// IoError on failure. The PNG carries an sRGB
// chunk (plot/plot.h WriteSrgbPng).
void WriteLinearExr(StagedFiles& files, const std::filesystem::path& path, const Image& image,
                    const Attributes& attributes);
void WritePng(StagedFiles& files, const std::filesystem::path& path, const Rgb8& image, const Attributes& attributes);

// Reads an 8-bit RGB PNG (tests and tools); IoError on failure.
Rgb8 ReadPng(const std::filesystem::path& path);

// Columns side by side, each column's images stacked top to bottom, with a
// `gap`-pixel dark separator; a column's label is drawn above it when a
// TrueType font (DejaVu Sans, Liberation Sans, FreeSans) is found.
Rgb8 ContactSheet(const std::vector<std::vector<const Rgb8*>>& columns, const std::vector<std::string>& labels,
                  int gap = 4);

}  // namespace skybake::render
