// One interrupt rule for every command (core/interrupt.h): an interrupt at
// any moment either leaves a command's outputs as they were before it ran
// (exit 130) or lets them complete (exit 0, with a note), and never kills
// the process with the signal itself. Each test runs the skybake executable
// (testing::Skybake()) and sends SIGINT at chosen moments of a run.
#include <gtest/gtest.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "test_util.h"

extern char** environ;

namespace skybake {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
using testing::ReadText;
using testing::RunCommand;
using testing::ShellQuote;
using testing::Skybake;
using testing::TempDir;

// Every regular file below `dir`, by its path relative to `dir`, with its bytes.
using Snapshot = std::map<std::string, std::string>;
Snapshot TakeSnapshot(const fs::path& dir) {
  Snapshot files;
  std::error_code ec;
  for (const auto& entry : fs::recursive_directory_iterator(dir, ec)) {
    if (entry.is_regular_file()) files[fs::relative(entry.path(), dir).string()] = ReadText(entry.path());
  }
  return files;
}

std::vector<std::string> Names(const Snapshot& files) {
  std::vector<std::string> names;
  for (const auto& [name, bytes] : files) names.push_back(name);
  return names;
}

// Puts `files` back as `dir`'s whole content.
void Restore(const fs::path& dir, const Snapshot& files) {
  fs::remove_all(dir);
  for (const auto& [name, bytes] : files) {
    fs::create_directories((dir / name).parent_path());
    testing::WriteText(dir / name, bytes);
  }
}

// How a run ended: its exit code, or the signal that killed it (-1 if none).
struct Ended {
  int exit_code = -1;
  int killed_by = -1;
  double seconds_after_signal = 0.0;
  std::string out, err;
};

// Starts `command` (a shell command line whose last word runs skybake with
// `exec`, so that the signal reaches skybake itself) with its stdout and
// stderr in files of `dir`; calls `until_signal` (which returns when the
// signal is due), sends `signal`, and waits for the end.
Ended RunAndInterrupt(const std::string& command, const TempDir& dir, const std::function<void(pid_t)>& until_signal,
                      int signal = SIGINT) {
  const fs::path out = dir.path() / "interrupted.stdout", err = dir.path() / "interrupted.stderr";
  const std::string script = "exec " + command + " >" + ShellQuote(out) + " 2>" + ShellQuote(err);
  const char* argv[] = {"/bin/sh", "-c", script.c_str(), nullptr};
  pid_t pid = 0;
  EXPECT_EQ(posix_spawn(&pid, "/bin/sh", nullptr, nullptr, const_cast<char**>(argv), environ), 0);
  until_signal(pid);
  const auto signalled = Clock::now();
  ::kill(pid, signal);
  int status = 0;
  ::waitpid(pid, &status, 0);
  Ended ended;
  ended.seconds_after_signal = std::chrono::duration<double>(Clock::now() - signalled).count();
  if (WIFEXITED(status)) ended.exit_code = WEXITSTATUS(status);
  if (WIFSIGNALED(status)) ended.killed_by = WTERMSIG(status);
  ended.out = ReadText(out);
  ended.err = ReadText(err);
  return ended;
}

// Whether `pid` has taken the interrupt signals over (core/interrupt.h
// blocks them in every thread first thing in main(): /proc's SigBlk mask
// shows SIGINT) or has ended. Before that only the dynamic loader and
// static initialisers have run, and nothing has been written: a signal
// then ends the process as it ends any.
void WaitUntilSignalsAreTaken(pid_t pid) {
  for (;;) {
    std::string status = ReadText("/proc/" + std::to_string(pid) + "/status");
    const std::size_t at = status.find("SigBlk:");
    if (at == std::string::npos || status.find("State:\tZ") != std::string::npos) return;  // ended
    const unsigned long long blocked = std::stoull(status.substr(at + 7), nullptr, 16);
    if (blocked & (1ull << (SIGINT - 1))) return;
  }
}

// `seconds` after the process took the signals over.
std::function<void(pid_t)> After(double seconds) {
  return [seconds](pid_t pid) {
    WaitUntilSignalsAreTaken(pid);
    std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
  };
}

// Waits until `file` is replaced (its inode or its modification time
// changes: a freed inode may be reused) or the run ends.
std::function<void(pid_t)> WhenReplaced(const fs::path& file) {
  auto identity = [file] {
    struct stat s {};
    if (::stat(file.c_str(), &s) != 0) return std::string();
    return std::to_string(s.st_ino) + ":" + std::to_string(s.st_mtim.tv_sec) + "." + std::to_string(s.st_mtim.tv_nsec);
  };
  return [identity](pid_t pid) {
    const std::string before = identity();
    for (;;) {
      siginfo_t info{};
      if (::waitid(P_PID, pid, &info, WEXITED | WNOHANG | WNOWAIT) == 0 && info.si_pid == pid) return;
      if (identity() != before) return;
    }
  };
}

double SecondsToRun(const std::string& command, const TempDir& dir) {
  const auto start = Clock::now();
  EXPECT_EQ(RunCommand(command, dir), 0) << command;
  return std::chrono::duration<double>(Clock::now() - start).count();
}

bool HasTemporaryFile(const Snapshot& files) {
  for (const auto& [name, bytes] : files) {
    if (name.find(".tmp-") != std::string::npos) return true;
  }
  return false;
}

// Sends SIGINT at 20 evenly spaced moments of `command`, which writes into
// `output` (holding `before` at the start of each run; the command's own
// complete run leaves `complete`'s files there). Every run must end with
// exit 130 and `output` as it was, or with exit 0 and every file of a
// complete run present (`is_complete` checks the rest).
void InterruptAtEvenlySpacedMoments(const std::string& command, const fs::path& output, const Snapshot& before,
                                    const std::vector<std::string>& complete_names, double run_seconds,
                                    const std::function<void(const Snapshot&)>& is_complete) {
  TempDir dir;
  int left_as_it_was = 0, completed = 0;
  for (int k = 0; k < 20; ++k) {
    Restore(output, before);
    const double moment = (k + 0.5) / 20.0 * run_seconds;
    const Ended ended = RunAndInterrupt(command, dir, After(moment));
    const Snapshot after = TakeSnapshot(output);
    SCOPED_TRACE("SIGINT at " + std::to_string(moment) + " s of " + std::to_string(run_seconds) + " s: " +
                 ended.err);
    ASSERT_EQ(ended.killed_by, -1) << "killed by the signal itself";
    EXPECT_FALSE(HasTemporaryFile(after));
    if (ended.exit_code == 130) {
      ++left_as_it_was;
      EXPECT_EQ(after, before) << "exit 130 says the outputs were left as they were";
      EXPECT_NE(ended.err.find("interrupted by SIGINT"), std::string::npos);
    } else {
      ASSERT_EQ(ended.exit_code, 0);
      ++completed;
      EXPECT_EQ(Names(after), complete_names) << "exit 0 says the outputs are complete";
      is_complete(after);
    }
  }
  std::printf("20 interrupts: %d left the outputs as they were (exit 130), %d let them complete (exit 0)\n",
              left_as_it_was, completed);
  // Most moments fall inside the run: each outcome is tested.
  EXPECT_GE(left_as_it_was, 5);
}

// Small tables (a bake of a few tenths of a second), with the scattering
// table's r, mu, mu_s and nu sizes.
std::string SmallTables(const std::string& scattering_size = "8 32 16 4") {
  return " --transmittance-size 64 16 --irradiance-size 16 4 --scattering-size " + scattering_size +
         " --ray-samples 16 --sphere-samples 8";
}
const std::string kSmallBake = SmallTables() + " -q";

// Defect 1 of the pipeline issue: SIGINT right after the new manifest
// appeared made `bake` exit 130 saying "nothing was written" over a
// complete new set.
TEST(Interrupt, D01_ASignalJustAfterTheSetIsWrittenSaysItIsComplete) {
  TempDir dir;
  const fs::path out = dir.path() / "set";
  const std::string bake = Skybake() + " bake earth --format ktx2 -o " + ShellQuote(out) + kSmallBake;
  ASSERT_EQ(RunCommand(bake + " --orders 1", dir), 0);
  const std::string old_manifest = ReadText(out / "skybake.json");
  const Ended ended = RunAndInterrupt(bake, dir, WhenReplaced(out / "skybake.json"));
  EXPECT_EQ(ended.killed_by, -1);
  EXPECT_EQ(ended.exit_code, 0) << ended.err;
  // The signal lands during the commit or after it (or once the process
  // has ended: nothing is said then).
  if (!ended.err.empty()) {
    EXPECT_NE(ended.err.find("interrupted by SIGINT after the outputs were complete"), std::string::npos) << ended.err;
  }
  EXPECT_NE(ReadText(out / "skybake.json"), old_manifest);
  EXPECT_EQ(RunCommand(Skybake() + " info " + ShellQuote(out), dir), 0);
}

TEST(Interrupt, D02_BakeLeavesTheOldSetOrCompletesTheNew) {
  TempDir dir;
  const fs::path out = dir.path() / "set", complete = dir.path() / "complete";
  const std::string bake = Skybake() + " bake earth" + SmallTables("16 64 16 4") + " -q -o ";
  ASSERT_EQ(RunCommand(bake + ShellQuote(out) + " --orders 1", dir), 0);
  const Snapshot before = TakeSnapshot(out);
  const double seconds = SecondsToRun(bake + ShellQuote(complete), dir);
  const Snapshot complete_files = TakeSnapshot(complete);
  InterruptAtEvenlySpacedMoments(bake + ShellQuote(out), out, before, Names(complete_files), seconds,
                                 [&](const Snapshot& after) {
                                   EXPECT_NE(after.at("skybake.json"), before.at("skybake.json"));
                                   EXPECT_EQ(RunCommand(Skybake() + " info " + ShellQuote(out), dir), 0);
                                 });
}

TEST(Interrupt, D02_RenderLeavesTheOldImagesOrCompletesTheNew) {
  TempDir dir;
  const fs::path set = dir.path() / "set", out = dir.path() / "images", complete = dir.path() / "complete";
  ASSERT_EQ(RunCommand(Skybake() + " bake earth --format exr --runtime none -o " + ShellQuote(set) + kSmallBake, dir),
            0);
  const std::string render = Skybake() + " render " + ShellQuote(set) + " --size 96 --plots -q -o ";
  ASSERT_EQ(RunCommand(render + ShellQuote(out) + " --exposure 1", dir), 0);
  const Snapshot before = TakeSnapshot(out);
  const double seconds = SecondsToRun(render + ShellQuote(complete), dir);
  const Snapshot complete_files = TakeSnapshot(complete);
  InterruptAtEvenlySpacedMoments(render + ShellQuote(out), out, before, Names(complete_files), seconds,
                                 [&](const Snapshot& after) {
                                   EXPECT_NE(after.at("contact_sheet.png"), before.at("contact_sheet.png"));
                                 });
}

TEST(Interrupt, D02_ReportLeavesNoFolderOrCompletesTheReport) {
  TempDir dir;
  const fs::path out = dir.path() / "report", complete = dir.path() / "complete";
  const std::string report = Skybake() + " report earth --quick --passes 1 --march-steps 4 --wavelengths 0 -q" +
                             " --transmittance-size 64 16 --irradiance-size 16 4 --scattering-size 8 32 16 4 -o ";
  const double seconds = SecondsToRun(report + ShellQuote(complete) + " >/dev/null", dir);
  const Snapshot complete_files = TakeSnapshot(complete);
  InterruptAtEvenlySpacedMoments(report + ShellQuote(out), out, {}, Names(complete_files), seconds,
                                 [&](const Snapshot&) {});
  // Exit 130 left no folder behind (a folder that was not there before).
  fs::remove_all(out);
  TempDir run;
  const Ended ended = RunAndInterrupt(report + ShellQuote(out), run, After(0.3 * seconds));
  if (ended.exit_code == 130) {
    EXPECT_FALSE(fs::exists(out));
  }
}

// Defect 2: the other commands died of SIGINT with no message and left
// partial outputs. Each is interrupted once, a third of the way through.
TEST(Interrupt, D02_EveryCommandThatWritesEndsTruthfully) {
  TempDir dir;
  const fs::path set = dir.path() / "set";
  ASSERT_EQ(RunCommand(Skybake() + " bake earth --format exr --runtime none -o " + ShellQuote(set) + kSmallBake, dir),
            0);
  testing::WriteText(dir.path() / "queries.csv",
                     "altitude_m,view_zenith_deg,sun_zenith_deg,view_sun_azimuth_deg\n0,45,30,0\n1000,80,60,90\n");
  const fs::path out = dir.path() / "out";
  struct Case {
    std::string name, command;
    bool writes_into_existing_folder = false;
    bool sets_replace_each_other = false;  // bench's runs: exit 130 may leave an earlier run's set, whole
  };
  const std::vector<Case> cases = {
      {"info --plot", Skybake() + " info " + ShellQuote(set) + " --plot " + ShellQuote(out)},
      {"fit", Skybake() + " fit earth -o " + ShellQuote(out)},
      {"reference", Skybake() + " reference earth --paths 4096 --in " + ShellQuote(dir.path() / "queries.csv") +
                        " --out " + ShellQuote(out / "reference.csv"), true},
      {"bench", Skybake() + " bench earth --runs 3 -o " + ShellQuote(out) + SmallTables(), false, true},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    auto prepare = [&] {
      fs::remove_all(out);
      if (c.writes_into_existing_folder) fs::create_directory(out);
    };
    prepare();
    const double seconds = SecondsToRun(c.command + " >/dev/null", dir);
    const Snapshot complete = TakeSnapshot(out);
    prepare();
    const Ended ended = RunAndInterrupt(c.command, dir, After(seconds / 3.0));
    EXPECT_EQ(ended.killed_by, -1) << "killed by the signal itself";
    const Snapshot after = TakeSnapshot(out);
    EXPECT_FALSE(HasTemporaryFile(after));
    if (ended.exit_code == 130) {
      EXPECT_TRUE(after.empty() || (c.sets_replace_each_other && Names(after) == Names(complete)))
          << Names(after).size() << " files left";
      EXPECT_NE(ended.err.find("interrupted by SIGINT"), std::string::npos) << ended.err;
    } else {
      EXPECT_EQ(ended.exit_code, 0) << ended.err;
      EXPECT_EQ(Names(after), Names(complete));
    }
  }
}

// Defect 11: an interrupted batch with --json printed only the error.
TEST(Interrupt, D11_AnInterruptedBatchKeepsTheFinishedResultsInItsJson) {
  TempDir dir;
  const fs::path out = dir.path() / "sets";
  const std::string batch = Skybake() + " bake earth mars light-haze --json --format ktx2 --runtime none" +
                            SmallTables("16 64 32 8") + " -q -o " + ShellQuote(out);
  const Ended ended = RunAndInterrupt(batch, dir, WhenReplaced(out / "earth" / "skybake.json"));
  ASSERT_EQ(ended.exit_code, 130) << ended.err;
  const nlohmann::json report = nlohmann::json::parse(ended.out);
  ASSERT_GE(report["bakes"].size(), 1u) << ended.out;
  EXPECT_EQ(report["bakes"][0]["atmosphere"], "earth");
  EXPECT_EQ(report["error"]["exit_code"], 130);
  EXPECT_NE(ended.err.find("of 3 atmospheres done"), std::string::npos) << ended.err;
  EXPECT_EQ(RunCommand(Skybake() + " info " + ShellQuote(out / "earth"), dir), 0);
}

// Defect 3: --wavelengths had no upper bound, and a spectral bake answered
// SIGTERM only at the end of a phase.
TEST(Interrupt, D03_SpectralBakesAreBoundedAndStopAtOnce) {
  TempDir dir;
  std::string err;
  EXPECT_NE(RunCommand("timeout 20 " + Skybake() + " bake earth --wavelengths 1000000 -o " +
                           ShellQuote(dir.path() / "x"),
                       dir, nullptr, &err),
            0);
  EXPECT_NE(err.find("at most 95"), std::string::npos) << err;
  EXPECT_FALSE(fs::exists(dir.path() / "x"));
  const Ended ended = RunAndInterrupt(Skybake() + " bake earth --wavelengths 95 -o " + ShellQuote(dir.path() / "y"),
                                      dir, After(1.0), SIGTERM);
  EXPECT_EQ(ended.exit_code, 130) << ended.err;
  EXPECT_NE(ended.err.find("interrupted by SIGTERM"), std::string::npos) << ended.err;
  EXPECT_FALSE(fs::exists(dir.path() / "y"));
  // At once: not at the end of the bake's phase (seconds at 95 wavelengths).
  EXPECT_LT(ended.seconds_after_signal, 1.0);
}

}  // namespace
}  // namespace skybake
