// Independent reference computations for the geometry tests: brute-force contacts, lens area from
// circular segments, point-in-polygon and the solid area enclosed by outer loops. They share no
// code with the library on purpose.
#pragma once

#include <cmath>
#include <cstdint>
#include <numbers>
#include <utility>
#include <vector>

#include "seep/core/geometry/contact_detection.h"
#include "seep/core/geometry/domain_detection.h"
#include "seep/core/geometry/packing.h"

namespace seep::core::testing {

inline constexpr double kPi = std::numbers::pi;

// O(N^2) reference for ContactDetector: every pair i < j with gap <= max_gap, in (i, j) order.
inline ContactList BruteForceContacts(const Packing& p, double max_gap) {
  ContactList out;
  for (std::size_t i = 0; i < p.size(); ++i) {
    for (std::size_t j = i + 1; j < p.size(); ++j) {
      const double dx = p.x[j] - p.x[i];
      const double dy = p.y[j] - p.y[i];
      const double gap = std::sqrt(dx * dx + dy * dy) - p.radius[i] - p.radius[j];
      if (gap <= max_gap) {
        out.i.push_back(static_cast<std::int32_t>(i));
        out.j.push_back(static_cast<std::int32_t>(j));
        out.gap.push_back(gap);
      }
    }
  }
  return out;
}

// Lens of two overlapping disks as two circular segments cut by the radical chord.
inline double SegmentLens(double r1, double r2, double d) {
  if (d >= r1 + r2) return 0.0;
  const double a1 = (d * d + r1 * r1 - r2 * r2) / (2.0 * d);  // centre 1 to chord
  const double a2 = d - a1;
  auto segment = [](double r, double a) {
    // Area of the part of a disk of radius r beyond a line at signed distance a from its centre.
    return r * r * std::acos(a / r) - a * std::sqrt(r * r - a * a);
  };
  return segment(r1, a1) + segment(r2, a2);
}

inline double PolygonArea(const std::vector<double>& xs, const std::vector<double>& ys) {
  double twice = 0.0;
  for (std::size_t k = 0; k < xs.size(); ++k) {
    const std::size_t l = (k + 1) % xs.size();
    twice += (xs[k] - xs[0]) * (ys[l] - ys[0]) - (xs[l] - xs[0]) * (ys[k] - ys[0]);
  }
  return 0.5 * twice;
}

// Winding-number test (different from the library's crossing test).
inline bool InsidePolygon(const std::vector<double>& xs, const std::vector<double>& ys, double px,
                          double py) {
  int winding = 0;
  for (std::size_t k = 0; k < xs.size(); ++k) {
    const std::size_t l = (k + 1) % xs.size();
    const double cross = (xs[l] - xs[k]) * (py - ys[k]) - (px - xs[k]) * (ys[l] - ys[k]);
    if (ys[k] <= py) {
      if (ys[l] > py && cross > 0) ++winding;
    } else {
      if (ys[l] <= py && cross < 0) --winding;
    }
  }
  return winding != 0;
}

// Solid area inside the top-level outer loops, computed from the geometry: full disks whose centre
// is inside a loop, the inner part of each outer-loop disk (2 pi minus its outer-face angles at
// every visit, measured here with atan2 of the loop neighbours), minus each overlapping pair's
// lens once (half of it for pairs that are outer-loop edges). `contacts` must hold every
// overlapping pair.
inline double SolidInsideOuterLoops(const Packing& p, const ContactList& contacts,
                                    const DomainNetwork& net) {
  const std::size_t n = p.size();
  std::vector<char> on_loop(n, 0);
  std::vector<char> inside(n, 0);
  std::vector<double> outer_angle(n, 0.0);
  double solid = 0.0;
  std::vector<std::pair<std::int32_t, std::int32_t>> outer_edges;
  for (std::size_t k = 0; k < net.num_outer_faces(); ++k) {
    if (net.outer_host_domain[k] >= 0) continue;
    const std::int32_t b = net.outer_offsets[k];
    const std::int32_t e = net.outer_offsets[k + 1];
    std::vector<double> xs, ys;
    for (std::int32_t q = b; q < e; ++q) {
      const std::size_t v = static_cast<std::size_t>(net.outer_particles[q]);
      xs.push_back(p.x[v]);
      ys.push_back(p.y[v]);
      on_loop[v] = 1;
      const std::size_t prev =
          static_cast<std::size_t>(net.outer_particles[q == b ? e - 1 : q - 1]);
      const std::size_t next =
          static_cast<std::size_t>(net.outer_particles[q + 1 == e ? b : q + 1]);
      // The outer face lies left of the walk: CCW sweep from (next - v) to (prev - v).
      const double ax = p.x[next] - p.x[v], ay = p.y[next] - p.y[v];
      const double bx = p.x[prev] - p.x[v], by = p.y[prev] - p.y[v];
      double angle = std::atan2(ax * by - ay * bx, ax * bx + ay * by);
      if (angle < 0) angle += 2 * kPi;
      outer_angle[v] += angle;
      const std::int32_t u = std::min(net.outer_particles[q], static_cast<std::int32_t>(next));
      const std::int32_t w = std::max(net.outer_particles[q], static_cast<std::int32_t>(next));
      outer_edges.emplace_back(u, w);
    }
    for (std::size_t v = 0; v < n; ++v) {
      if (InsidePolygon(xs, ys, p.x[v], p.y[v])) inside[v] = 1;
    }
  }
  for (std::size_t v = 0; v < n; ++v) {
    const double r2 = p.radius[v] * p.radius[v];
    if (on_loop[v]) {
      solid += kPi * r2 - 0.5 * outer_angle[v] * r2;
    } else if (inside[v]) {
      solid += kPi * r2;
    }
  }
  for (std::size_t c = 0; c < contacts.size(); ++c) {
    if (!(contacts.gap[c] < 0)) continue;
    const std::size_t i = static_cast<std::size_t>(contacts.i[c]);
    const std::size_t j = static_cast<std::size_t>(contacts.j[c]);
    const bool i_in = on_loop[i] || inside[i];
    const bool j_in = on_loop[j] || inside[j];
    if (!i_in || !j_in) continue;
    const double lens =
        SegmentLens(p.radius[i], p.radius[j], p.radius[i] + p.radius[j] + contacts.gap[c]);
    std::size_t visits = 0;
    for (const auto& edge : outer_edges) {
      if (edge.first == contacts.i[c] && edge.second == contacts.j[c]) ++visits;
    }
    // Each visit of an outer walk along this edge has the outside on one side of it.
    solid -= visits == 0 ? lens : (visits == 1 ? 0.5 * lens : 0.0);
  }
  return solid;
}

template <typename T>
double Sum(const std::vector<T>& v) {
  double s = 0.0;
  for (const T& x : v) s += x;
  return s;
}

inline double SumTopLevelOuterArea(const DomainNetwork& net) {
  double s = 0.0;
  for (std::size_t k = 0; k < net.num_outer_faces(); ++k) {
    if (net.outer_host_domain[k] < 0) s += net.outer_area[k];
  }
  return s;
}

// Euler's relation V - E + cycles = 2 C after pruning.
inline bool EulerHolds(const DomainNetwork& net) {
  return net.euler.vertices - net.euler.edges + net.euler.cycles == 2 * net.euler.components;
}

}  // namespace seep::core::testing
