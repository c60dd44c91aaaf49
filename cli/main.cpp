// skybake: bakes atmospheric-scattering tables for real-time renderers.
//
// Exit codes: 0 ok, 1 usage, 2 invalid input, 3 I/O error, 4 internal error.
#include <cstdio>
#include <exception>

#include <CLI/CLI.hpp>

#include "bake/errors.h"
#include "bake/version.h"
#include "cli/command_line.h"
#include "cli/commands.h"

int main(int argc, char** argv) {
  CLI::App app{
      "skybake bakes physically based atmospheric-scattering data for real-time renderers.\n"
      "Exit codes: 0 ok, 1 usage, 2 invalid input, 3 I/O error, 4 internal error."};
  app.name("skybake");
  skybake::cli::SetCommandLine(argc, argv);
  app.set_version_flag("--version", "skybake " SKYBAKE_VERSION);
  app.require_subcommand(1, 1);
  skybake::cli::AddPresetsCommand(app);
  skybake::cli::AddValidateCommand(app);
  skybake::cli::AddBakeCommand(app);
  skybake::cli::AddEvalCommand(app);
  skybake::cli::AddFitCommand(app);
  skybake::cli::AddReferenceCommand(app);
  skybake::cli::AddRenderCommand(app);
  skybake::cli::AddInfoCommand(app);
  skybake::cli::AddConvertCommand(app);
  skybake::cli::AddBenchCommand(app);
  skybake::cli::AddStressCommand(app);
  skybake::cli::AddReportCommand(app);

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "skybake: %s (see skybake --help)\n", e.what());
    return static_cast<int>(skybake::ExitCode::kUsage);
  } catch (const skybake::Error& e) {
    std::fprintf(stderr, "skybake: %s\n", e.what());
    return static_cast<int>(e.code());
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "skybake: out of memory\n");
    return static_cast<int>(skybake::ExitCode::kInternal);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "skybake: internal error: %s\n", e.what());
    return static_cast<int>(skybake::ExitCode::kInternal);
  }
  return static_cast<int>(skybake::ExitCode::kOk);
}
