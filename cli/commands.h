// The `skybake` subcommands. Each Add*Command registers one subcommand on the
// application; its callback does the work and reports failure by throwing a
// skybake::Error, which main() turns into a one-line message and exit code.
#pragma once

namespace CLI {
class App;
}

namespace skybake::cli {

void AddPresetsCommand(CLI::App& app);
void AddValidateCommand(CLI::App& app);
void AddBakeCommand(CLI::App& app);
void AddEvalCommand(CLI::App& app);
void AddFitCommand(CLI::App& app);
void AddReferenceCommand(CLI::App& app);
void AddRenderCommand(CLI::App& app);
void AddInfoCommand(CLI::App& app);
void AddConvertCommand(CLI::App& app);
void AddBenchCommand(CLI::App& app);
void AddStressCommand(CLI::App& app);
void AddReportCommand(CLI::App& app);

}  // namespace skybake::cli
