// `skybake bake` and `skybake eval` (being written).
#include <CLI/CLI.hpp>

#include "bake/errors.h"
#include "cli/commands.h"

namespace skybake::cli {

void AddBakeCommand(CLI::App& app) {
  app.add_subcommand("bake", "Bake the lookup tables")->callback([] {
    throw InternalError("bake is not implemented yet");
  });
}

void AddEvalCommand(CLI::App& app) {
  app.add_subcommand("eval", "Evaluate queries against baked tables")->callback([] {
    throw InternalError("eval is not implemented yet");
  });
}

}  // namespace skybake::cli
