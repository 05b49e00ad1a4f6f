// FlowNetwork: the pipe network the pressure solvers work on, as plain structure-of-arrays.
//
// It knows nothing about particles or geometry: the scene glue maps detected domains and contacts
// onto these arrays (docs/physics.md §2.1). Units are SI per unit thickness.
//
// Domains (index d in [0, num_domains)):
//   apparent_volume[d]  V_d, m^2: polygon area through the particle centres.
//   pore_volume[d]      V_p, m^2: fluid area, V_p <= V_d.
//   pressure[d]         P, Pa: the state the solvers advance (gauge or absolute, caller's choice).
//   role[d]             kFree: pressure evolves; no flow across its non-pipe boundary.
//                       kFixedPressure: Dirichlet node, P is held at pressure[d].
//                       kSource: evolves like kFree and receives source_rate[d].
//   source_rate[d]      Q_src, m^2/s injected (negative = extraction); must be 0 unless kSource.
// Pipes (index p in [0, num_pipes)), one per flow-relevant contact separating two domains:
//   pipe_domain_a/b[p]  the two domain indices (distinct, in range).
//   pipe_length[p]      L, m (PFC: R_A + R_B).
//   pipe_aperture[p]    a, m (aperture_law.h).
//   pipe_conductance[p] C = a^3/(12 mu L), m^2/(Pa s); q = C (P_b - P_a) flows from b into a.
//   pipe_head_offset[p] rho_f g.(x_b - x_a), Pa: the hydrostatic pressure difference between the
//                       pipe's two ends when the fluid has weight (docs/guide/fluid-weight.md). The
//                       flow is then driven by the head, q = C (P_b - P_a - offset): fluid at rest
//                       under gravity has P_b - P_a = offset and moves nowhere. Empty (the default)
//                       = no fluid weight, and every solver runs exactly the weightless code.
//
// Boundary reservoirs are ordinary domains with role kFixedPressure; their volumes may be 0 (they
// store nothing and are never updated). A pipe from an interior domain to such a node carries the
// boundary flux. "No flow" is the default: a side without pipes is impermeable.
//
// Versions. Solvers cache symbolic analyses and factorizations. Every mutation goes through this
// class and draws a fresh stamp from a process-wide counter, so a stamp identifies one state of
// one network and never collides across networks:
//   topology_version():    domain/pipe counts, pipe endpoints, roles (matrix pattern);
//   coefficient_version(): conductances, volumes, source rates, head offsets (matrix values,
//                          right-hand sides, Δt_crit).
// Pressures are state, not coefficients: writing them bumps nothing. Spans returned by mutable_*()
// bump the version when obtained; do not keep them across solver calls.
//
// Ownership: FlowNetwork owns its arrays (value type, copyable). Solvers take it by reference per
// call and keep only caches keyed by the stamps above.
#pragma once

#include <atomic>
#include <cstdint>
#include <span>
#include <vector>

#include "seep/core/status.h"

namespace seep::core {

enum class DomainRole : std::uint8_t { kFree = 0, kFixedPressure = 1, kSource = 2 };

// The plain arrays a FlowNetwork is built from (and can be read back as).
struct FlowNetworkData {
  std::vector<double> apparent_volume;
  std::vector<double> pore_volume;
  std::vector<double> pressure;
  std::vector<DomainRole> role;
  std::vector<double> source_rate;

  std::vector<std::int32_t> pipe_domain_a;
  std::vector<std::int32_t> pipe_domain_b;
  std::vector<double> pipe_length;
  std::vector<double> pipe_aperture;
  std::vector<double> pipe_conductance;
  std::vector<double> pipe_head_offset;  // empty, or one per pipe
};

class FlowNetwork {
 public:
  // An empty network (0 domains, 0 pipes).
  FlowNetwork();

  // Validates every array (see Validate()) and takes ownership.
  static Result<FlowNetwork> Create(FlowNetworkData data);

  // Checks sizes, finiteness, signs and indices. Messages name the field and index, e.g.
  // "flow.network.pore_volume[3]: must be finite and >= 0 (got -1e-07)".
  static Status Validate(const FlowNetworkData& data);
  Status Validate() const;
  // The part of Validate that a coefficient edit can break (volumes, source rates, lengths,
  // apertures, conductances), for callers that validated the topology already. Sizes are
  // assumed to be right. Branch-free passes: cheap enough for every flow update.
  static Status ValidateCoefficients(const FlowNetworkData& data);
  // The same answer and message. Besides the volumes (written through spans), the values are
  // passed over only when they changed since they last passed, other than by a write that
  // checked what it wrote (SetApertures, SetPipeHeadOffsets, the role edits): the coupled loop
  // sets every aperture at each flow update, and the whole check cost 5 % of a one-thread step
  // of the settled bed.
  Status ValidateCoefficients() const;

