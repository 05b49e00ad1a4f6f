// V_d and V_p of detected domains recomputed from moved particles (see domain_volume_update.h).
// The per-loop arithmetic follows DomainDetector::TraceFaces term by term (same shoelace origin,
// same summation order, same lens formula), so that a bound network reproduces the detector's
// volumes to round-off.
#include "seep/core/coupling/domain_volume_update.h"

#include <cmath>
#include <numbers>
#include <string>

#include "seep/core/geometry/disk_overlap.h"

namespace seep::core {
namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

struct LoopMeasure {
  double signed_area = 0.0;  // shoelace over the centres (> 0 for a CCW loop)
  double sector = 0.0;       // sum of (theta/2) R^2 over the face's wedges
  double half_lens = 0.0;    // sum of half the overlap lens of each loop contact
};

// Half the lens of an overlapping pair, computed as the detector does from the contact gap.
double HalfLens(const ParticleView& p, std::int32_t a, std::int32_t b) {
  const std::size_t lo = static_cast<std::size_t>(a < b ? a : b);
  const std::size_t hi = static_cast<std::size_t>(a < b ? b : a);
  const double dx = p.x[hi] - p.x[lo];
  const double dy = p.y[hi] - p.y[lo];
  const double d2 = dx * dx + dy * dy;
  const double sum = p.radius[lo] + p.radius[hi];
  if (!(d2 < sum * sum)) return 0.0;  // apart or touching: no square root on the common path
  const double gap = std::sqrt(d2) - p.radius[lo] - p.radius[hi];
  if (!(gap < 0.0)) return 0.0;
  return 0.5 * LensArea(p.radius[lo], p.radius[hi], p.radius[lo] + p.radius[hi] + gap);
}

LoopMeasure MeasureLoop(const ParticleView& p, const std::int32_t* loop, std::size_t begin,
                        std::size_t end) {
  LoopMeasure m;
  if (end <= begin) return m;
  const std::size_t count = end - begin;
  const double* x = p.x.data();
  const double* y = p.y.data();
  const double* r = p.radius.data();
  const std::size_t v0 = static_cast<std::size_t>(loop[begin]);
  const double x0 = x[v0];
  const double y0 = y[v0];
  double twice_area = 0.0;
  for (std::size_t k = 0; k < count; ++k) {
    // Cyclic successors without a division per entry.
    const std::size_t k1 = k + 1 < count ? k + 1 : k + 1 - count;
    const std::size_t k2 = k1 + 1 < count ? k1 + 1 : k1 + 1 - count;
    const std::size_t v = static_cast<std::size_t>(loop[begin + k]);
    const std::size_t w = static_cast<std::size_t>(loop[begin + k1]);
    const std::size_t u = static_cast<std::size_t>(loop[begin + k2]);
    // Shoelace relative to the first vertex, as the detector, to keep precision far from 0.
    const double ax = x[v] - x0, ay = y[v] - y0;
    const double bx = x[w] - x0, by = y[w] - y0;
    twice_area += ax * by - bx * ay;
    m.half_lens += HalfLens(p, static_cast<std::int32_t>(v), static_cast<std::int32_t>(w));
    // Face angle at w: the CCW sweep from the outgoing edge w->u to the incoming edge's reverse
    // w->v, in [0, 2 pi), which handles reflex vertices.
    // One atan2 of (cross, dot) instead of the detector's difference of two edge angles: the
    // same angle to round-off at half the cost.
    const double in_x = x[v] - x[w], in_y = y[v] - y[w];
    const double out_x = x[u] - x[w], out_y = y[u] - y[w];
    double theta = std::atan2(out_x * in_y - out_y * in_x, out_x * in_x + out_y * in_y);
    if (theta < 0.0) theta += kTwoPi;
    m.sector += 0.5 * theta * r[w] * r[w];
  }
  m.signed_area = 0.5 * twice_area;
  return m;
}

Status CheckIds(std::span<const std::int32_t> ids, std::size_t n, const char* field) {
  for (std::size_t k = 0; k < ids.size(); ++k) {
    if (ids[k] < 0 || static_cast<std::size_t>(ids[k]) >= n) {
      return InvalidArgument(std::string("coupling.domain_volume.network.") + field + "[" +
                             std::to_string(k) + "]: particle id " + std::to_string(ids[k]) +
                             " is not in [0, " + std::to_string(n) + ")");
    }
  }
  return Status::Ok();
}

}  // namespace

