// CellGrid: uniform cell grid over 2D points for O(N) neighbour search, optionally periodic in x
// and/or y.
//
// Build() bins the points into cells at least `reach` wide, so every pair of points closer than
// `reach` (in the minimum image, when periodic) lies in the same or in adjacent cells.
// ForEachNeighbour(a, visit) then calls visit(b, dx, dy) once for every point b > a in the 3x3
// block of cells around a, with (dx, dy) = position of b - position of a, taken as the minimum
// image along a periodic axis. It visits a superset of the pairs within reach, in no particular
// order: callers filter by their own distance test and sort, so their output depends only on that
// test, never on the cell layout.
//
// Periodic axes: cells tile [origin, origin + period) and wrap; points may lie outside that range
// (they are binned by their image inside it). The period must hold at least 3 cells of `reach`, so
// that the 3 cells around a point are distinct and a pair has only one image within reach.
//
// The grid keeps pointers to the coordinates passed to Build(): they must stay alive and unchanged
// while it is queried. Buffers are kept between builds: after the first one it allocates nothing
// unless the point count or the cell count grows.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "seep/core/status.h"

namespace seep::core {

struct CellGridAxis {
  bool periodic = false;
  double origin = 0.0;  // periodic only: cells tile [origin, origin + period)
  double period = 0.0;  // periodic only: > 0 and >= 3 reach
};

struct CellGridOptions {
  double reach = 0.0;  // > 0: pairs closer than this are in adjacent cells
  CellGridAxis x, y;
};

class CellGrid {
 public:
  // Bins the points (x and y of equal length < 2^31, finite). InvalidArgument when the options
  // are bad; the message for a periodic axis too short for 3 cells ("the periodic length ...")
  // carries no prefix, so that callers can name their own setting.
  Status Build(std::span<const double> x, std::span<const double> y,
               const CellGridOptions& options);

  template <typename Visit>
  void ForEachNeighbour(std::int32_t a, Visit&& visit) const;

  std::size_t size() const { return cell_of_.size(); }
  // Heap bytes held by the grid buffers.
  std::size_t MemoryBytes() const;

 private:
  struct Axis {
    std::int32_t cells = 1;
    bool periodic = false;
    double period = 0.0;
  };
  // The cells around point a as runs of consecutive cells (a row's cells are consecutive except
  // where a periodic x wraps), given as item ranges [begin, end): fewer, longer loops than one
  // per cell. Returns how many (<= 6).
  int NeighbourRanges(std::int32_t a, std::int32_t begin[6], std::int32_t end[6]) const;
  template <bool kWrap, typename Visit>
  void VisitRanges(std::int32_t a, const std::int32_t begin[6], const std::int32_t end[6],
                   int ranges, Visit& visit) const;

  const double* x_ = nullptr;
  const double* y_ = nullptr;
  Axis ax_, ay_;
  std::vector<std::int32_t> cell_of_;     // cell index of each point
  std::vector<std::int32_t> cell_start_;  // CSR offsets into cell_items_, size cells + 1
  std::vector<std::int32_t> cell_items_;  // point ids grouped by cell, ascending within a cell
  std::vector<std::int32_t> fill_;        // counting-sort cursor
};

inline int CellGrid::NeighbourRanges(std::int32_t a, std::int32_t begin[6],
                                     std::int32_t end[6]) const {
  const std::int32_t nx = ax_.cells, ny = ay_.cells;
  const std::int32_t ca = cell_of_[static_cast<std::size_t>(a)];
  const std::int32_t cx = ca % nx, cy = ca / nx;
  std::int32_t rows[3];
  int nrows = 0;
  if (ay_.periodic) {
    rows[nrows++] = cy == 0 ? ny - 1 : cy - 1;
    rows[nrows++] = cy;
    rows[nrows++] = cy + 1 == ny ? 0 : cy + 1;
  } else {
    for (std::int32_t r = std::max(cy - 1, 0); r <= std::min(cy + 1, ny - 1); ++r)
      rows[nrows++] = r;
  }
  // Column runs [lo, hi] within a row.
  std::int32_t lo[2], hi[2];
  int runs = 1;
  lo[0] = std::max(cx - 1, 0);
  hi[0] = std::min(cx + 1, nx - 1);
  if (ax_.periodic && cx == 0) lo[1] = hi[1] = nx - 1, runs = 2;
  if (ax_.periodic && cx + 1 == nx) lo[1] = hi[1] = 0, runs = 2;
  int k = 0;
  for (int r = 0; r < nrows; ++r) {
    const std::size_t row = static_cast<std::size_t>(rows[r]) * static_cast<std::size_t>(nx);
    for (int q = 0; q < runs; ++q) {
      begin[k] = cell_start_[row + static_cast<std::size_t>(lo[q])];
      end[k] = cell_start_[row + static_cast<std::size_t>(hi[q]) + 1];
      ++k;
    }
  }
  return k;
}

template <typename Visit>
void CellGrid::ForEachNeighbour(std::int32_t a, Visit&& visit) const {
  std::int32_t begin[6], end[6];
  const int ranges = NeighbourRanges(a, begin, end);
  // Open grids skip the minimum-image arithmetic altogether (it is the hot loop of detection).
  if (ax_.periodic || ay_.periodic) {
    VisitRanges<true>(a, begin, end, ranges, visit);
  } else {
    VisitRanges<false>(a, begin, end, ranges, visit);
  }
}

template <bool kWrap, typename Visit>
void CellGrid::VisitRanges(std::int32_t a, const std::int32_t begin[6], const std::int32_t end[6],
                           int ranges, Visit& visit) const {
  const double* x = x_;
  const double* y = y_;
  const std::int32_t* items = cell_items_.data();
  const bool wrap_x = ax_.periodic, wrap_y = ay_.periodic;
  const double lx = ax_.period, ly = ay_.period;
  const double xa = x[a], ya = y[a];
  for (int k = 0; k < ranges; ++k) {
    for (std::int32_t s = begin[k]; s < end[k]; ++s) {
      const std::int32_t b = items[s];
      if (b <= a) continue;
      double dx = x[b] - xa;
      double dy = y[b] - ya;
      if constexpr (kWrap) {
        // Rounded, not one period off by cell: the points need not be wrapped into the period.
        if (wrap_x) dx -= lx * std::round(dx / lx);
        if (wrap_y) dy -= ly * std::round(dy / ly);
      }
      visit(b, dx, dy);
    }
  }
}

}  // namespace seep::core
