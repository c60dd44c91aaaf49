// skybake: bakes atmospheric-scattering tables for real-time renderers.
//
// Exit codes: 0 ok, 1 usage, 2 invalid input, 3 I/O error, 4 internal error,
// 130 interrupted.
#include <malloc.h>

#include <cstdio>
#include <cstring>
#include <exception>
#include <functional>
#include <limits>
#include <string>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "cli/command_line.h"
#include "cli/commands.h"
#include "core/errors.h"
#include "core/interrupt.h"
#include "core/version.h"

namespace {

// Whether the command line asks for machine-readable output (`--json`
// before any `--`): errors then go to stdout as JSON too.
bool WantsJson(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--") == 0) return false;
    if (std::strcmp(argv[i], "--json") == 0) return true;
  }
  return false;
}

// The first word, when it is neither a subcommand nor a global option, named
// as CLI11's "a subcommand is required" would not.
void CheckFirstWord(const CLI::App& app, int argc, char** argv) {
  if (argc < 2) return;
  const std::string word = argv[1];
  if (word == "--" || word.empty()) return;
  if (word[0] == '-') {
    for (const char* known : {"-h", "--help", "--help-all", "--version"}) {
      if (word == known) return;
    }
    throw skybake::UsageError("unknown option '" + word + "' (options follow the command: skybake COMMAND --help)");
  }
  std::string commands;
  for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; })) {
    if (sub->get_name() == word) return;
    commands += (commands.empty() ? "" : ", ") + sub->get_name();
  }
  throw skybake::UsageError("unknown command '" + word + "' (commands: " + commands + ")");
}

// The JSON document of an error on stdout (`--json`).
std::string ErrorJson(skybake::ExitCode code, const std::string& message, const skybake::ErrorLocation& where = {}) {
  auto or_null = [](const std::string& s) { return s.empty() ? nlohmann::json(nullptr) : nlohmann::json(s); };
  nlohmann::json error = {{"exit_code", static_cast<int>(code)},
                          {"message", message},
                          {"file", or_null(where.file)},
                          {"key", or_null(where.key)},
                          {"line", where.line > 0 ? nlohmann::json(where.line) : nlohmann::json(nullptr)}};
  return nlohmann::json{{"error", error}}.dump(2);
}

int Fail(bool json, skybake::ExitCode code, const std::string& message, const skybake::ErrorLocation& where = {}) {
  std::fprintf(stderr, "skybake: %s\n", message.c_str());
  if (json) {
    std::fflush(stdout);
    std::printf("%s\n", ErrorJson(code, message, where).c_str());
  }
  return static_cast<int>(code);
}

// A bake allocates and frees tables of 4 to 17 MiB (more at larger sizes)
// in every phase. glibc serves blocks above 128 KiB with their own mmap and
// unmaps them when they are freed, so every new table faults in all its
// pages again (about a tenth of the default bake's time). With mmap off and
// no trimming, freed tables stay in the heap and are reused. (Raising the
// mmap threshold instead stops at 32 MiB, and a table twice the default
// size, 33.5 MiB, would be mapped afresh again.)
void KeepFreedTablesForReuse() {
  mallopt(M_MMAP_MAX, 0);
  mallopt(M_TRIM_THRESHOLD, std::numeric_limits<int>::max());
}

}  // namespace

int main(int argc, char** argv) {
  KeepFreedTablesForReuse();
  const bool json = WantsJson(argc, argv);
  // Before any thread starts, so that every thread leaves the signals to
  // the one that acts on them (core/interrupt.h).
  skybake::HandleInterrupts(json ? [](const std::string& message) {
    return ErrorJson(skybake::ExitCode::kInterrupted, message);
  } : std::function<std::string(const std::string&)>());
  CLI::App app{
      "skybake bakes physically based atmospheric-scattering data for real-time renderers.\n"
      "Exit codes: 0 ok, 1 usage, 2 invalid input, 3 I/O error, 4 internal error, 130 interrupted (SIGINT or "
      "SIGTERM before the outputs were complete: they are left as they were, nothing half-written; a signal "
      "during or after their commit lets them complete, exit 0 with a note on stderr). With --json, an error is also "
      "a JSON object on stdout: {\"error\": {\"exit_code\", \"message\", \"file\", \"key\", \"line\"}}."};
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

  using skybake::ExitCode;
  try {
    CheckFirstWord(app, argc, argv);
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    return Fail(json, ExitCode::kUsage, std::string(e.what()) + " (see skybake --help)");
  } catch (const skybake::ReportedError& e) {
    return Fail(false, e.code(), e.what());
  } catch (const skybake::Error& e) {
    return Fail(json, e.code(), e.what(), e.location());
  } catch (const std::bad_alloc&) {
    return Fail(json, ExitCode::kInternal, "out of memory");
  } catch (const std::exception& e) {
    return Fail(json, ExitCode::kInternal, std::string("internal error: ") + e.what());
  }
  // A signal recorded but never acted on arrived during or after the commit
  // of the outputs.
  const std::string late_interrupt = skybake::TakeInterruptAfterCommit();
  if (!late_interrupt.empty()) std::fprintf(stderr, "skybake: %s\n", late_interrupt.c_str());
  return static_cast<int>(ExitCode::kOk);
}
