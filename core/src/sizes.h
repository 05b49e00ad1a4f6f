// Sizes and indices shared by the core's files: the heap a std::vector holds (for the
// MemoryBytes() reports), an id as an index.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace seep::core::internal {

// The heap of all the vectors passed, summed.
template <typename... T>
std::size_t VectorBytes(const std::vector<T>&... v) {
  return (std::size_t{0} + ... + (v.capacity() * sizeof(T)));
}

// An id as an index (ids are checked non-negative where they enter).
inline std::size_t Index(std::int32_t k) { return static_cast<std::size_t>(k); }

}  // namespace seep::core::internal
