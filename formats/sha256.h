// SHA-256 (FIPS 180-4, section 6.2) for the checksums in the manifest. Small
// and dependency-free on purpose: the manifest needs a digest that any engine
// can recompute with its platform's library.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace skybake {

class Sha256 {
 public:
  Sha256();
  void Update(const void* data, std::size_t size);
  // The 32-byte digest; the object must not be updated afterwards.
  std::array<std::uint8_t, 32> Finish();

 private:
  void Compress(const std::uint8_t* block);

  std::array<std::uint32_t, 8> state_;
  std::array<std::uint8_t, 64> buffer_;
  std::size_t buffered_ = 0;
  std::uint64_t total_bytes_ = 0;
};

// Lower-case hexadecimal digest of `bytes` (64 characters).
std::string Sha256Hex(std::string_view bytes);
std::string Sha256Hex(const void* data, std::size_t size);

}  // namespace skybake
