// Things that sit inside a domain without bounding it: rattlers and dangling trees (particles
// pruned from the graph) and islands (whole components inside a domain of another component).
//
// A pruned tree hangs from at most one live particle (two attachments would close a cycle and the
// tree would not have been pruned), so its face is read off the attachment's angular order. Free
// rattlers/trees and islands need point location: a uniform grid over the domains' bounding
// boxes, built only when such a query exists.
#include <algorithm>
#include <cmath>
#include <numbers>

#include "seep/core/geometry/domain_detection.h"
#include "seep/core/geometry/loop_polygon.h"

namespace seep::core {
namespace {

// Even-odd test of point (px, py) against the polygon through domain `domain`'s loop.
bool DomainContains(const DomainNetwork& net, const Packing& packing, std::size_t domain, double px,
                    double py) {
  const auto begin = static_cast<std::size_t>(net.loop_offsets[domain]);
  const auto end = static_cast<std::size_t>(net.loop_offsets[domain + 1]);
  return LoopContains(std::span(net.loop_particles).subspan(begin, end - begin), packing.x.data(),
                      packing.y.data(), px, py);
}

// Point location over the domains of `net`, using buffers owned by the detector.
class DomainLocator {
 public:
  DomainLocator(const DomainNetwork& net, const Packing& packing,
                const std::vector<std::int32_t>& component, std::vector<std::int32_t>* grid_start,
                std::vector<std::int32_t>* grid_items, std::vector<double>* box,
                std::vector<std::int32_t>* cursor)
      : net_(net),
        packing_(packing),
        component_(component),
        grid_start_(*grid_start),
        grid_items_(*grid_items),
        box_(*box),
        cursor_(*cursor) {}

  // Smallest domain (by its polygon area) containing the point, skipping domains of
  // `skip_component`; -1 if none.
  std::int32_t Locate(double px, double py, std::int32_t skip_component) {
    if (net_.num_domains() == 0) return -1;
    if (!boxes_built_) BuildBoxes();
    if (px < x0_ || px > x1_ || py < y0_ || py > y1_) return -1;
    // A few queries (the common case: a handful of rattlers) scan the boxes; many build a grid.
    if (++queries_ > kScanQueries && !grid_built_) BuildGrid();
    std::int32_t best = -1;
    if (grid_built_) {
      const std::size_t c = Cell(CellX(px), CellY(py));
      for (std::int32_t k = grid_start_[c]; k < grid_start_[c + 1]; ++k) {
        Consider(static_cast<std::size_t>(grid_items_[static_cast<std::size_t>(k)]), px, py,
                 skip_component, &best);
      }
    } else {
      for (std::size_t d = 0; d < net_.num_domains(); ++d) {
        Consider(d, px, py, skip_component, &best);
      }
    }
    return best;
  }

 private:
  static constexpr int kScanQueries = 16;

  // Candidates are visited in ascending id in both modes and ties keep the first, so the grid and
  // the scan return the same domain.
  void Consider(std::size_t d, double px, double py, std::int32_t skip_component,
                std::int32_t* best) const {
    if (px < box_[4 * d] || py < box_[4 * d + 1] || px > box_[4 * d + 2] || py > box_[4 * d + 3]) {
      return;
    }
    const std::size_t first = static_cast<std::size_t>(
        net_.loop_particles[static_cast<std::size_t>(net_.loop_offsets[d])]);
    if (component_[first] == skip_component) return;
    if (!DomainContains(net_, packing_, d, px, py)) return;
    if (*best < 0 ||
        net_.apparent_volume[d] < net_.apparent_volume[static_cast<std::size_t>(*best)]) {
      *best = static_cast<std::int32_t>(d);
    }
  }

  std::int32_t CellX(double v) const {
    return std::clamp(static_cast<std::int32_t>((v - x0_) * inv_cell_), 0, nx_ - 1);
  }
  std::int32_t CellY(double v) const {
    return std::clamp(static_cast<std::int32_t>((v - y0_) * inv_cell_), 0, ny_ - 1);
  }
  std::size_t Cell(std::int32_t gx, std::int32_t gy) const {
    return static_cast<std::size_t>(gy) * static_cast<std::size_t>(nx_) +
           static_cast<std::size_t>(gx);
  }

