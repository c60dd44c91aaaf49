// Plots of table slices through the CPU twin (SVG and PNG via plot/plot.h),
// for people who would rather look than read:
//   lut_transmittance.{svg,png}  transmittance to the top of the atmosphere vs
//                                view zenith, at altitudes 0, 5 and 20 km;
//   lut_sky_radiance.{svg,png}   sky radiance at 550 nm-ish (the middle channel;
//                                a spectral set's Y, its luminance)
//                                seen from the ground in the sun's vertical
//                                plane, vs signed view zenith (negative: away
//                                from the sun), for sun zeniths 0, 45, 80, 90;
//   lut_irradiance.{svg,png}     direct sun and sky irradiance on horizontal
//                                ground vs sun zenith;
//   lut_sunset.{svg,png}         sky luminance through sunset and twilight
//                                (SunsetCurves).
// A scene's bake (bake/scene.h) holds only some tables and covers only some
// cameras and suns: a plot whose table the set leaves out is not drawn, the
// sky radiance plot keeps only the sun zeniths the scene covers at the
// ground, and each omission is described in PlotFiles::left_out.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "core/file_io.h"
#include "shaders_runtime/glsl_shim.h"

namespace skybake {
struct LutSet;
class Twin;
}

namespace skybake::render {

struct PlotFiles {
  std::vector<std::filesystem::path> files;  // in the order written
  bool png_text = true;                       // false: no TrueType font, PNGs have no text
  // One line per plot or curve left out, e.g.
  // "lut_irradiance: the set has no irradiance table (...)".
  std::vector<std::string> left_out;
};

// Sky luminance (report::Luminance of the three channels, or Y where
// `channels_are_xyz`: a spectral set's) seen from 1 m
// above the ground through sunset and twilight: at the zenith, and 2 degrees
// above the horizon toward the sun and away from it, for sun zenith angles
// from 85 degrees to the table's lowest sun (102 for earth) in 0.05 degree
// steps. The tests hold these to falling smoothly (docs/accuracy.md).
struct SunsetCurves {
  std::vector<double> sun_zenith_deg;
  std::vector<double> zenith, sunward_horizon, antisolar_horizon;
};
SunsetCurves ComputeSunsetCurves(const Twin& twin, bool channels_are_xyz);

// Stages the plots of `luts` into `dir` (which must exist) in `files`
// (core/file_io.h), which the caller commits. `caption` goes under each plot
// (e.g. the command line).
PlotFiles WriteLutPlots(StagedFiles& files, const LutSet& luts, const std::filesystem::path& dir,
                        const std::string& caption);

}  // namespace skybake::render
