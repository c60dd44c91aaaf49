// Placeholder until the TOML reader lands.
#include "bake/config.h"

#include "bake/errors.h"

namespace skybake {
Atmosphere ParseAtmosphere(std::string_view, const std::string& source_name) {
  throw InputError(source_name + ": atmosphere files are not supported yet");
}
Atmosphere LoadAtmosphere(const std::string& f) { return ParseAtmosphere({}, f); }
std::vector<PresetInfo> ListPresets() { return {}; }
Atmosphere LoadPreset(const std::string& name) { return ParseAtmosphere({}, name); }
std::string ToToml(const Atmosphere&) { return {}; }
void Validate(const Atmosphere&, const std::string&) {}
}  // namespace skybake
