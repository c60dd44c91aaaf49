// A failed or interrupted bake leaves the previous set of files as it was and
// no temporary files: the whole set is staged and renamed at the end.
#include <gtest/gtest.h>

#include <csignal>
#include <filesystem>
#include <map>

#include "bake/errors.h"
#include "formats/file_io.h"
#include "test_util.h"

namespace skybake {
namespace {

namespace fs = std::filesystem;
using testing::ReadText;
using testing::RunCommand;
using testing::Skybake;
using testing::TempDir;

std::map<std::string, std::string> Snapshot(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (entry.is_regular_file()) files[entry.path().filename().string()] = ReadText(entry.path());
  }
  return files;
}

TEST(StagedFiles, FailureLeavesEarlierFilesAndNoTemporaries) {
  TempDir dir;
  testing::WriteText(dir.path() / "a.txt", "old");
  {
    StagedFiles staged;
    staged.Write(dir.path() / "a.txt", "new");
    EXPECT_THROW(staged.Write(dir.path() / "missing" / "b.txt", "new"), IoError);
  }
  EXPECT_EQ(Snapshot(dir.path()), (std::map<std::string, std::string>{{"a.txt", "old"}}));
}

TEST(StagedFiles, CommitRenamesEveryFile) {
  TempDir dir;
  testing::WriteText(dir.path() / "a.txt", "old");
  StagedFiles staged;
  staged.Write(dir.path() / "a.txt", "new a");
  staged.Write(dir.path() / "b.txt", "new b");
  EXPECT_EQ(Snapshot(dir.path()).count("b.txt"), 0u) << "nothing appears before Commit";
  staged.Commit();
  EXPECT_EQ(Snapshot(dir.path()), (std::map<std::string, std::string>{{"a.txt", "new a"}, {"b.txt", "new b"}}));
}

volatile std::sig_atomic_t received_signal = 0;
extern "C" void RecordSignal(int signal) { received_signal = signal; }

TEST(DeferInterrupts, DeliversSigintOnlyOnceDestroyed) {
  auto previous = std::signal(SIGINT, RecordSignal);
  received_signal = 0;
  {
    DeferInterrupts defer;
    std::raise(SIGINT);
    EXPECT_EQ(received_signal, 0);
  }
  EXPECT_EQ(received_signal, SIGINT);
  std::signal(SIGINT, previous);
}

const std::string kTinyBake =
    " --transmittance-size 16 8 --irradiance-size 8 4 --scattering-size 4 8 4 2 --ray-samples 8"
    " --sphere-samples 4 -q";

TEST(BakeOutput, FailureOnALateFileKeepsThePreviousSetWhole) {
  TempDir dir;
  const fs::path out = dir.path() / "out";
  const std::string bake = Skybake() + " bake earth -o " + testing::ShellQuote(out) + kTinyBake;
  ASSERT_EQ(RunCommand(bake + " --orders 1", dir), 0);
  // A table file that cannot be replaced, late in the set: the new
  // transmittance and irradiance files, staged before it, must not appear.
  fs::remove(out / "single_mie_scattering.ktx2");
  fs::create_directory(out / "single_mie_scattering.ktx2");
  const auto before = Snapshot(out);
  std::string err;
  EXPECT_EQ(RunCommand(bake + " --orders 2", dir, nullptr, &err), 3);
  EXPECT_EQ(testing::Lines(err).size(), 1u) << err;
  EXPECT_EQ(Snapshot(out), before);
}

TEST(BakeOutput, InterruptedBakeLeavesNoFiles) {
  TempDir dir;
  const fs::path out = dir.path() / "out";
  // Default tables take seconds: the interrupt lands during the bake.
  const std::string bake = "timeout -s INT 1 " + Skybake() + " bake earth -q -o " + testing::ShellQuote(out);
  EXPECT_NE(RunCommand(bake, dir), 0);
  EXPECT_TRUE(!fs::exists(out) || Snapshot(out).empty());
}

}  // namespace
}  // namespace skybake
