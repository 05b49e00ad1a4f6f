#include "region_overlap.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <type_traits>
#include <variant>

namespace seep::core::spec_internal {
namespace {

struct Point {
  double x = 0.0, y = 0.0;
};

Point Vertex(const PolygonShape& p, std::size_t k) { return {p.x[k], p.y[k]}; }

// > 0: c lies left of the direction a -> b.
double Orient(Point a, Point b, Point c) {
  return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

// c, collinear with a-b, lies within the segment's bounding box.
bool WithinBox(Point a, Point b, Point c) {
  return std::min(a.x, b.x) <= c.x && c.x <= std::max(a.x, b.x) && std::min(a.y, b.y) <= c.y &&
         c.y <= std::max(a.y, b.y);
}

// The closed segments a-b and c-d meet (cross, touch, or overlap collinearly).
bool SegmentsMeet(Point a, Point b, Point c, Point d) {
  const double d1 = Orient(c, d, a), d2 = Orient(c, d, b);
  const double d3 = Orient(a, b, c), d4 = Orient(a, b, d);
  if (((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0)) &&
      ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0))) {
    return true;
  }
  return (d1 == 0.0 && WithinBox(c, d, a)) || (d2 == 0.0 && WithinBox(c, d, b)) ||
         (d3 == 0.0 && WithinBox(a, b, c)) || (d4 == 0.0 && WithinBox(a, b, d));
}

double PointSegmentDistance(Point p, Point a, Point b) {
  const double ex = b.x - a.x, ey = b.y - a.y;
  const double length2 = ex * ex + ey * ey;
  double t = length2 > 0.0 ? ((p.x - a.x) * ex + (p.y - a.y) * ey) / length2 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  return std::hypot(p.x - (a.x + t * ex), p.y - (a.y + t * ey));
}

double SegmentDistance(Point a, Point b, Point c, Point d) {
  if (SegmentsMeet(a, b, c, d)) return 0.0;
  return std::min({PointSegmentDistance(a, c, d), PointSegmentDistance(b, c, d),
                   PointSegmentDistance(c, a, b), PointSegmentDistance(d, a, b)});
}

// The frame's part of the half-plane (Sutherland-Hodgman against its one line); fewer than three
// vertices when the half-plane misses the frame.
PolygonShape ClipFrame(const HalfPlaneShape& h, const Frame& f) {
  const Point corners[] = {{f.x0, f.y0}, {f.x1, f.y0}, {f.x1, f.y1}, {f.x0, f.y1}};
  const auto side = [&h](Point p) { return h.nx * (p.x - h.px) + h.ny * (p.y - h.py); };
  PolygonShape out;
  const auto add = [&out](Point p) {
    out.x.push_back(p.x);
    out.y.push_back(p.y);
  };
  for (std::size_t k = 0; k < 4; ++k) {
    const Point s = corners[(k + 3) % 4];
    const Point e = corners[k];
    const double fs = side(s), fe = side(e);
    const auto cut = [&] {
      const double t = fs / (fs - fe);
      add({s.x + t * (e.x - s.x), s.y + t * (e.y - s.y)});
    };
    if (fe >= 0.0) {
      if (fs < 0.0) cut();
      add(e);
    } else if (fs >= 0.0) {
      cut();
    }
  }
  return out;
}

// A box or a polygon as a polygon; a half-plane as its part of the frame.
PolygonShape AsPolygon(const RegionShape& shape, const Frame& frame) {
  if (const auto* box = std::get_if<BoxShape>(&shape)) {
    return PolygonShape{{box->x0, box->x1, box->x1, box->x0}, {box->y0, box->y0, box->y1, box->y1}};
  }
  if (const auto* half = std::get_if<HalfPlaneShape>(&shape)) return ClipFrame(*half, frame);
  return std::get<PolygonShape>(shape);
}

bool Contains(const PolygonShape& polygon, Point p) {
  return RegionContains(RegionShape(polygon), p.x, p.y);
}

// A circle against any other shape but a circle.
bool CircleMeets(const CircleShape& c, const RegionShape& other, const Frame& frame,
                 double tolerance) {
  if (const auto* half = std::get_if<HalfPlaneShape>(&other)) {
    // The centre's signed distance from the line, positive inside the half-plane.
    const double n = std::hypot(half->nx, half->ny);
    const double distance = (half->nx * (c.cx - half->px) + half->ny * (c.cy - half->py)) / n;
    return distance >= -(c.r + tolerance);
  }
  const PolygonShape polygon = AsPolygon(other, frame);
  const Point centre{c.cx, c.cy};
  if (Contains(polygon, centre)) return true;
  const std::size_t n = polygon.x.size();
  for (std::size_t i = 0, j = n - 1; i < n; j = i++) {
    if (PointSegmentDistance(centre, Vertex(polygon, j), Vertex(polygon, i)) <= c.r + tolerance) {
      return true;
    }
  }
  return false;
}

Frame BoundsOf(const PolygonShape& p) {
  const auto [x0, x1] = std::minmax_element(p.x.begin(), p.x.end());
  const auto [y0, y1] = std::minmax_element(p.y.begin(), p.y.end());
  return {*x0, *y0, *x1, *y1};
}

// Two polygons share area or come within the tolerance: an edge of one within it of an edge of
// the other, or (no boundary near the other's) one wholly inside the other.
bool PolygonsMeet(const PolygonShape& a, const PolygonShape& b, double tolerance) {
  if (a.x.size() < 3 || b.x.size() < 3) return false;  // a half-plane that misses the frame
  const Frame fa = BoundsOf(a), fb = BoundsOf(b);
  if (fa.x0 > fb.x1 + tolerance || fb.x0 > fa.x1 + tolerance || fa.y0 > fb.y1 + tolerance ||
      fb.y0 > fa.y1 + tolerance) {
    return false;
  }
  const std::size_t na = a.x.size(), nb = b.x.size();
  for (std::size_t i = 0, j = na - 1; i < na; j = i++) {
    for (std::size_t k = 0, l = nb - 1; k < nb; l = k++) {
      if (SegmentDistance(Vertex(a, j), Vertex(a, i), Vertex(b, l), Vertex(b, k)) <= tolerance) {
        return true;
      }
    }
  }
  return Contains(b, Vertex(a, 0)) || Contains(a, Vertex(b, 0));
}

}  // namespace

