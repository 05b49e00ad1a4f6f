#include "codec/state_size_estimate.h"

#include <fmt/format.h>

#include <variant>

#include "seep/core/run/stepper.h"

namespace seep::service {
namespace {

// Upper bounds per particle of seep.v1.SimulationState (checkpoint.proto). A 2D contact graph is
// planar: at most 3 contacts (and so pipes and bonds) and 2 domains per particle; the DEM's
// neighbour list holds a few pairs more within its skin (4 per particle). Varint ids count 4 bytes.
constexpr std::uint64_t kDouble = 8;
constexpr std::uint64_t kId = 4;
// A frozen packing keeps only the pressure of each domain.
constexpr std::uint64_t kFrozenBytesPerParticle = 2 * kDouble;
// Moving particles: 12 doubles per particle (position, velocity, spin, force, torque, the
// positions of the last detection and of the last neighbour-list rebuild); per neighbour pair
// 3 ids and 4 doubles; per bond 2 ids, 4 doubles and 2 flags; per detected contact 2 ids and a
// gap; per pipe an aperture; per domain a pressure and two volumes.
constexpr std::uint64_t kMovingBytesPerParticle =
    12 * kDouble + 4 * (3 * kId + 4 * kDouble) + 3 * (2 * kId + 4 * kDouble + 2) +
    3 * (2 * kId + kDouble) + 3 * kDouble + 2 * 3 * kDouble;
// The series at its cap, with room for many more columns than any scene has.
constexpr std::uint64_t kMaxSeriesColumns = 32;

// Peak resident memory of a run per particle, measured by seep_stable_step_probe's last line on
// 300,000- and 1,200,000-disk lattices: a bonded DEM with flow (hydraulic_fracturing) 2,100 and
// 1,470 bytes, a steady solve (darcy_square_lattice) 1,070 and 1,000, an explicit transient
// (transient_1d) 560; bounds a quarter above the largest of each kind. Plus the process's own.
constexpr std::uint64_t kPeakBytesPerMovingParticle = 2600;
constexpr std::uint64_t kPeakBytesPerFrozenParticle = 1350;
constexpr std::uint64_t kPeakProcessBytes = std::uint64_t{96} << 20;

std::uint64_t ParticleCount(const core::PackingSource& source) {
  if (const auto* lattice = std::get_if<core::LatticePackingSpec>(&source)) {
    return std::uint64_t{lattice->columns} * lattice->rows;
  }
  if (const auto* random = std::get_if<core::RandomPackingSpec>(&source)) {
    return random->particle_count;
  }
  return std::get<core::ParticleListSpec>(source).x_m.size();
}

}  // namespace

StateSizeEstimate EstimateStateSize(const core::SceneSpec& scene) {
  StateSizeEstimate e;
  e.particles = ParticleCount(scene.packing.source);
  e.bytes_per_particle = core::FindEffect<core::ContactsEffectSpec>(scene) != nullptr
                             ? kMovingBytesPerParticle
                             : kFrozenBytesPerParticle;
  e.series_bytes = core::Stepper::kMaxSeriesRows * kMaxSeriesColumns * kDouble;
  e.total_bytes = e.particles * e.bytes_per_particle + e.series_bytes;
  return e;
}

PeakMemoryEstimate EstimatePeakMemory(const core::SceneSpec& scene) {
  PeakMemoryEstimate e;
  e.particles = ParticleCount(scene.packing.source);
  e.bytes_per_particle = core::FindEffect<core::ContactsEffectSpec>(scene) != nullptr
                             ? kPeakBytesPerMovingParticle
                             : kPeakBytesPerFrozenParticle;
  e.total_bytes = e.particles * e.bytes_per_particle + kPeakProcessBytes;
  return e;
}

core::Status CheckJobFitsMemory(const core::SceneSpec& scene, std::uint64_t limit_bytes) {
  const PeakMemoryEstimate e = EstimatePeakMemory(scene);
  if (limit_bytes == 0 || e.total_bytes <= limit_bytes) return core::Status::Ok();
  const bool moving = e.bytes_per_particle == kPeakBytesPerMovingParticle;
  return core::ResourceExhausted(fmt::format(
      "scene.packing: a run of this scene needs about {} MiB ({} particles x {} bytes{} + {} "
      "MiB for the process), more than the {} MiB a job may use (seepd --job-memory-limit-mb); "
      "use at most {} particles, or a seepd with more memory for each job",
      e.total_bytes >> 20, e.particles, e.bytes_per_particle,
      moving ? " for particles that move" : "", kPeakProcessBytes >> 20, limit_bytes >> 20,
      limit_bytes > kPeakProcessBytes ? (limit_bytes - kPeakProcessBytes) / e.bytes_per_particle
                                      : 0));
}

core::Status CheckStateFitsACheckpoint(const core::SceneSpec& scene) {
  const StateSizeEstimate e = EstimateStateSize(scene);
  if (e.total_bytes <= kMaxSerializedStateBytes) return core::Status::Ok();
  const bool moving = e.bytes_per_particle == kMovingBytesPerParticle;
  return core::InvalidArgument(fmt::format(
      "scene.packing: a checkpoint of this scene's state would take up to {} bytes ({} particles "
      "x {} bytes{} + {} for the time series), over the {} bytes protobuf can serialize in one "
      "message, so it could never be checkpointed; use at most {} particles",
      e.total_bytes, e.particles, e.bytes_per_particle, moving ? " for particles that move" : "",
      e.series_bytes, kMaxSerializedStateBytes,
      (kMaxSerializedStateBytes - e.series_bytes) / e.bytes_per_particle));
}

}  // namespace seep::service
