#include "sha256.h"

#include <fmt/format.h>
#include <openssl/sha.h>

namespace seep::service {

std::string Sha256(std::string_view bytes) {
  std::string digest(SHA256_DIGEST_LENGTH, '\0');
  SHA256(reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size(),
         reinterpret_cast<unsigned char*>(digest.data()));
  return digest;
}

std::string HexSha256(std::string_view bytes) {
  const std::string raw = Sha256(bytes);
  std::string hex;
  hex.reserve(raw.size() * 2);
  for (const unsigned char c : raw) hex += fmt::format("{:02x}", c);
  return hex;
}

}  // namespace seep::service
