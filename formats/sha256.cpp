#include "formats/sha256.h"

#include <openssl/evp.h>

#include "core/errors.h"

namespace skybake {

Sha256::Sha256() : context_(EVP_MD_CTX_new()) {
  if (context_ == nullptr || EVP_DigestInit_ex(context_, EVP_sha256(), nullptr) != 1) {
    EVP_MD_CTX_free(context_);
    throw InternalError("SHA-256: OpenSSL could not set up a digest");
  }
}

Sha256::~Sha256() { EVP_MD_CTX_free(context_); }

void Sha256::Update(const void* data, std::size_t size) {
  if (EVP_DigestUpdate(context_, data, size) != 1) throw InternalError("SHA-256: OpenSSL's update failed");
}

std::array<std::uint8_t, 32> Sha256::Finish() {
  std::array<std::uint8_t, 32> digest;
  unsigned int length = 0;
  if (EVP_DigestFinal_ex(context_, digest.data(), &length) != 1 || length != digest.size()) {
    throw InternalError("SHA-256: OpenSSL's final step failed");
  }
  return digest;
}

std::string Sha256Hex(const void* data, std::size_t size) {
  Sha256 hash;
  hash.Update(data, size);
  static const char kHex[] = "0123456789abcdef";
  std::string hex;
  for (std::uint8_t byte : hash.Finish()) {
    hex += kHex[byte >> 4];
    hex += kHex[byte & 15];
  }
  return hex;
}

std::string Sha256Hex(std::string_view bytes) { return Sha256Hex(bytes.data(), bytes.size()); }

}  // namespace skybake
