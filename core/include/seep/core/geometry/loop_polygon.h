// The polygon through a loop of particle centres: its signed area and centroid, summed relative
// to the loop's first vertex (precision far from the origin), and the even-odd point test. One
// definition for every face trace (DomainDetector, LocalDomainDetector, the fluid weight's
// centroids), so that they add the same terms in the same order and agree to the bit.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

namespace seep::core {

class LoopPolygonSums {
 public:
  // (x0, y0): the loop's first vertex.
  LoopPolygonSums(double x0, double y0) : x0_(x0), y0_(y0) {}

  // The loop's next edge, from vertex (xv, yv) to vertex (xw, yw).
  void AddEdge(double xv, double yv, double xw, double yw) {
    const double ax = xv - x0_, ay = yv - y0_;
    const double bx = xw - x0_, by = yw - y0_;
    const double cross = ax * by - bx * ay;
    twice_area_ += cross;
    cx_ += (ax + bx) * cross;
    cy_ += (ay + by) * cross;
    sum_x_ += ax;
    sum_y_ += ay;
    ++count_;
  }

  // Signed area: positive for a counter-clockwise loop.
  double area() const { return 0.5 * twice_area_; }
  // The polygon's centroid, or the vertex mean of a loop of zero area.
  double centroid_x() const {
    return twice_area_ != 0.0 ? x0_ + cx_ / (3.0 * twice_area_)
                              : x0_ + sum_x_ / static_cast<double>(count_);
  }
  double centroid_y() const {
    return twice_area_ != 0.0 ? y0_ + cy_ / (3.0 * twice_area_)
                              : y0_ + sum_y_ / static_cast<double>(count_);
  }

 private:
  double x0_, y0_;
  double twice_area_ = 0.0;
  double cx_ = 0.0, cy_ = 0.0;        // sums of (a + b) x cross, for the centroid
  double sum_x_ = 0.0, sum_y_ = 0.0;  // vertex sums, for a loop of zero area
  std::size_t count_ = 0;
};

// Even-odd crossing test of point (px, py) against the polygon through the centres of `loop`
// (particle ids into x and y). A point on the boundary may fall either way.
inline bool LoopContains(std::span<const std::int32_t> loop, const double* x, const double* y,
                         double px, double py) {
  bool inside = false;
  std::size_t prev = static_cast<std::size_t>(loop.back());
  for (const std::int32_t id : loop) {
    const auto cur = static_cast<std::size_t>(id);
    const double xa = x[cur], ya = y[cur];
    const double xb = x[prev], yb = y[prev];
    if ((ya > py) != (yb > py)) {
      const double x_cross = xa + (xb - xa) * (py - ya) / (yb - ya);
      if (px < x_cross) inside = !inside;
    }
    prev = cur;
  }
  return inside;
}

}  // namespace seep::core
