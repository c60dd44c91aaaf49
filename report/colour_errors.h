// The colour error of `skybake report` (docs/colour.md): a spectral set
// (tables in CIE 1931 XYZ, bake/spectral.h) and a three-wavelength set read
// as linear sRGB, as an engine reads its red, green and blue, both against a
// spectral reference converted exactly (`skybake reference --wavelengths N`),
// per case group: the relative error of the luminance Y and the chromaticity
// difference Delta u'v' (CIE 1976 UCS).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "bake/bake.h"
#include "report/case_errors.h"

namespace skybake::report {

// RMS and largest of the relative luminance error and of Delta u'v' over a
// group's cases.
struct ColourStats {
  int cases = 0;
  double luminance_rms = 0.0, luminance_max = 0.0;
  double delta_uv_rms = 0.0, delta_uv_max = 0.0;
};

struct ColourGroup {
  std::string name;
  ColourStats spectral, as_srgb;
};

struct ColourErrors {
  int wavelengths = 0;  // of the spectral set
  // Of those, how many computed the scattering orders >= 2 (the others'
  // interpolated, bake/spectral.h).
  int higher_order_wavelengths = 0;
  double spectral_bake_seconds = 0.0;
  // The three-wavelength set's values are in the atmosphere's solar units,
  // not cd m^-2: its luminance is compared after this one scale, fitted (least
  // squares) on the daylight group, so that what is left is its error of shape.
  double as_srgb_luminance_scale = 1.0;
  std::vector<ColourGroup> groups;  // in kColourGroups' order, those with cases

  // The entry for `name`; InternalError if there is none.
  const ColourGroup& Group(const std::string& name) const;
};

// The case groups, the reference's own split by sun zenith in twilight (the
// targets differ to sun 90, 96 and beyond) and the irradiance cases' sky
// irradiance.
inline const char* const kColourGroups[] = {"daylight",           "horizon",        "space",
                                            "aerial_perspective", "twilight to 90", "twilight 91-96",
                                            "twilight 97-100",    "sky_irradiance"};

// The spectral reference for `atmosphere_name` ("<name>_spectral_reference.csv",
// committed for earth: 15 wavelengths), or `file` where it is given; nullopt
// where neither exists. InputError for a file without X, Y, Z columns.
std::optional<ReferenceSet> LoadSpectralReference(const std::string& file, const std::string& atmosphere_name);

// `spectral` (colour tables) and `three_wavelength` (the same atmosphere at
// its three wavelengths) answered through the CPU twin on every case of
// `reference` where the reference's Y is positive. InputError if `spectral`
// holds no colour tables or `three_wavelength` does.
ColourErrors MeasureColourErrors(const ReferenceSet& reference, const LutSet& spectral,
                                 const LutSet& three_wavelength);

// The Markdown table of the report's "Colour" section, and its report.json object.
std::string ColourMarkdown(const ColourErrors& errors);
nlohmann::json ColourJson(const ColourErrors& errors);

}  // namespace skybake::report
