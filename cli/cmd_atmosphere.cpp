// `skybake presets` and `skybake validate`.
#include <cstdio>
#include <memory>
#include <string>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "bake/config.h"
#include "cli/commands.h"

namespace skybake::cli {

void AddPresetsCommand(CLI::App& app) {
  CLI::App* cmd = app.add_subcommand("presets", "List the built-in atmosphere presets");
  auto json = std::make_shared<bool>(false);
  cmd->add_flag("--json", *json, "Print a JSON array of {name, description}");
  cmd->callback([json] {
    std::vector<PresetInfo> presets = ListPresets();
    if (*json) {
      nlohmann::ordered_json list = nlohmann::ordered_json::array();
      for (const PresetInfo& preset : presets)
        list.push_back({{"name", preset.name}, {"description", preset.description}});
      std::printf("%s\n", list.dump(2).c_str());
      return;
    }
    for (const PresetInfo& preset : presets)
      std::printf("%-18s %s\n", preset.name.c_str(), preset.description.c_str());
  });
}

void AddValidateCommand(CLI::App& app) {
  CLI::App* cmd = app.add_subcommand(
      "validate", "Check an atmosphere file or preset and print it resolved to SI units (TOML)");
  auto source = std::make_shared<std::string>();
  auto json = std::make_shared<bool>(false);
  cmd->add_option("atmosphere", *source, "Atmosphere file (.toml) or preset name")->required();
  cmd->add_flag("--json", *json, "Print the resolved atmosphere as a JSON object instead");
  cmd->callback([source, json] {
    Atmosphere atmosphere = LoadAtmosphere(*source);
    std::fputs((*json ? ToJson(atmosphere) : ToToml(atmosphere)).c_str(), stdout);
  });
}

}  // namespace skybake::cli