  void BuildBoxes() {
    boxes_built_ = true;
    const std::size_t num_domains = net_.num_domains();
    const double* x = packing_.x.data();
    const double* y = packing_.y.data();
    box_.resize(4 * num_domains);
    x0_ = y0_ = INFINITY;
    x1_ = y1_ = -INFINITY;
    for (std::size_t d = 0; d < num_domains; ++d) {
      double bx0 = INFINITY, by0 = INFINITY, bx1 = -INFINITY, by1 = -INFINITY;
      for (std::int32_t k = net_.loop_offsets[d]; k < net_.loop_offsets[d + 1]; ++k) {
        const std::size_t p =
            static_cast<std::size_t>(net_.loop_particles[static_cast<std::size_t>(k)]);
        bx0 = std::min(bx0, x[p]);
        by0 = std::min(by0, y[p]);
        bx1 = std::max(bx1, x[p]);
        by1 = std::max(by1, y[p]);
      }
      box_[4 * d + 0] = bx0;
      box_[4 * d + 1] = by0;
      box_[4 * d + 2] = bx1;
      box_[4 * d + 3] = by1;
      x0_ = std::min(x0_, bx0);
      y0_ = std::min(y0_, by0);
      x1_ = std::max(x1_, bx1);
      y1_ = std::max(y1_, by1);
    }
  }

  void BuildGrid() {
    grid_built_ = true;
    const std::size_t num_domains = net_.num_domains();
    // About one cell per domain, never many more cells than domains.
    const double span_x = std::max(x1_ - x0_, 1e-300);
    const double span_y = std::max(y1_ - y0_, 1e-300);
    double cell = std::sqrt(span_x * span_y / static_cast<double>(num_domains));
    if (!(cell > 0.0)) cell = std::max(span_x, span_y);
    const double max_cells = 4.0 * static_cast<double>(num_domains) + 16.0;
    while ((span_x / cell + 1.0) * (span_y / cell + 1.0) > max_cells) cell *= 1.5;
    nx_ = static_cast<std::int32_t>(span_x / cell) + 1;
    ny_ = static_cast<std::int32_t>(span_y / cell) + 1;
    inv_cell_ = 1.0 / cell;
    const std::size_t num_cells = static_cast<std::size_t>(nx_) * static_cast<std::size_t>(ny_);
    grid_start_.assign(num_cells + 1, 0);
    // Two passes over the boxes: count per cell, then fill (counting sort, domain ids ascending).
    for (int pass = 0; pass < 2; ++pass) {
      for (std::size_t d = 0; d < num_domains; ++d) {
        const std::int32_t gx0 = CellX(box_[4 * d + 0]), gy0 = CellY(box_[4 * d + 1]);
        const std::int32_t gx1 = CellX(box_[4 * d + 2]), gy1 = CellY(box_[4 * d + 3]);
        for (std::int32_t gy = gy0; gy <= gy1; ++gy) {
          for (std::int32_t gx = gx0; gx <= gx1; ++gx) {
            const std::size_t c = Cell(gx, gy);
            if (pass == 0) {
              ++grid_start_[c + 1];
            } else {
              grid_items_[static_cast<std::size_t>(cursor_[c]++)] = static_cast<std::int32_t>(d);
            }
          }
        }
      }
      if (pass == 0) {
        for (std::size_t c = 0; c < num_cells; ++c) grid_start_[c + 1] += grid_start_[c];
        grid_items_.resize(static_cast<std::size_t>(grid_start_[num_cells]));
        cursor_.assign(grid_start_.begin(), grid_start_.end() - 1);
      }
    }
  }

  const DomainNetwork& net_;
  const Packing& packing_;
  const std::vector<std::int32_t>& component_;
  std::vector<std::int32_t>& grid_start_;
  std::vector<std::int32_t>& grid_items_;
  std::vector<double>& box_;
  std::vector<std::int32_t>& cursor_;
  bool boxes_built_ = false;
  bool grid_built_ = false;
  int queries_ = 0;
  double x0_ = 0.0, y0_ = 0.0, x1_ = 0.0, y1_ = 0.0, inv_cell_ = 1.0;
  std::int32_t nx_ = 1, ny_ = 1;
};

std::int32_t FindRoot(std::vector<std::int32_t>& parent, std::int32_t v) {
  while (parent[static_cast<std::size_t>(v)] != v) {
    // Path halving keeps the trees flat; the result does not depend on the order of unions.
    parent[static_cast<std::size_t>(v)] =
        parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(v)])];
    v = parent[static_cast<std::size_t>(v)];
  }
  return v;
}

constexpr std::int32_t kUnknownHost = -2;

}  // namespace

