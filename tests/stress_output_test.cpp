// A failed or interrupted bake leaves the previous set of files as it was and
// no temporary files: the whole set is staged and renamed at the end.
#include <gtest/gtest.h>

#include <filesystem>
#include <map>

#include "core/errors.h"
#include "core/file_io.h"
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

TEST(StagedFiles, FailedRenameKeepsTheFileItWouldReplace) {
  TempDir dir;
  testing::WriteText(dir.path() / "a.txt", "old a");
  testing::WriteText(dir.path() / "b.txt", "old b");
  {
    StagedFiles staged;
    staged.Write(dir.path() / "a.txt", "new a");
    staged.Write(dir.path() / "b.txt", "new b");
    staged.Write(dir.path() / "manifest.json", "new manifest");
    // b.txt's staged copy vanishes before Commit, so its rename fails after
    // the file it replaces was moved aside.
    for (const auto& entry : fs::directory_iterator(dir.path())) {
      const std::string name = entry.path().filename().string();
      if (name.rfind("b.txt", 0) == 0 && IsTemporaryFileName(name)) fs::remove(entry.path());
    }
    EXPECT_THROW(staged.Commit(), IoError);
  }
  EXPECT_EQ(Snapshot(dir.path()), (std::map<std::string, std::string>{{"a.txt", "new a"}, {"b.txt", "old b"}}));
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

// A full disk: the output directory is a 256 KiB tmpfs (mounted in a user
// and mount namespace, so no privileges are needed), holding a tiny set of
// ~100 KB; the next bake's set (~500 KB) cannot fit, so a write fails with
// ENOSPC part-way. Skipped where unprivileged namespaces are not allowed.
TEST(BakeOutput, FullDiskExitsThreeAndKeepsThePreviousSet) {
  TempDir dir;
  const fs::path mount = dir.path() / "small_disk", out = mount / "out";
  fs::create_directory(mount);
  // The GLSL runtime only, so that the first set fits the small disk.
  const std::string bake = Skybake() + " bake earth --runtime glsl -o " + testing::ShellQuote(out);
  const std::string script =
      "mount -t tmpfs -o size=256k tmpfs " + testing::ShellQuote(mount) + " || exit 77\n" + bake + kTinyBake +
      " --orders 1 || exit 78\n"
      "cd " + testing::ShellQuote(out) + " && sha256sum * > ../../before\n" +
      bake + " -q --transmittance-size 64 16 --irradiance-size 16 4 --scattering-size 8 32 8 4 --ray-samples 8"
             " --sphere-samples 4 --orders 1 2> ../../err\n"
      "echo $? > ../../code\n"
      "sha256sum * > ../../after; ls -a > ../../listing\n";
  testing::WriteText(dir.path() / "full_disk.sh", script);
  int code = RunCommand("unshare -r -m sh " + testing::ShellQuote(dir.path() / "full_disk.sh"), dir);
  if (code == 77 || code == 1) GTEST_SKIP() << "cannot mount a small tmpfs in a user namespace here";
  ASSERT_EQ(code, 0);
  EXPECT_EQ(ReadText(dir.path() / "code"), "3\n");
  const std::string err = ReadText(dir.path() / "err");
  EXPECT_EQ(testing::Lines(err).size(), 1u) << err;
  EXPECT_NE(err.find("No space left on device"), std::string::npos) << err;
  EXPECT_EQ(ReadText(dir.path() / "after"), ReadText(dir.path() / "before"));
  EXPECT_EQ(ReadText(dir.path() / "listing").find(".tmp"), std::string::npos) << ReadText(dir.path() / "listing");
}

}  // namespace
}  // namespace skybake
