// formats/sha256.h against the FIPS 180-4 example vectors and, for lengths
// around the padding boundaries, against coreutils' sha256sum.
#include <gtest/gtest.h>

#include <random>
#include <string>

#include "formats/sha256.h"
#include "test_util.h"

namespace skybake {
namespace {

using testing::RunCommand;
using testing::ShellQuote;
using testing::TempDir;

TEST(Sha256, FipsExampleVectors) {
  // FIPS 180-4 examples (csrc.nist.gov "SHA256.pdf"): one block and two blocks.
  EXPECT_EQ(Sha256Hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(Sha256Hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  // FIPS 180-2 Appendix B.3: one million 'a'.
  EXPECT_EQ(Sha256Hex(std::string(1000000, 'a')),
            "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
  // The empty message (NIST SHAVS short-message test, Len = 0).
  EXPECT_EQ(Sha256Hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
}

TEST(Sha256, PiecewiseUpdatesEqualOneUpdate) {
  std::string message(1000, '\0');
  std::mt19937 random(7);
  for (char& c : message) c = static_cast<char>(random());
  const std::string whole = Sha256Hex(message);
  for (std::size_t piece : {1u, 3u, 55u, 63u, 64u, 65u, 127u}) {
    Sha256 hash;
    for (std::size_t at = 0; at < message.size(); at += piece) {
      hash.Update(message.data() + at, std::min(piece, message.size() - at));
    }
    std::string hex;
    char buffer[3];
    for (std::uint8_t byte : hash.Finish()) {
      std::snprintf(buffer, sizeof(buffer), "%02x", byte);
      hex += buffer;
    }
    EXPECT_EQ(hex, whole) << "pieces of " << piece;
  }
}

// Lengths where the padding spills into a second block (55/56 bytes mod 64)
// are where hand-written SHA-256 goes wrong; sha256sum is independent.
TEST(Sha256, AgreesWithSha256sumAcrossPaddingBoundaries) {
  TempDir dir;
  std::string out;
  if (RunCommand("command -v sha256sum", dir, &out) != 0) GTEST_SKIP() << "sha256sum not installed";
  std::mt19937 random(11);
  for (std::size_t length : {1u, 55u, 56u, 57u, 63u, 64u, 65u, 119u, 120u, 128u, 1000u}) {
    std::string message(length, '\0');
    for (char& c : message) c = static_cast<char>(random());
    testing::WriteText(dir.path() / "m.bin", message);
    ASSERT_EQ(RunCommand("sha256sum " + ShellQuote(dir.path() / "m.bin"), dir, &out), 0);
    EXPECT_EQ(out.substr(0, 64), Sha256Hex(message)) << "length " << length;
  }
}

}  // namespace
}  // namespace skybake