void DomainDetector::LocateRattlersAndIslands(const Packing& packing, const ContactList& contacts,
                                              DomainNetwork* network) {
  DomainNetwork& net = *network;
  const std::size_t n = packing.size();
  const std::size_t m = contacts.size();
  const double* x = packing.x.data();
  const double* y = packing.y.data();
  const double* r = packing.radius.data();
  const double* gap = contacts.gap.data();
  DomainLocator locator(net, packing, component_, &grid_start_, &grid_items_, &domain_box_,
                        &prune_queue_);

  // Islands first: a tree hanging into an island's outer face belongs to the island's host.
  const std::size_t num_components = component_outer_face_.size();
  if (num_components > 1) {
    for (std::size_t k = 0; k < num_components; ++k) {
      const std::size_t p = static_cast<std::size_t>(
          net.outer_particles[static_cast<std::size_t>(net.outer_offsets[k])]);
      net.outer_host_domain[k] = locator.Locate(x[p], y[p], static_cast<std::int32_t>(k));
    }
  }
  auto face_to_domain = [&](std::int32_t face) -> std::int32_t {
    const std::int32_t d = face_domain_[static_cast<std::size_t>(face)];
    return d >= 0 ? d : net.outer_host_domain[static_cast<std::size_t>(-d - 1)];
  };

  // Group pruned particles into trees (union-find over edges between two pruned particles).
  pruned_parent_.resize(n);
  for (std::size_t v = 0; v < n; ++v) pruned_parent_[v] = static_cast<std::int32_t>(v);
  for (std::size_t c = 0; c < m; ++c) {
    if (!(gap[c] <= max_gap_)) continue;
    const std::int32_t i = contacts.i[c], j = contacts.j[c];
    if (alive_[static_cast<std::size_t>(i)] || alive_[static_cast<std::size_t>(j)]) continue;
    const std::int32_t ri = FindRoot(pruned_parent_, i), rj = FindRoot(pruned_parent_, j);
    if (ri != rj) pruned_parent_[static_cast<std::size_t>(std::max(ri, rj))] = std::min(ri, rj);
  }
  // A tree's host, stored at its root: from its attaching edge when it has one.
  particle_host_.assign(n, kUnknownHost);
  for (std::size_t c = 0; c < m; ++c) {
    if (!(gap[c] <= max_gap_)) continue;
    const std::size_t i = static_cast<std::size_t>(contacts.i[c]);
    const std::size_t j = static_cast<std::size_t>(contacts.j[c]);
    if (alive_[i] == alive_[j]) continue;
    const std::size_t live = alive_[i] ? i : j;
    const std::size_t hanging = alive_[i] ? j : i;
    // The face on the left of slot s spans the CCW wedge from s to the next slot, so the edge
    // lies in the face of the last slot at or below its angle (cyclically).
    const double angle = std::atan2(y[hanging] - y[live], x[hanging] - x[live]);
    const std::int32_t b = vertex_offsets_[live];
    const std::int32_t e = vertex_offsets_[live + 1];
    std::int32_t slot = e - 1;
    for (std::int32_t s = b; s < e && slot_angle_[static_cast<std::size_t>(s)] <= angle; ++s) {
      slot = s;
    }
    const std::int32_t root = FindRoot(pruned_parent_, static_cast<std::int32_t>(hanging));
    particle_host_[static_cast<std::size_t>(root)] =
        face_to_domain(slot_face_[static_cast<std::size_t>(slot)]);
  }
  // Free rattlers and free trees: point location of the root's centre.
  for (std::size_t v = 0; v < n; ++v) {
    if (alive_[v] || pruned_parent_[v] != static_cast<std::int32_t>(v)) continue;
    if (particle_host_[v] == kUnknownHost) particle_host_[v] = locator.Locate(x[v], y[v], -1);
  }
  for (std::size_t v = 0; v < n; ++v) {
    if (!alive_[v]) {
      particle_host_[v] = particle_host_[static_cast<std::size_t>(
          FindRoot(pruned_parent_, static_cast<std::int32_t>(v)))];
    } else {
      particle_host_[v] = -1;
    }
  }

  // Subtract, now that every query has seen the unmodified areas.
  constexpr double kPi = std::numbers::pi;
  for (std::size_t p = 0; p < n; ++p) {
    const std::int32_t host = particle_host_[p];
    if (host >= 0) net.pore_volume[static_cast<std::size_t>(host)] -= kPi * r[p] * r[p];
  }
  // A pruned particle's overlap with a neighbour was removed twice (its disk and the neighbour's
  // disk or sector): give the lens back once, to the domain holding the pruned particle.
  for (std::size_t c = 0; c < m; ++c) {
    if (half_lens_[c] == 0.0) continue;
    const std::size_t i = static_cast<std::size_t>(contacts.i[c]);
    const std::size_t j = static_cast<std::size_t>(contacts.j[c]);
    if (alive_[i] && alive_[j]) continue;
    const std::int32_t host = !alive_[i] ? particle_host_[i] : particle_host_[j];
    if (host >= 0) net.pore_volume[static_cast<std::size_t>(host)] += 2.0 * half_lens_[c];
  }
  for (std::size_t k = 0; k < num_components; ++k) {
    const std::int32_t host = net.outer_host_domain[k];
    if (host < 0) continue;
    const std::size_t f = static_cast<std::size_t>(component_outer_face_[k]);
    // The island's solid outside its outer loop: its outer-face wedges, lenses counted once.
    const double solid_outside = face_sector_area_[f] - face_half_lens_[f];
    net.apparent_volume[static_cast<std::size_t>(host)] -= net.outer_area[k];
    net.pore_volume[static_cast<std::size_t>(host)] -= net.outer_area[k] + solid_outside;
  }
}

}  // namespace seep::core
