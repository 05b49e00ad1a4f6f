// Random numbers from the kernel's cryptographic generator (getrandom(2), /dev/urandom when the
// call is not available), for identifiers that must not be guessed or repeated: job ids and the
// lease owner of a seepd process. A seeded std::mt19937 is neither: its state is recovered from a
// few outputs and a bad seed repeats whole sequences.
#pragma once

#include <cstdint>

#include "seep/core/status.h"

namespace seep::service {

// UNAVAILABLE (with the reason) only when neither source can be read.
core::Result<std::uint64_t> SecureRandomU64();

}  // namespace seep::service