double TwiceSignedArea(const std::vector<double>& x, const std::vector<double>& y) {
  double area = 0.0;
  const std::size_t n = x.size();
  for (std::size_t i = 0, j = n - 1; i < n; j = i++) area += x[j] * y[i] - x[i] * y[j];
  return area;
}

bool SelfIntersects(const std::vector<double>& x, const std::vector<double>& y, std::size_t* first,
                    std::size_t* second) {
  const std::size_t n = x.size();
  const auto at = [&](std::size_t k) { return Point{x[k % n], y[k % n]}; };
  for (std::size_t i = 0; i < n; ++i) {
    // Neighbours i and i + 1 share vertex i + 1; they fold back when they run on one line in
    // opposite directions (a spike of zero width).
    const Point a = at(i), b = at(i + 1), c = at(i + 2);
    const double dot = (b.x - a.x) * (c.x - b.x) + (b.y - a.y) * (c.y - b.y);
    if (Orient(a, b, c) == 0.0 && dot < 0.0) {
      *first = i;
      *second = (i + 1) % n;
      return true;
    }
    // Edges that share no vertex must not meet.
    for (std::size_t j = i + 2; j < n; ++j) {
      if (i == 0 && j == n - 1) continue;  // the closing edge neighbours edge 0
      if (SegmentsMeet(a, b, at(j), at(j + 1))) {
        *first = i;
        *second = j;
        return true;
      }
    }
  }
  return false;
}

bool ShapesOverlap(const RegionShape& a, const RegionShape& b, const Frame& frame,
                   double tolerance) {
  const auto* ca = std::get_if<CircleShape>(&a);
  const auto* cb = std::get_if<CircleShape>(&b);
  if (ca != nullptr && cb != nullptr) {
    return std::hypot(ca->cx - cb->cx, ca->cy - cb->cy) <= ca->r + cb->r + tolerance;
  }
  if (ca != nullptr) return CircleMeets(*ca, b, frame, tolerance);
  if (cb != nullptr) return CircleMeets(*cb, a, frame, tolerance);
  return PolygonsMeet(AsPolygon(a, frame), AsPolygon(b, frame), tolerance);
}

}  // namespace seep::core::spec_internal
