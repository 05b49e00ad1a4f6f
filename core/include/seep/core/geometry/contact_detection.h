// Contact detection: every pair of disks closer than a gap threshold, found with a uniform cell
// grid in O(N).
//
// Output (ContactList, one entry per pair, structure of arrays):
//   i[c] < j[c]   the two particle ids (indices into the Packing);
//   gap[c]        |x_i - x_j| - r_i - r_j, same length unit as the packing; negative = overlap.
// Every pair with gap <= max_gap is listed exactly once, sorted by (i, j), so iteration order is
// deterministic and a contact's index c is stable for a given input. The contact index is what
// domain detection stores in loops and pipes.
//
// ContactDetector keeps its cell grid between calls: it is meant to be called every DEM step,
// and after the first call it allocates nothing unless the particle count or extent grows.
// No hash maps and no unordered containers are used.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "seep/core/geometry/cell_grid.h"
#include "seep/core/geometry/packing.h"
#include "seep/core/status.h"

namespace seep::core {

struct ContactList {
  std::vector<std::int32_t> i;  // lower particle id
  std::vector<std::int32_t> j;  // higher particle id
  std::vector<double> gap;      // surface gap (negative = overlap)

  std::size_t size() const { return i.size(); }
  void Clear();
  std::size_t MemoryBytes() const;
};

class ContactDetector {
 public:
  // Fills `contacts` (cleared first) with every pair whose gap <= max_gap. max_gap must be finite
  // and > -min(radius) (a pair cannot overlap by more than the smaller diameter and still be
  // found by the grid). The packing is validated only cheaply (array lengths); call
  // ValidatePacking() once on untrusted input.
  Status Detect(const Packing& packing, double max_gap, ContactList* contacts);

  // Heap bytes held by the grid buffers.
  std::size_t MemoryBytes() const;

 private:
  CellGrid grid_;
  std::vector<std::int32_t> candidates_;  // per-particle scratch: neighbours j > i
  std::vector<double> candidate_gaps_;    // their gaps
};

// Process-wide count of ContactDetector::Detect calls (relaxed atomic; instrumentation only, it
// never influences a result): lets a test prove that a run detects nothing after its set-up.
std::uint64_t ContactDetectionCalls();

// Convenience wrapper with a throw-away detector.
Result<ContactList> DetectContacts(const Packing& packing, double max_gap);

}  // namespace seep::core
