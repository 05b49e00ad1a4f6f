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
  return sizeof(std::int32_t) * (cell_of_.capacity() + cell_start_.capacity() +
                                 cell_items_.capacity() + candidates_.capacity()) +
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
  const double* px = packing.x.data();
  const double* py = packing.y.data();
  const double* pr = packing.radius.data();

  double x_min = px[0], x_max = px[0], y_min = py[0], y_max = py[0];
  double r_max = pr[0], r_min = pr[0];
  for (std::size_t k = 1; k < n; ++k) {
    x_min = std::min(x_min, px[k]);
    x_max = std::max(x_max, px[k]);
    y_min = std::min(y_min, py[k]);
    y_max = std::max(y_max, py[k]);
    r_max = std::max(r_max, pr[k]);
    r_min = std::min(r_min, pr[k]);
  }
  if (!std::isfinite(max_gap) || !(max_gap > -r_min)) {
    return InvalidArgument("contact detection: max_gap must be finite and > -min(radius) (got " +
                           std::to_string(max_gap) + ")");
  }

  // Any pair within reach is at most one cell apart when the cell is 2 r_max + max_gap wide.
  // The cell is widened if the grid would have far more cells than particles (sparse input).
  double cell = 2.0 * r_max + std::max(max_gap, 0.0);
  const double span_x = x_max - x_min;
  const double span_y = y_max - y_min;
  const double max_cells = 4.0 * static_cast<double>(n) + 16.0;
  if ((span_x / cell + 1.0) * (span_y / cell + 1.0) > max_cells) {
    cell = std::max(cell, std::sqrt(span_x * span_y / max_cells) * 1.5);
    while ((span_x / cell + 1.0) * (span_y / cell + 1.0) > max_cells) cell *= 1.5;
  }
  const std::int32_t nx = static_cast<std::int32_t>(span_x / cell) + 1;
  const std::int32_t ny = static_cast<std::int32_t>(span_y / cell) + 1;
  const std::size_t num_cells = static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny);
  const double inv_cell = 1.0 / cell;

  // Counting sort of particle ids by cell; ids stay ascending within a cell.
  cell_of_.resize(n);
  cell_start_.assign(num_cells + 1, 0);
  for (std::size_t k = 0; k < n; ++k) {
    const std::int32_t cx = std::min(nx - 1, static_cast<std::int32_t>((px[k] - x_min) * inv_cell));
    const std::int32_t cy = std::min(ny - 1, static_cast<std::int32_t>((py[k] - y_min) * inv_cell));
    const std::int32_t c = cy * nx + cx;
    cell_of_[k] = c;
    ++cell_start_[static_cast<std::size_t>(c) + 1];
  }
  for (std::size_t c = 0; c < num_cells; ++c) cell_start_[c + 1] += cell_start_[c];
  cell_items_.resize(n);
  {
    // Reuse candidates_ as the fill cursor to avoid another buffer.
    candidates_.assign(cell_start_.begin(), cell_start_.end() - 1);
    for (std::size_t k = 0; k < n; ++k) {
      cell_items_[static_cast<std::size_t>(candidates_[static_cast<std::size_t>(cell_of_[k])]++)] =
          static_cast<std::int32_t>(k);
    }
  }

  // A dense packing has about 3 contacts per particle; reserve so that push_back rarely grows.
  contacts->i.reserve(3 * n);
  contacts->j.reserve(3 * n);
  contacts->gap.reserve(3 * n);
  candidates_.clear();
  candidate_gaps_.clear();

  for (std::size_t a = 0; a < n; ++a) {
    const std::int32_t ca = cell_of_[a];
    const std::int32_t cx = ca % nx;
    const std::int32_t cy = ca / nx;
    const double xa = px[a], ya = py[a], ra = pr[a];
    candidates_.clear();
    candidate_gaps_.clear();
    for (std::int32_t gy = std::max(cy - 1, 0); gy <= std::min(cy + 1, ny - 1); ++gy) {
      for (std::int32_t gx = std::max(cx - 1, 0); gx <= std::min(cx + 1, nx - 1); ++gx) {
        const std::size_t c = static_cast<std::size_t>(gy) * static_cast<std::size_t>(nx) +
                              static_cast<std::size_t>(gx);
        for (std::int32_t s = cell_start_[c]; s < cell_start_[c + 1]; ++s) {
          const std::int32_t b = cell_items_[static_cast<std::size_t>(s)];
          if (static_cast<std::size_t>(b) <= a) continue;
          const double dx = px[b] - xa;
          const double dy = py[b] - ya;
          const double reach = ra + pr[b] + max_gap;  // > 0 by the max_gap check
          const double d2 = dx * dx + dy * dy;
          if (d2 > reach * reach) continue;
          const double g = std::sqrt(d2) - ra - pr[b];
          if (g > max_gap) continue;
          candidates_.push_back(b);
          candidate_gaps_.push_back(g);
        }
      }
    }
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
