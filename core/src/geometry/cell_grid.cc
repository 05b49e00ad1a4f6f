#include "seep/core/geometry/cell_grid.h"

#include <fmt/format.h>

#include <limits>
#include <string>

namespace seep::core {
namespace {

// Where the points of one axis lie: [lo, lo + span] for an open axis, one period for a periodic
// one (lo = origin).
struct AxisExtent {
  bool periodic = false;
  double lo = 0.0;
  double span = 0.0;
};

// Cells of width >= `width` along the axis (a periodic axis keeps >= 3, which Build checked
// still leaves them >= reach wide).
double CellCount(const AxisExtent& e, double width) {
  if (e.periodic) return std::max(3.0, std::floor(e.span / width));
  return std::floor(e.span / width) + 1.0;
}

Status ValidateAxis(const char* name, const CellGridAxis& axis, double reach) {
  if (!axis.periodic) return Status::Ok();
  if (!std::isfinite(axis.origin) || !std::isfinite(axis.period) || !(axis.period > 0.0)) {
    return InvalidArgument(std::string("cell grid: periodic ") + name +
                           " needs a finite origin and a finite period > 0");
  }
  if (std::floor(axis.period / reach) < 3.0) {
    return InvalidArgument("the periodic length " + std::to_string(axis.period) +
                           " must hold at least 3 cells of the reach " + std::to_string(reach));
  }
  return Status::Ok();
}

// Bins coordinates along one axis.
struct AxisBinning {
  bool periodic = false;
  double lo = 0.0;
  double inv = 0.0;  // 1 / period when periodic, 1 / cell width otherwise
  std::int32_t cells = 1;

  std::int32_t CellOf(double v) const {
    if (periodic) {
      // Fraction of a period first, so that a point far outside the period cannot overflow.
      double u = (v - lo) * inv;
      u -= std::floor(u);
      return std::min(cells - 1, static_cast<std::int32_t>(u * static_cast<double>(cells)));
    }
    return std::min(cells - 1, static_cast<std::int32_t>((v - lo) * inv));
  }
};

}  // namespace

std::size_t CellGrid::MemoryBytes() const {
  return sizeof(std::int32_t) *
         (cell_of_.capacity() + cell_start_.capacity() + cell_items_.capacity() + fill_.capacity());
}

Status CellGrid::Build(std::span<const double> x, std::span<const double> y,
                       const CellGridOptions& options) {
  const std::size_t n = x.size();
  if (y.size() != n) return InvalidArgument("cell grid: x and y differ in length");
  if (n > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max())) {
    return InvalidArgument("cell grid: more than 2^31-1 points");
  }
  const double reach = options.reach;
  // Normal, not only > 0: the inverse of a subnormal cell width is inf, which bins a point at
  // NaN and indexes outside the cells.
  if (!std::isfinite(reach) || !(reach > 0.0) || !std::isnormal(reach)) {
    return InvalidArgument("cell grid: reach must be a finite normal number > 0 (got " +
                           fmt::format("{}", reach) + ")");
  }
  SEEP_RETURN_IF_ERROR(ValidateAxis("x", options.x, reach));
  SEEP_RETURN_IF_ERROR(ValidateAxis("y", options.y, reach));
  x_ = x.data();
  y_ = y.data();

  AxisExtent ex{options.x.periodic, options.x.origin, options.x.period};
  AxisExtent ey{options.y.periodic, options.y.origin, options.y.period};
  if (n > 0 && (!ex.periodic || !ey.periodic)) {
    double x_min = x[0], x_max = x[0], y_min = y[0], y_max = y[0];
    for (std::size_t k = 1; k < n; ++k) {
      x_min = std::min(x_min, x[k]);
      x_max = std::max(x_max, x[k]);
      y_min = std::min(y_min, y[k]);
      y_max = std::max(y_max, y[k]);
    }
    if (!ex.periodic) ex = {false, x_min, x_max - x_min};
    if (!ey.periodic) ey = {false, y_min, y_max - y_min};
  }

  // Widen the cells when the grid would have far more cells than points (sparse input): larger
  // cells are still correct, only slower. The count ends at <= 9 cells at worst.
  const double max_cells =
      std::min(4.0 * static_cast<double>(n) + 16.0, static_cast<double>(1 << 30));
  double width = reach;
  if (CellCount(ex, width) * CellCount(ey, width) > max_cells) {
    width = std::max(width, std::sqrt(ex.span * ey.span / max_cells) * 1.5);
    while (CellCount(ex, width) * CellCount(ey, width) > max_cells) width *= 1.5;
  }
  ax_ = Axis{static_cast<std::int32_t>(CellCount(ex, width)), ex.periodic, ex.span};
  ay_ = Axis{static_cast<std::int32_t>(CellCount(ey, width)), ey.periodic, ey.span};
  // A periodic axis divides its period evenly; an open one uses `width` itself.
  const AxisBinning bx{ex.periodic, ex.lo, 1.0 / (ex.periodic ? ex.span : width), ax_.cells};
  const AxisBinning by{ey.periodic, ey.lo, 1.0 / (ey.periodic ? ey.span : width), ay_.cells};
  const std::size_t num_cells =
      static_cast<std::size_t>(ax_.cells) * static_cast<std::size_t>(ay_.cells);

  // Counting sort of point ids by cell; ids stay ascending within a cell.
  cell_of_.resize(n);
  cell_start_.assign(num_cells + 1, 0);
  for (std::size_t k = 0; k < n; ++k) {
    const std::int32_t c = by.CellOf(y[k]) * ax_.cells + bx.CellOf(x[k]);
    cell_of_[k] = c;
    ++cell_start_[static_cast<std::size_t>(c) + 1];
  }
  for (std::size_t c = 0; c < num_cells; ++c) cell_start_[c + 1] += cell_start_[c];
  cell_items_.resize(n);
  fill_.assign(cell_start_.begin(), cell_start_.end() - 1);
  for (std::size_t k = 0; k < n; ++k) {
    cell_items_[static_cast<std::size_t>(fill_[static_cast<std::size_t>(cell_of_[k])]++)] =
        static_cast<std::int32_t>(k);
  }
  return Status::Ok();
}

}  // namespace seep::core
