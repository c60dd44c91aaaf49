// SHA-256 (FIPS 180-4) for the checksums in the manifest, which any engine
// can recompute with its platform's library. Computed by OpenSSL's
// libcrypto, which uses the CPU's SHA instructions where it has them.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

struct evp_md_ctx_st;

namespace skybake {

class Sha256 {
 public:
  Sha256();
  ~Sha256();
  Sha256(const Sha256&) = delete;
  Sha256& operator=(const Sha256&) = delete;
  void Update(const void* data, std::size_t size);
  // The 32-byte digest; the object must not be updated afterwards.
  std::array<std::uint8_t, 32> Finish();

 private:
  evp_md_ctx_st* context_;
};

// Lower-case hexadecimal digest of `bytes` (64 characters).
std::string Sha256Hex(std::string_view bytes);
std::string Sha256Hex(const void* data, std::size_t size);

}  // namespace skybake
