// `skybake presets` and `skybake validate`.
#include <cstdio>
#include <string>

#include <CLI/CLI.hpp>

#include "bake/config.h"
#include "cli/commands.h"

namespace skybake::cli {

void AddPresetsCommand(CLI::App& app) {
  CLI::App* cmd = app.add_subcommand("presets", "List the built-in atmosphere presets");
  cmd->callback([] {
    for (const PresetInfo& preset : ListPresets())
      std::printf("%-18s %s\n", preset.name.c_str(), preset.description.c_str());
  });
}

void AddValidateCommand(CLI::App& app) {
  CLI::App* cmd = app.add_subcommand(
      "validate", "Check an atmosphere file or preset and print it resolved to SI units (TOML)");
  auto source = std::make_shared<std::string>();
  cmd->add_option("atmosphere", *source, "Atmosphere file (.toml) or preset name")->required();
  cmd->callback([source] {
    Atmosphere atmosphere = LoadAtmosphere(*source);
    std::fputs(ToToml(atmosphere).c_str(), stdout);
  });
}

}  // namespace skybake::cli
