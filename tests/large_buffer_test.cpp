// core/large_buffer.h: the bake's large arrays in memory the kernel may
// back with huge pages, behaving as any vector.
#include "core/large_buffer.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace skybake {
namespace {

// The VmFlags line of /proc/self/smaps for the mapping that holds `address`
// ("" where there is none to read).
std::string MappingFlags(const void* address) {
  std::ifstream smaps("/proc/self/smaps");
  const auto at = reinterpret_cast<std::uintptr_t>(address);
  std::string line;
  bool inside = false;
  while (std::getline(smaps, line)) {
    std::uintptr_t begin = 0, end = 0;
    char dash = 0;
    std::istringstream range(line);
    if (range >> std::hex >> begin >> dash >> end && dash == '-') {
      inside = begin <= at && at < end;
    } else if (inside && line.rfind("VmFlags:", 0) == 0) {
      return line;
    }
  }
  return "";
}

// An array of 2 MiB or more starts on a huge page's boundary, where the
// kernel offers huge pages is advised to use them (smaps' "hg"), and holds,
// copies and moves its values as a std::vector does; a small one is
// ordinary memory.
TEST(LargeBuffer, LargeArraysAreAlignedToHugePagesAndAdvised) {
  const std::size_t count = 3 * kHugePageBytes / sizeof(float) + 5;  // not a whole number of huge pages
  LargeBuffer<float> large(count, 0.0f);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(large.data()) % kHugePageBytes, 0u);
  for (std::size_t i = 0; i < count; ++i) large[i] = float(i % 1000);
  if (std::filesystem::exists("/sys/kernel/mm/transparent_hugepage/enabled")) {
    EXPECT_NE(MappingFlags(large.data()).find(" hg"), std::string::npos) << MappingFlags(large.data());
  }
  const LargeBuffer<float> copy = large;
  ASSERT_EQ(copy.size(), count);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(copy.data()) % kHugePageBytes, 0u);
  for (std::size_t i = 0; i < count; i += 4099) EXPECT_EQ(copy[i], float(i % 1000));
  LargeBuffer<float> moved = std::move(large);
  EXPECT_EQ(moved.back(), float((count - 1) % 1000));
  moved.resize(10);
  moved.shrink_to_fit();  // now a small array, freed as one
  EXPECT_EQ(moved[9], 9.0f);

  LargeBuffer<std::uint8_t> small(1000, 7);
  EXPECT_EQ(small[999], 7);
}

}  // namespace
}  // namespace skybake
