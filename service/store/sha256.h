// SHA-256 (OpenSSL) of a byte string: checkpoint chunks and files, the scene a checkpoint belongs
// to, a calibration's setup and a result's final state.
#pragma once

#include <string>
#include <string_view>

namespace seep::service {

// 32 raw bytes.
std::string Sha256(std::string_view bytes);
// The same digest as 64 lower-case hex digits.
std::string HexSha256(std::string_view bytes);

}  // namespace seep::service
