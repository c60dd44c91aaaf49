#include "shaders_runtime/snippet.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cstdio>
#include <stdexcept>

#include "core/version.h"
#include "shaders_runtime/embedded_text.h"

namespace skybake {

namespace {

// A GLSL float literal that reads back as the same float: 9 significant
// digits, always with a '.' or an exponent so it never parses as an int.
std::string FloatLiteral(double value) {
  char buffer[40];
  std::snprintf(buffer, sizeof(buffer), "%.9g", static_cast<double>(static_cast<float>(value)));
  std::string text = buffer;
  if (text.find_first_of(".e") == std::string::npos) text += ".0";
  return text;
}

// How each language spells the constants file's few constructs.
struct ConstantSyntax {
  const char* extension;
  const char* vec3;              // a vec3 constructor, up to its '('
  const char* vec3_constant;     // declares a vec3 constant, up to its name
  const char* struct_constant;   // declares ATMOSPHERE, up to its name
  const char* struct_open;       // after "ATMOSPHERE = "
  const char* struct_close;
  std::string array_open;        // a profile array of ALTITUDE_PROFILE_SIZE vec3s
  const char* array_close;
};

const ConstantSyntax& Syntax(ShadingLanguage language) {
  static const ConstantSyntax glsl_syntax{"glsl", "vec3(", "const vec3 ", "const AtmosphereParameters ",
                                          "AtmosphereParameters(", ")", "vec3[ALTITUDE_PROFILE_SIZE](", ")"};
  static const ConstantSyntax hlsl_syntax{"hlsl", "float3(", "static const float3 ", "static const AtmosphereParameters ",
                                          "{", "}", "{", "}"};
  static const ConstantSyntax msl_syntax{"metal", "float3(", "constant float3 ", "constant AtmosphereParameters ",
                                         "{", "}", "{", "}"};
  static const ConstantSyntax wgsl_syntax{"wgsl", "vec3<f32>(", "const ", "const ", "AtmosphereParameters(", ")",
                                          "array<vec3<f32>, " + std::to_string(glsl::ALTITUDE_PROFILE_SIZE) + ">(",
                                          ")"};
  switch (language) {
    case ShadingLanguage::kGlsl: return glsl_syntax;
    case ShadingLanguage::kHlsl: return hlsl_syntax;
    case ShadingLanguage::kMsl: return msl_syntax;
    case ShadingLanguage::kWgsl: return wgsl_syntax;
  }
  throw std::logic_error("unknown shading language");
}

std::string Vec3Literal(const ConstantSyntax& syntax, const glsl::vec3& v) {
  return syntax.vec3 + FloatLiteral(v.x) + ", " + FloatLiteral(v.y) + ", " + FloatLiteral(v.z) + ")";
}

// One profile array, one sample per line.
std::string ProfileLiteral(const ConstantSyntax& syntax, const glsl::vec3 (&profile)[glsl::ALTITUDE_PROFILE_SIZE]) {
  std::string s = syntax.array_open;
  for (int i = 0; i < glsl::ALTITUDE_PROFILE_SIZE; ++i) {
    s += (i ? ",\n        " : "\n        ") + Vec3Literal(syntax, profile[i]);
  }
  return s + syntax.array_close;
}

std::string_view EmbeddedShader(const std::string& name) {
  for (const EmbeddedText& file : kRuntimeShaderFiles)
    if (file.name == name) return file.text;
  throw std::logic_error("runtime shader " + name + " is not embedded");
}

// The switches saying which of the optional tables' functions exist, with
// their values for `parts`.
std::array<std::pair<const char*, bool>, 3> TableSwitches(const SnippetParts& parts) {
  return {{{"SKYBAKE_HAS_SCATTERING_TEXTURE", parts.scattering},
           {"SKYBAKE_HAS_IRRADIANCE_TEXTURE", parts.irradiance},
           {"SKYBAKE_HAS_AERIAL_PERSPECTIVE", parts.aerial_perspective}}};
}

// functions.wgsl without the functions whose tables `parts` leaves out.
// WGSL has no preprocessor; translate.mjs marks each function that needs a
// table with a line "// skybake: needs FLAG [&& FLAG]" before it, and naga
// closes every function with a "}" line of its own.
std::string WgslFunctionsFor(std::string_view text, const SnippetParts& parts) {
  constexpr std::string_view kMarker = "// skybake: needs ";
  std::string out;
  bool skipping = false;
  for (size_t start = 0; start < text.size();) {
    const size_t end = std::min(text.find('\n', start), text.size());
    const std::string_view line = text.substr(start, end - start);
    start = end + 1;
    if (skipping) {
      skipping = line != "}";
      continue;
    }
    if (line.substr(0, kMarker.size()) == kMarker) {
      for (const auto& [name, on] : TableSwitches(parts)) {
        skipping = skipping || (!on && line.find(name) != std::string_view::npos);
      }
    }
    if (!skipping) out.append(line).append("\n");
  }
  return out;
}

}  // namespace

const char* ShadingLanguageName(ShadingLanguage language) {
  switch (language) {
    case ShadingLanguage::kGlsl: return "glsl";
    case ShadingLanguage::kHlsl: return "hlsl";
    case ShadingLanguage::kMsl: return "msl";
    case ShadingLanguage::kWgsl: return "wgsl";
  }
  throw std::logic_error("unknown shading language");
}

std::optional<ShadingLanguage> ParseShadingLanguage(std::string_view name) {
  for (ShadingLanguage language : kShadingLanguages)
    if (name == ShadingLanguageName(language)) return language;
  return std::nullopt;
}

std::string AtmosphereConstants(ShadingLanguage language, const glsl::AtmosphereParameters& p,
                                const glsl::vec3& wavelengths_nm, const std::string& atmosphere_name,
                                const SnippetParts& parts) {
  if (parts.aerial_perspective && !parts.scattering) {
    throw std::logic_error("aerial perspective needs the scattering table");
  }
  const ConstantSyntax& syntax = Syntax(language);
  const std::string ext = syntax.extension;
  const bool wgsl = language == ShadingLanguage::kWgsl;  // no preprocessor: switches are constants
  auto flag = [&](const char* name, bool on) {
    if (wgsl) return std::string("const ") + name + (on ? " = true;\n" : " = false;\n");
    return std::string("#define ") + name + (on ? " 1\n" : " 0\n");
  };
  auto vec3_constant = [&](const char* name, const glsl::vec3& v) {
    return syntax.vec3_constant + std::string(name) + " = " + Vec3Literal(syntax, v) + ";\n";
  };
  const bool separate_mie = p.single_mie_in_scattering_alpha == 0;
  std::string s;
  s += "// Generated by skybake " SKYBAKE_VERSION " for the atmosphere '" + atmosphere_name +
       "' and the table sizes of this bake (the manifest's \"parameters\"). " +
       (wgsl ? std::string("Include with functions.wgsl (WGSL declarations may come in any order).\n")
             : "Include after definitions." + ext + " and before functions." + ext + ".\n");
  s += flag("SKYBAKE_HAS_TRANSMITTANCE_TEXTURE", true);
  for (const auto& [name, on] : TableSwitches(parts)) s += flag(name, on);
  s += std::string(wgsl ? "// false" : "// 0") + ": single Mie is packed into the scattering table's alpha; pass the scattering\n" +
       "// texture as single_mie_scattering_texture too.\n";
  s += flag("SKYBAKE_HAS_SINGLE_MIE_SCATTERING_TEXTURE", parts.scattering && separate_mie);
  if (parts.channels_are_xyz) {
    s += "// The channels are CIE 1931 XYZ of a spectral bake: Y is luminance in cd m^-2 (illuminance in lx),\n"
         "// X and Z alike; the manifest's colour.xyz_to_linear_srgb converts to linear sRGB. No one wavelength\n"
         "// per channel: SKYBAKE_WAVELENGTHS_NM is 0.\n";
  } else {
    s += "// Wavelength of each RGB channel, nm.\n";
  }
  s += flag("SKYBAKE_CHANNELS_ARE_XYZ", parts.channels_are_xyz);
  s += vec3_constant("SKYBAKE_WAVELENGTHS_NM", parts.channels_are_xyz ? glsl::vec3(0.0) : wavelengths_nm);
  s += syntax.struct_constant + std::string("ATMOSPHERE = ") + syntax.struct_open + "\n";
  s += "    " + Vec3Literal(syntax, p.solar_irradiance) +
       (parts.channels_are_xyz ? ",  // solar_irradiance, XYZ (Y in lx)\n" : ",  // solar_irradiance, W m^-2 nm^-1\n");
  s += "    " + FloatLiteral(p.sun_angular_radius) + ",  // sun_angular_radius, rad\n";
  s += "    " + FloatLiteral(p.bottom_radius) + ",  // bottom_radius, m\n";
  s += "    " + FloatLiteral(p.top_radius) + ",  // top_radius, m\n";
  s += "    " + FloatLiteral(p.mu_s_min) + ",  // mu_s_min\n";
  s += "    " + std::to_string(p.mie_phase) + ",  // mie_phase\n";
  s += "    " + FloatLiteral(p.mie_g) + ",  // mie_g\n";
  s += "    " + Vec3Literal(syntax, p.mie_to_rayleigh_scattering_ratio) + ",  // mie_to_rayleigh_scattering_ratio\n";
  s += "    " + std::to_string(p.single_mie_in_scattering_alpha) + ",  // single_mie_in_scattering_alpha\n";
  s += "    " + std::to_string(p.transmittance_is_colour) + ",  // transmittance_is_colour\n";
  s += "    " + std::to_string(p.transmittance_width) + ", " + std::to_string(p.transmittance_height) +
       ",  // transmittance_width (mu), transmittance_height (r)\n";
  s += "    " + std::to_string(p.scattering_r_size) + ", " + std::to_string(p.scattering_mu_size) + ", " +
       std::to_string(p.scattering_mu_s_size) + ", " + std::to_string(p.scattering_nu_size) +
       ",  // scattering r, mu, mu_s, nu sizes\n";
  s += "    " + FloatLiteral(p.scattering_r_min) + ", " + FloatLiteral(p.scattering_r_max) +
       ",  // scattering_r_min, scattering_r_max, m\n";
  s += "    " + FloatLiteral(p.scattering_mu_s_min) + ", " + FloatLiteral(p.scattering_mu_s_max) +
       ",  // scattering_mu_s_min, scattering_mu_s_max\n";
  s += "    " + std::to_string(p.scattering_mu_s_split) + ",  // scattering_mu_s_split\n";
  s += "    " + std::to_string(p.irradiance_width) + ", " + std::to_string(p.irradiance_height) +
       ",  // irradiance_width (mu_s), irradiance_height (r)\n";
  s += "    // extinction_profile, m^-1\n    " + ProfileLiteral(syntax, p.extinction_profile) + ",\n";
  s += "    // mie_scattering_profile, m^-1\n    " + ProfileLiteral(syntax, p.mie_scattering_profile) + ",\n";
  s += "    // rayleigh_scattering_profile, m^-1\n    " + ProfileLiteral(syntax, p.rayleigh_scattering_profile) +
       syntax.struct_close + ";\n";
  return s;
}

std::string RuntimeFunctionsGlsl() {
  // The engine's functions.glsl: the sources in their order of definition.
  std::string text;
  for (const char* name : kRuntimeFunctionSources) text += EmbeddedShader(name);
  return text;
}

std::vector<SnippetFile> RuntimeSnippetFiles(ShadingLanguage language, const glsl::AtmosphereParameters& parameters,
                                             const glsl::vec3& wavelengths_nm, const std::string& atmosphere_name,
                                             const SnippetParts& parts) {
  const std::string ext = Syntax(language).extension;
  std::string name = ShadingLanguageName(language);
  for (char& c : name) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  SnippetFile constants{"atmosphere_constants." + ext,
                        AtmosphereConstants(language, parameters, wavelengths_nm, atmosphere_name, parts),
                        name + " runtime: this bake's constants (ATMOSPHERE)"};
  std::string functions_text;
  switch (language) {
    case ShadingLanguage::kGlsl: functions_text = RuntimeFunctionsGlsl(); break;
    case ShadingLanguage::kWgsl: functions_text = WgslFunctionsFor(EmbeddedShader("functions.wgsl"), parts); break;
    default: functions_text = EmbeddedShader("functions." + ext);  // #if on the switches, as the GLSL
  }
  SnippetFile functions{"functions." + ext, std::move(functions_text),
                        name + " runtime: sky radiance, aerial perspective, irradiance"};
  // WGSL declarations are order-independent: the structs travel with the functions.
  if (language == ShadingLanguage::kWgsl) return {std::move(constants), std::move(functions)};
  SnippetFile definitions{"definitions." + ext, std::string(EmbeddedShader("definitions." + ext)),
                          name + " runtime: types and constants"};
  return {std::move(definitions), std::move(constants), std::move(functions)};
}

std::string RuntimeSnippetSource(ShadingLanguage language, const glsl::AtmosphereParameters& parameters,
                                 const glsl::vec3& wavelengths_nm, const std::string& atmosphere_name,
                                 const SnippetParts& parts) {
  std::string source;
  for (const SnippetFile& f : RuntimeSnippetFiles(language, parameters, wavelengths_nm, atmosphere_name, parts)) {
    source += f.text;
  }
  return source;
}

}  // namespace skybake
