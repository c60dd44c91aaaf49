// Atmosphere files (TOML) and the built-in presets.
//
// Every error names the source, the key path and the problem on one line,
// e.g. "mars.toml: constituents.dust.phase.g = 1.2 is outside (-1, 1)", and is
// thrown as InputError (exit code 2). Unknown keys are errors. The file format
// is documented in examples/atmospheres/README.md.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "bake/atmosphere.h"
#include "core/file_io.h"

namespace skybake {

// Parses and validates an atmosphere description. `source_name` prefixes
// error messages (usually InputName's). With `wavelengths_nm`, every
// per-wavelength value is taken at those wavelengths instead of the file's
// [spectrum] (the batches of a spectral bake, bake/spectral.h); a value the
// file gives as an array of 3 then has no meaning there and is an InputError,
// but for planet.ground_albedo, read as the smooth reflectance spectrum
// through its three values (SmoothReflectance, bake/spectral_form.h).
Atmosphere ParseAtmosphere(std::string_view toml_text, const std::string& source_name,
                           std::optional<Spectrum> wavelengths_nm = std::nullopt);

// How messages (and the `file` of --json errors) name an input: "standard
// input" for "-", else the path as the user gave it, so that it finds the
// file from where the command ran.
std::string InputName(const std::string& path);

// An atmosphere named on the command line, by one rule:
// - "preset:NAME" is always the built-in preset NAME (InputError if none);
// - "-" is standard input;
// - a path with a '/' or ending in ".toml" is always a file;
// - any other word is the preset of that name where one exists (a file or
//   folder of the same name does not hide it: write ./NAME for the file),
//   otherwise a file.
// A missing or unreadable file is an IoError.
Atmosphere LoadAtmosphere(const std::string& file_or_preset);

// The text of the atmosphere `file_or_preset` names (LoadAtmosphere's rule)
// and the name its messages use, read once: a spectral bake parses it at
// each batch of wavelengths.
struct AtmosphereSource {
  std::string text;
  std::string name;
  std::string file = {};  // the file read, as named; empty for a preset or standard input
};
AtmosphereSource ReadAtmosphereSource(const std::string& file_or_preset);

// The name a batch bake gives the output of `file_or_preset`: the preset's
// name, or the file name without ".toml".
std::string AtmosphereSourceName(const std::string& file_or_preset);

struct PresetInfo {
  std::string name;
  std::string description;
};
std::vector<PresetInfo> ListPresets();
Atmosphere LoadPreset(const std::string& name);  // InputError if unknown

// The resolved atmosphere as canonical TOML in SI keys; parsing it back gives
// the same Atmosphere (tested), so `skybake validate` output is a valid input.
// Each per-wavelength value keeps the form the file gave it in (a law, a
// table, a published spectrum: the Atmosphere's SpectralForms, where they
// still give its values), so the output bakes spectrally as the file does;
// values given as three numbers, or built by hand, are written as arrays.
std::string ToToml(const Atmosphere& atmosphere);

// The same canonical model as a JSON object with the same keys, for tools that
// would rather not parse TOML (`skybake validate --json`); its per-wavelength
// values are the numbers at the three wavelengths, not their forms.
std::string ToJson(const Atmosphere& atmosphere);

// Throws InputError if the atmosphere is not physically meaningful (negative
// or non-finite coefficients, top radius <= ground radius, |g| >= 1, ...).
// ParseAtmosphere calls it; code that builds an Atmosphere by hand should too.
void Validate(const Atmosphere& atmosphere, const std::string& source_name);

}  // namespace skybake