Status DomainVolumeUpdater::Check(const ParticleView& particles, const DomainNetwork& network,
                                  std::size_t volumes) const {
  SEEP_RETURN_IF_ERROR(CheckParticleView(particles, "coupling.domain_volume.particles"));
  const std::size_t num_domains = network.num_domains();
  if (volumes != num_domains) {
    return InvalidArgument("coupling.domain_volume: volume arrays have " + std::to_string(volumes) +
                           " entries, expected " + std::to_string(num_domains) +
                           " (one per domain)");
  }
  if (network.loop_offsets.size() != num_domains + 1 ||
      static_cast<std::size_t>(network.loop_offsets.back()) != network.loop_particles.size() ||
      network.outer_offsets.size() != network.num_outer_faces() + 1 ||
      static_cast<std::size_t>(network.outer_offsets.back()) != network.outer_particles.size() ||
      network.outer_host_domain.size() != network.num_outer_faces()) {
    return InvalidArgument("coupling.domain_volume.network: loop offsets do not match the loops");
  }
  SEEP_RETURN_IF_ERROR(CheckIds(network.loop_particles, particles.size(), "loop_particles"));
  SEEP_RETURN_IF_ERROR(CheckIds(network.outer_particles, particles.size(), "outer_particles"));
  for (const std::int32_t host : network.outer_host_domain) {
    if (host >= static_cast<std::int32_t>(num_domains)) {
      return InvalidArgument("coupling.domain_volume.network.outer_host_domain: domain " +
                             std::to_string(host) + " out of range");
    }
  }
  return Status::Ok();
}

void DomainVolumeUpdater::ComputeGeometric(const ParticleView& particles,
                                           const DomainNetwork& network,
                                           std::span<double> apparent_volume,
                                           std::span<double> pore_volume) const {
  const std::int32_t* loops = network.loop_particles.data();
  for (std::size_t d = 0; d < network.num_domains(); ++d) {
    const LoopMeasure m =
        MeasureLoop(particles, loops, static_cast<std::size_t>(network.loop_offsets[d]),
                    static_cast<std::size_t>(network.loop_offsets[d + 1]));
    apparent_volume[d] = m.signed_area;
    pore_volume[d] = m.signed_area - m.sector + m.half_lens;
  }
  // Islands: the host loses the area inside the island's outer walk (traced clockwise, so its
  // signed area is negative) and, from V_p, the island's solid outside that walk.
  const std::int32_t* outer = network.outer_particles.data();
  for (std::size_t k = 0; k < network.num_outer_faces(); ++k) {
    const std::int32_t host = network.outer_host_domain[k];
    if (host < 0) continue;
    const LoopMeasure m =
        MeasureLoop(particles, outer, static_cast<std::size_t>(network.outer_offsets[k]),
                    static_cast<std::size_t>(network.outer_offsets[k + 1]));
    const double inside = -m.signed_area;
    apparent_volume[static_cast<std::size_t>(host)] -= inside;
    pore_volume[static_cast<std::size_t>(host)] -= inside + (m.sector - m.half_lens);
  }
}

Status DomainVolumeUpdater::Bind(const ParticleView& particles, const DomainNetwork& network) {
  const std::size_t num_domains = network.num_domains();
  if (network.pore_volume.size() != num_domains) {
    return InvalidArgument("coupling.domain_volume.network.pore_volume: has " +
                           std::to_string(network.pore_volume.size()) + " entries, expected " +
                           std::to_string(num_domains));
  }
  SEEP_RETURN_IF_ERROR(Check(particles, network, num_domains));
  std::vector<double> apparent(num_domains);
  rattler_correction_.assign(num_domains, 0.0);
  ComputeGeometric(particles, network, apparent, rattler_correction_);
  for (std::size_t d = 0; d < num_domains; ++d) {
    rattler_correction_[d] = network.pore_volume[d] - rattler_correction_[d];
  }
  return Status::Ok();
}

Status DomainVolumeUpdater::Compute(const ParticleView& particles, const DomainNetwork& network,
                                    std::span<double> apparent_volume,
                                    std::span<double> pore_volume) const {
  if (network.num_domains() != rattler_correction_.size()) {
    return FailedPrecondition(
        "coupling.domain_volume: the network has " + std::to_string(network.num_domains()) +
        " domains but the updater was bound to one with " +
        std::to_string(rattler_correction_.size()) + " (call Bind after every detection)");
  }
  if (pore_volume.size() != apparent_volume.size()) {
    return InvalidArgument(
        "coupling.domain_volume: apparent_volume and pore_volume differ in size");
  }
  SEEP_RETURN_IF_ERROR(Check(particles, network, apparent_volume.size()));
  ComputeGeometric(particles, network, apparent_volume, pore_volume);
  for (std::size_t d = 0; d < pore_volume.size(); ++d) pore_volume[d] += rattler_correction_[d];
  return Status::Ok();
}

Status ComputeVolumeChange(std::span<const double> before, std::span<const double> after,
                           std::span<double> change) {
  if (after.size() != before.size() || change.size() != before.size()) {
    return InvalidArgument(
        "coupling.domain_volume.change: before, after and change differ in size (" +
        std::to_string(before.size()) + ", " + std::to_string(after.size()) + ", " +
        std::to_string(change.size()) + ")");
  }
  for (std::size_t d = 0; d < before.size(); ++d) change[d] = after[d] - before[d];
  return Status::Ok();
}

}  // namespace seep::core
