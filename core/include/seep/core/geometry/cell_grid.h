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
  // are bad; a periodic axis too short for 3 cells says "period <p> ... reach <h>" so that
  // callers can name their own setting.
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
  // The up to 3 cells around `c` along one axis; returns how many.
  static int Around(std::int32_t c, const Axis& axis, std::int32_t out[3]) {
    if (axis.periodic) {
      out[0] = c == 0 ? axis.cells - 1 : c - 1;
      out[1] = c;
      out[2] = c + 1 == axis.cells ? 0 : c + 1;
      return 3;
    }
    int k = 0;
    for (std::int32_t d = std::max(c - 1, 0); d <= std::min(c + 1, axis.cells - 1); ++d) {
      out[k++] = d;
    }
    return k;
  }

  const double* x_ = nullptr;
  const double* y_ = nullptr;
  Axis ax_, ay_;
  std::vector<std::int32_t> cell_of_;     // cell index of each point
  std::vector<std::int32_t> cell_start_;  // CSR offsets into cell_items_, size cells + 1
  std::vector<std::int32_t> cell_items_;  // point ids grouped by cell, ascending within a cell
  std::vector<std::int32_t> fill_;        // counting-sort cursor
};

template <typename Visit>
void CellGrid::ForEachNeighbour(std::int32_t a, Visit&& visit) const {
  const std::size_t sa = static_cast<std::size_t>(a);
  const std::int32_t nx = ax_.cells;
  const std::int32_t ca = cell_of_[sa];
  std::int32_t cols[3], rows[3];
  const int ncols = Around(ca % nx, ax_, cols);
  const int nrows = Around(ca / nx, ay_, rows);
  const bool wrap_x = ax_.periodic, wrap_y = ay_.periodic;
  const double lx = ax_.period, ly = ay_.period;
  const double xa = x_[sa], ya = y_[sa];
  for (int r = 0; r < nrows; ++r) {
    for (int q = 0; q < ncols; ++q) {
      const std::size_t c = static_cast<std::size_t>(rows[r]) * static_cast<std::size_t>(nx) +
                            static_cast<std::size_t>(cols[q]);
      for (std::int32_t s = cell_start_[c]; s < cell_start_[c + 1]; ++s) {
        const std::int32_t b = cell_items_[static_cast<std::size_t>(s)];
        if (b <= a) continue;
        double dx = x_[static_cast<std::size_t>(b)] - xa;
        double dy = y_[static_cast<std::size_t>(b)] - ya;
        // Rounded, not one period off by cell: the points need not be wrapped into the period.
        if (wrap_x) dx -= lx * std::round(dx / lx);
        if (wrap_y) dy -= ly * std::round(dy / ly);
        visit(b, dx, dy);
      }
    }
  }
}

}  // namespace seep::core