  std::size_t num_domains() const { return data_.pressure.size(); }
  std::size_t num_pipes() const { return data_.pipe_conductance.size(); }
  const FlowNetworkData& data() const { return data_; }

  std::span<const double> apparent_volume() const { return data_.apparent_volume; }
  std::span<const double> pore_volume() const { return data_.pore_volume; }
  std::span<const double> pressure() const { return data_.pressure; }
  std::span<const DomainRole> role() const { return data_.role; }
  std::span<const double> source_rate() const { return data_.source_rate; }
  std::span<const std::int32_t> pipe_domain_a() const { return data_.pipe_domain_a; }
  std::span<const std::int32_t> pipe_domain_b() const { return data_.pipe_domain_b; }
  std::span<const double> pipe_length() const { return data_.pipe_length; }
  std::span<const double> pipe_aperture() const { return data_.pipe_aperture; }
  std::span<const double> pipe_conductance() const { return data_.pipe_conductance; }
  // Empty when the fluid has no weight.
  std::span<const double> pipe_head_offset() const { return data_.pipe_head_offset; }
  bool has_head_offsets() const { return !data_.pipe_head_offset.empty(); }

  // State: free to write, bumps nothing. Fixed-pressure nodes hold the value written here.
  std::span<double> mutable_pressure() { return data_.pressure; }

  // Coefficient edits (bump coefficient_version). Callers keep values valid; solvers re-validate
  // when the stamp changes.
  std::span<double> mutable_pipe_conductance();
  std::span<double> mutable_apparent_volume();
  std::span<double> mutable_pore_volume();

  // Sets the head offsets (one per pipe, finite; empty removes them) and bumps
  // coefficient_version. Callers refresh them when the domains move (network/fluid_weight.h).
  Status SetPipeHeadOffsets(std::span<const double> offset);

  // Sets apertures and recomputes C = a^3/(12 mu L) for every pipe.
  Status SetApertures(std::span<const double> aperture, double viscosity);

  // Role edits. Changing a role bumps topology_version (it changes the unknowns of the implicit
  // system); changing only a value bumps coefficient_version.
  Status SetFixedPressure(std::int32_t domain, double pressure);
  Status SetSource(std::int32_t domain, double rate);
  Status SetFree(std::int32_t domain);

  std::uint64_t topology_version() const { return topology_version_; }
  std::uint64_t coefficient_version() const { return coefficient_version_; }

 private:
  explicit FlowNetwork(FlowNetworkData data);
  Status CheckDomainIndex(std::int32_t domain, const char* what) const;
  void SetRole(std::int32_t domain, DomainRole role);

  // Draws a stamp for a write to the values other than the volumes; `checked` says the write
  // checked what it wrote.
  void StampCheckedValues(bool checked);

  FlowNetworkData data_;
  std::uint64_t topology_version_;
  std::uint64_t coefficient_version_;
  // A stamp that const methods record: a relaxed atomic (two threads validating one network
  // write the same value), copied as a value.
  class RecordedStamp {
   public:
    RecordedStamp() = default;
    RecordedStamp(const RecordedStamp& other) : value_(other.Get()) {}
    RecordedStamp& operator=(const RecordedStamp& other) {
      Set(other.Get());
      return *this;
    }
    std::uint64_t Get() const { return value_.load(std::memory_order_relaxed); }
    void Set(std::uint64_t value) const { value_.store(value, std::memory_order_relaxed); }

   private:
    mutable std::atomic<std::uint64_t> value_{0};
  };

  // The values other than the volumes (pipe lengths, apertures, conductances and head offsets;
  // source rates and roles) as of their last write, and the last such state known to pass
  // ValidateCoefficients (0: none).
  std::uint64_t values_stamp_;
  RecordedStamp values_passed_;
};

// A fresh, never reused stamp (thread-safe). Exposed for solvers and tests.
std::uint64_t NextFlowVersionStamp();

}  // namespace seep::core
