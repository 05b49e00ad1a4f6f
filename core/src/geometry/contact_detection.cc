#include "seep/core/geometry/contact_detection.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <string>

namespace seep::core {

void ContactList::Clear() {
  i.clear();
  j.clear();
  gap.clear();
}

std::size_t ContactList::MemoryBytes() const {
  return sizeof(std::int32_t) * (i.capacity() + j.capacity()) + sizeof(double) * gap.capacity();
}

std::size_t ContactDetector::MemoryBytes() const {
  return grid_.MemoryBytes() + sizeof(std::int32_t) * candidates_.capacity() +
         sizeof(double) * candidate_gaps_.capacity();
}

namespace {
std::atomic<std::uint64_t> g_contact_detection_calls{0};
}  // namespace

std::uint64_t ContactDetectionCalls() {
  return g_contact_detection_calls.load(std::memory_order_relaxed);
}

Status ContactDetector::Detect(const Packing& packing, double max_gap, ContactList* contacts) {
  g_contact_detection_calls.fetch_add(1, std::memory_order_relaxed);
  contacts->Clear();
  const std::size_t n = packing.size();
  if (packing.y.size() != n || packing.radius.size() != n) {
    return InvalidArgument("contact detection: packing arrays differ in length");
  }
  if (n == 0) return Status::Ok();
  if (n > static_cast<std::size_t>(INT32_MAX)) {
    return InvalidArgument("contact detection: more than 2^31-1 particles");
  }
  const double* pr = packing.radius.data();

  double r_max = pr[0], r_min = pr[0];
  for (std::size_t k = 1; k < n; ++k) {
    r_max = std::max(r_max, pr[k]);
    r_min = std::min(r_min, pr[k]);
  }
  if (!std::isfinite(max_gap) || !(max_gap > -r_min)) {
    return InvalidArgument("contact detection: max_gap must be finite and > -min(radius) (got " +
                           std::to_string(max_gap) + ")");
  }
  // Any pair within reach is at most one cell apart when the cell is 2 r_max + max_gap wide.
  CellGridOptions grid_options;
  grid_options.reach = 2.0 * r_max + std::max(max_gap, 0.0);
  SEEP_RETURN_IF_ERROR(grid_.Build(packing.x, packing.y, grid_options));

  // A dense packing has about 3 contacts per particle; reserve so that push_back rarely grows.
  contacts->i.reserve(3 * n);
  contacts->j.reserve(3 * n);
  contacts->gap.reserve(3 * n);
  candidates_.clear();
  candidate_gaps_.clear();

  for (std::size_t a = 0; a < n; ++a) {
    const double ra = pr[a];
    candidates_.clear();
    candidate_gaps_.clear();
    grid_.ForEachNeighbour(static_cast<std::int32_t>(a), [&](std::int32_t b, double dx, double dy) {
      const double rb = pr[static_cast<std::size_t>(b)];
      const double reach = ra + rb + max_gap;  // > 0 by the max_gap check
      const double d2 = dx * dx + dy * dy;
      if (d2 > reach * reach) return;
      const double g = std::sqrt(d2) - ra - rb;
      if (g > max_gap) return;
      candidates_.push_back(b);
      candidate_gaps_.push_back(g);
    });
    // Few candidates per particle: insertion sort by neighbour id.
    for (std::size_t p = 1; p < candidates_.size(); ++p) {
      const std::int32_t b = candidates_[p];
      const double g = candidate_gaps_[p];
      std::size_t q = p;
      while (q > 0 && candidates_[q - 1] > b) {
        candidates_[q] = candidates_[q - 1];
        candidate_gaps_[q] = candidate_gaps_[q - 1];
        --q;
      }
      candidates_[q] = b;
      candidate_gaps_[q] = g;
    }
    for (std::size_t p = 0; p < candidates_.size(); ++p) {
      contacts->i.push_back(static_cast<std::int32_t>(a));
      contacts->j.push_back(candidates_[p]);
      contacts->gap.push_back(candidate_gaps_[p]);
    }
  }
  return Status::Ok();
}

Result<ContactList> DetectContacts(const Packing& packing, double max_gap) {
  ContactDetector detector;
  ContactList contacts;
  SEEP_RETURN_IF_ERROR(detector.Detect(packing, max_gap, &contacts));
  return contacts;
}

}  // namespace seep::core
