// Plots of table slices through the CPU twin (SVG and PNG via formats/plot.h),
// for people who would rather look than read:
//   lut_transmittance.{svg,png}  transmittance to the top of the atmosphere vs
//                                view zenith, at altitudes 0, 5 and 20 km;
//   lut_sky_radiance.{svg,png}   sky radiance at 550 nm-ish (the middle channel)
//                                seen from the ground in the sun's vertical
//                                plane, vs signed view zenith (negative: away
//                                from the sun), for sun zeniths 0, 45, 80, 90;
//   lut_irradiance.{svg,png}     direct sun and sky irradiance on horizontal
//                                ground vs sun zenith.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "shaders_runtime/glsl_shim.h"

namespace skybake {
class Twin;
}

namespace skybake::render {

struct PlotFiles {
  std::vector<std::filesystem::path> files;  // in the order written
  bool png_text = true;                       // false: no TrueType font, PNGs have no text
};

// Writes the plots into `dir` (which must exist), each file atomically.
// `caption` goes under each plot (e.g. the command line).
PlotFiles WriteLutPlots(const Twin& twin, const glsl::vec3& wavelengths_nm, const std::filesystem::path& dir,
                        const std::string& caption);

}  // namespace skybake::render
