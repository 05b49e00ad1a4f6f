#include "seep/core/flow/explicit_solver.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>

#include "../parallel_threshold.h"
#include "seep/core/flow/pipe_head.h"
#include "seep/core/flow/storage_volume.h"
#include "seep/core/log.h"
#include "step_input.h"

namespace seep::core {

namespace {

// The most sub-steps one ExplicitSolver::Advance takes (see there).
constexpr double kMaxSubSteps = 1e6;

// q = C (P_b - P_a) flows from b into a. Storage order, so a locality-ordered network streams.
void AccumulatePipeFlows(std::size_t num_pipes, const std::int32_t* __restrict a,
                         const std::int32_t* __restrict b, const double* __restrict c,
                         const double* __restrict pressure, double* __restrict inflow) {
  for (std::size_t p = 0; p < num_pipes; ++p) {
    const std::int32_t i = a[p];
    const std::int32_t j = b[p];
    const double q = c[p] * (pressure[j] - pressure[i]);
    inflow[i] += q;
    inflow[j] -= q;
  }
}

// The pipes of a share of the domains (IndexPipesByShare: `count` pipes, in pipe order, with the
// ends the share adds to, a pipe's end outside the share being the share's sink slot) add to the
// share's domains: each gets the terms of AccumulatePipeFlows in the same order. Without a test
// per end: GCC's code for `if (end in share) add` took longer per share on two threads (2.3 ns a
// pipe) than the whole pass on one (1 ns a pipe).
void AddShareFlows(const std::int32_t* __restrict pipes, std::int32_t count,
                   const std::int32_t* __restrict end_a, const std::int32_t* __restrict end_b,
                   const std::int32_t* __restrict a, const std::int32_t* __restrict b,
                   const double* __restrict c, const double* __restrict pressure,
                   double* __restrict inflow) {
  for (std::int32_t k = 0; k < count; ++k) {
    const std::int32_t p = pipes[k];
    const double q = c[p] * (pressure[b[p]] - pressure[a[p]]);
    inflow[end_a[k]] += q;
    inflow[end_b[k]] -= q;
  }
}

// The same for the sums of the conductances per domain.
void AddShareConductances(const std::int32_t* __restrict pipes, std::int32_t count,
                          const std::int32_t* __restrict end_a,
                          const std::int32_t* __restrict end_b, const double* __restrict c,
                          double* __restrict sum_c) {
  for (std::int32_t k = 0; k < count; ++k) {
    const double cp = c[pipes[k]];
    sum_c[end_a[k]] += cp;
    sum_c[end_b[k]] += cp;
  }
}

// The plain update: P += gain * inflow, accumulator reset. Fixed domains have gain 0.
void UpdateDomains(std::size_t n, const double* __restrict gain, double* __restrict inflow,
                   double* __restrict pressure) {
  for (std::size_t i = 0; i < n; ++i) {
    pressure[i] += gain[i] * inflow[i];
    inflow[i] = 0.0;
  }
}

// With a deformation term: P += gain * (inflow - dV/dt).
void UpdateDomainsWithVolumeChange(std::size_t n, const double* __restrict gain,
                                   const double* __restrict volume_change, double inv_dt,
                                   double* __restrict inflow, double* __restrict pressure) {
  for (std::size_t i = 0; i < n; ++i) {
    pressure[i] += gain[i] * (inflow[i] - volume_change[i] * inv_dt);
    inflow[i] = 0.0;
  }
}

struct Budget {
  double boundary_inflow = 0.0;
  double boundary_magnitude = 0.0;
  double volume_change = 0.0;
  double volume_magnitude = 0.0;
  double stored_change = 0.0;
  double stored_magnitude = 0.0;
  double stored_level = 0.0;  // sum V_s |P| / K_f after the step
  double min_pressure = std::numeric_limits<double>::infinity();
  double max_pressure = -std::numeric_limits<double>::infinity();
};

// One domain's part of the budget, after its update: a fixed-pressure node's inflow is what
// leaves the network into it; another domain stored `stored` = V_s dP / K_f. Every budget pass
// adds through here, so their sums are the same additions in the same (domain) order.
inline void AddToBudget(Budget& out, double capacity, double inflow, double stored, double dv,
                        double new_p) {
  if (capacity == 0.0) {
    out.boundary_inflow -= inflow;
    out.boundary_magnitude += std::abs(inflow);
  } else {
    out.stored_change += stored;
    out.stored_magnitude += std::abs(stored);
    out.stored_level += capacity * std::abs(new_p);
    out.volume_change += dv;
    out.volume_magnitude += std::abs(dv);
  }
  out.min_pressure = std::min(out.min_pressure, new_p);
  out.max_pressure = std::max(out.max_pressure, new_p);
}

// The update of domain i (not fixed): its new pressure, and the fluid it stored.
struct DomainUpdate {
  double new_p, stored;
};
inline DomainUpdate UpdateDomain(std::size_t i, const double* gain, const double* capacity,
                                 double dv, double inv_dt, const double* inflow, double* pressure) {
  const double old_p = pressure[i];
  const double new_p = old_p + gain[i] * (inflow[i] - dv * inv_dt);
  pressure[i] = new_p;
  return {new_p, capacity[i] * (new_p - old_p)};
}

// The update with the fluid budget of the step, in domain order (deterministic sums).
// node_outflow (may be null): per node, dt x what left the network into it is added.
Budget UpdateDomainsWithBudget(std::size_t n, const double* gain, const double* capacity,
                               const double* volume_change, double inv_dt, double* inflow,
                               double* pressure, double* node_outflow) {
  Budget out;
  for (std::size_t i = 0; i < n; ++i) {
    const double dv = volume_change != nullptr ? volume_change[i] : 0.0;
    DomainUpdate u{pressure[i], 0.0};
    if (capacity[i] == 0.0) {
      if (node_outflow != nullptr) node_outflow[i] += inflow[i] / inv_dt;
    } else {
      u = UpdateDomain(i, gain, capacity, dv, inv_dt, inflow, pressure);
    }
    AddToBudget(out, capacity[i], inflow[i], u.stored, dv, u.new_p);
    inflow[i] = 0.0;
  }
  return out;
}

// UpdateDomainsWithBudget split for threads. The update of domains [lo, hi) (per domain: any
// share may run on any thread), keeping each domain's stored change, and its inflow for the sums:
void UpdateShareKeepingBudgetTerms(std::size_t lo, std::size_t hi, const double* gain,
                                   const double* capacity, const double* volume_change,
                                   double inv_dt, const double* inflow, double* pressure,
                                   double* stored, double* node_outflow) {
  for (std::size_t i = lo; i < hi; ++i) {
    if (capacity[i] == 0.0) {
      if (node_outflow != nullptr) node_outflow[i] += inflow[i] / inv_dt;
    } else {
      const double dv = volume_change != nullptr ? volume_change[i] : 0.0;
      stored[i] = UpdateDomain(i, gain, capacity, dv, inv_dt, inflow, pressure).stored;
    }
  }
}

// ...then the sums of domains [lo, hi), continuing `out` (so the shares summed in turn make
// the one-pass sums, the same bits), and the accumulator reset.
void SumBudgetTerms(std::size_t lo, std::size_t hi, const double* capacity,
                    const double* volume_change, double* inflow, const double* pressure,
                    const double* stored, Budget& out) {
  // Summed in a local (registers: `out` may alias the arrays), the same additions.
  Budget sums = out;
  for (std::size_t i = lo; i < hi; ++i) {
    const double dv = volume_change != nullptr ? volume_change[i] : 0.0;
    AddToBudget(sums, capacity[i], inflow[i], capacity[i] == 0.0 ? 0.0 : stored[i], dv,
                pressure[i]);
    inflow[i] = 0.0;
  }
  out = sums;
}

}  // namespace

Result<ExplicitSolver> ExplicitSolver::Create(const ExplicitSolverOptions& options) {
  if (!(std::isfinite(options.bulk_modulus) && options.bulk_modulus > 0.0)) {
    return InvalidArgument("flow.explicit.bulk_modulus: must be finite and > 0 (got " +
                           flow_internal::FormatNumber(options.bulk_modulus) + ")");
  }
  SEEP_RETURN_IF_ERROR(ValidateStorageModel(options.storage));
  if (!(options.safety_factor > 0.0 && options.safety_factor <= 1.0)) {
    return InvalidArgument("flow.explicit.safety_factor: must be in (0, 1] (got " +
                           flow_internal::FormatNumber(options.safety_factor) + ")");
  }
  return ExplicitSolver(options);
}

Status ExplicitSolver::Prepare(const FlowNetwork& network) {
  if (network.topology_version() == topology_stamp_ &&
      network.coefficient_version() == coefficient_stamp_) {
    return Status::Ok();
  }
  // A new topology is validated whole; a coefficient edit on a known topology (the coupled loop
  // moves volumes and apertures at every flow update) re-checks the values only. Both check the
  // same values (Validate ends with ValidateCoefficients) and share RefreshCoefficients, so a
  // long-lived solver accepts, refuses and computes exactly what a fresh one (a resumed run's)
  // would.
  const bool known_topology = network.topology_version() == topology_stamp_;
  // Until the refresh succeeds the stamps are 0 (never issued): a half-refreshed cache is then
  // trusted by no network, not even a copy taken before the edit.
  topology_stamp_ = 0;
  coefficient_stamp_ = 0;
  SEEP_RETURN_IF_ERROR(known_topology ? network.ValidateCoefficients() : network.Validate());
  if (!known_topology) owner_threads_ = 0;  // the share lists are per topology
  SEEP_RETURN_IF_ERROR(RefreshCoefficients(network));
  topology_stamp_ = network.topology_version();
  coefficient_stamp_ = network.coefficient_version();
  return Status::Ok();
}

namespace {

// Thread t's share of n items: a contiguous block, the same for every pass that uses it.
std::ptrdiff_t ShareBegin(std::ptrdiff_t n, int t, int threads) { return n * t / threads; }

// The size of a per-domain accumulator the shares add to: the domains, and on shares a sink slot
// per share past them (IndexPipesByShare).
std::size_t WithSinkSlots(std::size_t n, int threads) {
  return n + (threads > 1 ? static_cast<std::size_t>(threads) : 0);
}

// Capacities V_s / K_f and rates K_f / V_s (as 1 / capacity) of domains [lo, hi), StorageVolumeOf
// term by term, 0 for fixed domains and non-positive volumes: branch-free so that the divisions,
// which bounded the refresh, vectorise (GCC if-converts the selects because the core is built
// with -fno-trapping-math, core/CMakeLists.txt).
void FillCapacitiesAndRates(std::ptrdiff_t lo, std::ptrdiff_t hi, const double* __restrict volume,
                            const DomainRole* __restrict role, double factor, double floor,
                            double bulk, double* __restrict capacity, double* __restrict rate) {
#pragma omp simd
  for (std::ptrdiff_t d = lo; d < hi; ++d) {
    const double vs = StorageVolumeFrom(volume[d], factor, floor);
    const bool live = (role[d] != DomainRole::kFixedPressure) & (vs > 0.0);
    const double cap = vs / bulk;
    const double inverse = 1.0 / cap;
    capacity[d] = live ? cap : 0.0;
    rate[d] = live ? inverse : 0.0;
  }
}

// What SweepOnShares reads and writes (the solver's arrays for the network).
struct ShareSweep {
  std::ptrdiff_t domains = 0;
  int threads = 1;
  const std::int32_t* a = nullptr;  // pipe ends
  const std::int32_t* b = nullptr;
  const double* c = nullptr;                  // conductances
  const std::int32_t* owner_start = nullptr;  // IndexPipesByShare's lists for `threads`
  const std::int32_t* owner_pipes = nullptr;
  const std::int32_t* owner_end_a = nullptr;
  const std::int32_t* owner_end_b = nullptr;
  const double* rate = nullptr;
  const double* capacity = nullptr;
  const double* volume_change = nullptr;  // or null
  double* gain = nullptr;
  double* inflow = nullptr;
  double* stored = nullptr;  // scratch, one per domain, with a budget
  double* pressure = nullptr;
  double* node_outflow = nullptr;  // or null
  double step = 0.0;
  double inv_dt = 0.0;
  bool new_gain = false;  // gain = step x rate first
};

// The pipe pass and the update of Step on `threads` shares of the domains, bit-identical to one
// thread's: each share passes over the pipes touching it in pipe order and adds to its own
// domains only, so every domain gets the terms of AccumulatePipeFlows in the same order. With a
// budget, each share's sums continue the previous share's in share order (an ordered loop): the
// one-pass sums, read by the thread that wrote the share (a serial pass over what another core
// had just written cost more than the whole one-thread update).
void SweepOnShares(const ShareSweep& s, Budget* budget) {
  const std::ptrdiff_t n = s.domains;
  const int threads = s.threads;
  internal::RunOnTeam(threads, [&](const internal::TeamMember& member) {
    // A team smaller than asked for takes the shares in turn (as RefreshCoefficients).
    const int team = member.size();
    for (int t = member.index(); t < threads; t += team) {
      const std::ptrdiff_t lo = ShareBegin(n, t, threads);
      const std::ptrdiff_t hi = ShareBegin(n, t + 1, threads);
      if (s.new_gain) {
        for (std::ptrdiff_t d = lo; d < hi; ++d) s.gain[d] = s.step * s.rate[d];
      }
      const std::int32_t first = s.owner_start[t];
      AddShareFlows(s.owner_pipes + first, s.owner_start[t + 1] - first, s.owner_end_a + first,
                    s.owner_end_b + first, s.a, s.b, s.c, s.pressure, s.inflow);
    }
    // Every share has read the pressures it needs before any changes.
    member.Barrier();
    if (budget != nullptr) {
      for (int t = member.index(); t < threads; t += team) {
        const auto lo = static_cast<std::size_t>(ShareBegin(n, t, threads));
        const auto hi = static_cast<std::size_t>(ShareBegin(n, t + 1, threads));
        UpdateShareKeepingBudgetTerms(lo, hi, s.gain, s.capacity, s.volume_change, s.inv_dt,
                                      s.inflow, s.pressure, s.stored, s.node_outflow);
      }
      // The sums in share order: share t's member adds once share t - 1's has.
      for (int t = 0; t < threads; ++t) {
        member.Barrier();
        if (t % team != member.index()) continue;
        const auto lo = static_cast<std::size_t>(ShareBegin(n, t, threads));
        const auto hi = static_cast<std::size_t>(ShareBegin(n, t + 1, threads));
        SumBudgetTerms(lo, hi, s.capacity, s.volume_change, s.inflow, s.pressure, s.stored,
                       *budget);
      }
    } else {
      for (int t = member.index(); t < threads; t += team) {
        const std::ptrdiff_t lo = ShareBegin(n, t, threads);
        const auto count = static_cast<std::size_t>(ShareBegin(n, t + 1, threads) - lo);
        if (s.volume_change == nullptr) {
          UpdateDomains(count, s.gain + lo, s.inflow + lo, s.pressure + lo);
        } else {
          UpdateDomainsWithVolumeChange(count, s.gain + lo, s.volume_change + lo, s.inv_dt,
                                        s.inflow + lo, s.pressure + lo);
        }
      }
    }
  });
}

}  // namespace

void ExplicitSolver::IndexPipesByShare(const FlowNetwork& network, int threads) {
  const auto n = static_cast<std::ptrdiff_t>(network.num_domains());
  const auto a = network.pipe_domain_a();
  const auto b = network.pipe_domain_b();
  owner_start_.assign(1, 0);
  owner_pipes_.clear();
  owner_end_a_.clear();
  owner_end_b_.clear();
  for (int t = 0; t < threads; ++t) {
    const std::ptrdiff_t lo = ShareBegin(n, t, threads);
    const std::ptrdiff_t hi = ShareBegin(n, t + 1, threads);
    const auto sink = static_cast<std::int32_t>(n + t);
    for (std::size_t p = 0; p < a.size(); ++p) {
      const bool has_a = a[p] >= lo && a[p] < hi;
      const bool has_b = b[p] >= lo && b[p] < hi;
      if (has_a || has_b) {
        owner_pipes_.push_back(static_cast<std::int32_t>(p));
        owner_end_a_.push_back(has_a ? a[p] : sink);
        owner_end_b_.push_back(has_b ? b[p] : sink);
      }
    }
    owner_start_.push_back(static_cast<std::int32_t>(owner_pipes_.size()));
  }
  owner_threads_ = threads;
}

Status ExplicitSolver::RefreshCoefficients(const FlowNetwork& network) {
  const std::size_t n = network.num_domains();
  const double* __restrict c = network.pipe_conductance().data();
  const DomainRole* __restrict role = network.role().data();
  const double* __restrict volume = options_.storage.volume == StorageVolume::kPore
                                        ? network.pore_volume().data()
                                        : network.apparent_volume().data();
  const double factor = options_.storage.factor;
  const double floor = options_.storage.floor_m2;
  const double bulk = options_.bulk_modulus;
  const auto domains = static_cast<std::ptrdiff_t>(n);
  const int threads = domains >= internal::MinParallelItems() ? internal::CoreThreads() : 1;
  sum_c_.resize(WithSinkSlots(n, threads));
  capacity_.resize(n);
  rate_.resize(n);
  double* __restrict sum_c = sum_c_.data();
  double* __restrict capacity = capacity_.data();
  double* __restrict rate = rate_.data();
  // Per domain only (the minimum step aside): threads change no bit. Each thread keeps the
  // first domain of its share with the least dt_i, and the shares are taken in order, so the
  // limit is the lowest-index domain on ties as in one pass.
  if (threads > 1 && owner_threads_ != threads) IndexPipesByShare(network, threads);
  const std::int32_t* __restrict owner_start = owner_start_.data();
  const std::int32_t* __restrict owner_pipes = owner_pipes_.data();
  share_limit_.assign(static_cast<std::size_t>(threads), CriticalTimeStep{});
  bool any_non_positive = false;
  // The accumulator starts at zero (the sources are set below), and the step's gains are
  // computed by the first Step (gain_dt_ = -1).
  inflow_.resize(WithSinkSlots(n, threads));
  gain_.resize(n);
  gain_dt_ = -1.0;
  double* __restrict inflow = inflow_.data();
  const double* __restrict q_src = network.source_rate().data();
  double sources = 0.0;  // a count, exact in any order
  // The shares first, first + stride, ... of the pass; on a team, its flag and count are each
  // member's own (reduced after).
  const auto refresh_shares = [&](int first, int stride, bool& non_positive_seen,
                                  double& source_count) {
    // sum C per domain, pipe by pipe in pipe order. One thread passes over all pipes; on several,
    // each share of the domains is passed over the pipes touching it (IndexPipesByShare), adding
    // to its own domains only, so every domain gets the same terms in the same order. A team
    // smaller than asked for (core_team.h: no more threads could be made) takes the shares in
    // turn.
    for (int t = first; t < threads; t += stride) {
      const std::ptrdiff_t lo = ShareBegin(domains, t, threads);
      const std::ptrdiff_t hi = ShareBegin(domains, t + 1, threads);
      const std::int32_t* __restrict a = network.pipe_domain_a().data();
      const std::int32_t* __restrict b = network.pipe_domain_b().data();
      std::fill(sum_c + lo, sum_c + hi, 0.0);
      if (threads == 1) {
        for (std::size_t p = 0; p < network.num_pipes(); ++p) {
          sum_c[a[p]] += c[p];
          sum_c[b[p]] += c[p];
        }
      } else {
        AddShareConductances(owner_pipes + owner_start[t], owner_start[t + 1] - owner_start[t],
                             owner_end_a_.data() + owner_start[t],
                             owner_end_b_.data() + owner_start[t], c, sum_c);
      }
      FillCapacitiesAndRates(lo, hi, volume, role, factor, floor, bulk, capacity, rate);
      // dt_i = V_s / (K_f sum C), as ComputeCriticalTimeStep (lowest index on ties). A domain
      // whose V_s is at least (1 + 2^-50) x least x K_f sum C cannot round below the least, so
      // a multiplication rules out nearly every domain before its division.
      CriticalTimeStep least;
      for (std::ptrdiff_t d = lo; d < hi; ++d) {
        if (role[d] == DomainRole::kFixedPressure) continue;
        const double sum = sum_c[d];
        const double vs = StorageVolumeFrom(volume[d], factor, floor);
        if (!(vs > 0.0)) {
          non_positive_seen = true;
          continue;
        }
        if (!(sum > 0.0)) continue;  // dt_i = infinity
        const double den = bulk * sum;
        const double bound = least.dt_crit * den * (1.0 + 0x1p-50);
        if (bound >= std::numeric_limits<double>::min() && vs >= bound) continue;
        const double dt = vs / den;
        if (dt < least.dt_crit) {
          least.dt_crit = dt;
          least.limiting_domain = static_cast<std::int32_t>(d);
          least.limiting_storage_volume = vs;
          least.limiting_conductance_sum = sum;
        }
      }
      share_limit_[static_cast<std::size_t>(t)] = least;
      // The sources: most scenes have none, and a branch-free count says so without the scan.
      std::fill(inflow + lo, inflow + hi, 0.0);
      double share_sources = 0.0;
#pragma omp simd reduction(+ : share_sources)
      for (std::ptrdiff_t d = lo; d < hi; ++d) {
        share_sources += ((role[d] == DomainRole::kSource) & (q_src[d] != 0.0)) ? 1.0 : 0.0;
      }
      source_count += share_sources;
    }
  };
  if (threads > 1) {
    std::atomic<bool> team_non_positive{false};
    std::atomic<double> team_sources{0.0};
    internal::RunOnTeam(threads, [&](const internal::TeamMember& member) {
      bool non_positive = false;
      double source_count = 0.0;
      refresh_shares(member.index(), member.size(), non_positive, source_count);
      if (non_positive) team_non_positive.store(true, std::memory_order_relaxed);
      team_sources.fetch_add(source_count, std::memory_order_relaxed);
    });
    any_non_positive = team_non_positive.load(std::memory_order_relaxed);
    sources = team_sources.load(std::memory_order_relaxed);
  } else {
    refresh_shares(0, 1, any_non_positive, sources);
  }
  if (any_non_positive) {
    for (std::size_t d = 0; d < n; ++d) {
      if (role[d] == DomainRole::kFixedPressure) continue;
      const double vs = StorageVolumeOf(network, options_.storage, d);
      if (!(vs > 0.0)) return NonPositiveStorageVolume(options_.storage, d, vs);
    }
  }
  limit_ = CriticalTimeStep{};
  for (const CriticalTimeStep& least : share_limit_) {
    if (least.dt_crit < limit_.dt_crit) limit_ = least;
  }
  sources_.clear();
  for (std::size_t d = 0; sources > 0.0 && d < n; ++d) {
    if (role[d] == DomainRole::kSource && q_src[d] != 0.0) {
      sources_.push_back(static_cast<std::int32_t>(d));
      inflow_[d] = q_src[d];
    }
  }
  // With fluid weight the accumulator starts every step at the head inflow (pipe_head.h) plus
  // the sources; without, at the sources alone (the sweep itself is the same either way).
  base_inflow_.clear();
  if (network.has_head_offsets()) {
    ComputeHeadInflow(network, &base_inflow_);
    for (const std::int32_t s : sources_) base_inflow_[s] += q_src[s];
    std::copy(base_inflow_.begin(), base_inflow_.end(), inflow_.begin());
  }
  return Status::Ok();
}

Result<CriticalTimeStep> ExplicitSolver::CriticalStep(const FlowNetwork& network) {
  SEEP_RETURN_IF_ERROR(Prepare(network));
  return limit_;
}

Result<FlowStepReport> ExplicitSolver::Step(FlowNetwork& network, double dt,
                                            std::span<const double> volume_change,
                                            FluidTally* tally) {
  const std::size_t n = network.num_domains();
  SEEP_RETURN_IF_ERROR(
      flow_internal::CheckStepInput("explicit", dt, n, volume_change, options_.diagnostics));
  SEEP_RETURN_IF_ERROR(flow_internal::CheckTally("explicit", n, tally, options_.diagnostics));
  SEEP_RETURN_IF_ERROR(Prepare(network));

  FlowStepReport report;
  report.dt_requested = dt;
  report.dt_crit = limit_.dt_crit;
  report.limiting_domain = limit_.limiting_domain;
  const double allowed = options_.safety_factor * limit_.dt_crit;
  double step = dt;
  if (dt > allowed) {
    switch (options_.policy) {
      case StepLimitPolicy::kRefuse:
        return FailedPrecondition(
            "flow.explicit: dt = " + flow_internal::FormatNumber(dt) +
            " s exceeds safety_factor * dt_crit = " + flow_internal::FormatNumber(allowed) +
            " s (dt_crit = V_s/(K_f sum C) = " + flow_internal::FormatNumber(limit_.dt_crit) +
            " s at domain " + std::to_string(limit_.limiting_domain) +
            ": V_s = " + flow_internal::FormatNumber(limit_.limiting_storage_volume) +
            " m^2, sum C = " + flow_internal::FormatNumber(limit_.limiting_conductance_sum) +
            " m^2/(Pa s)); the explicit update would be unstable. Reduce dt (or use policy "
            "kReduce to sub-step), switch to the implicit solver, raise the storage volume "
            "(a volume floor: scene.solver.storage_floor_fraction), cap the aperture, or lower "
            "K_f");
      case StepLimitPolicy::kReduce:
        step = allowed;
        break;
      case StepLimitPolicy::kAdviseOnly:
        report.limit_exceeded = true;
        if (warned_advise_only_) break;
        warned_advise_only_ = true;
        Logger()->warn(
            "flow.explicit: running dt = {} s above safety * dt_crit = {} s "
            "(advise-only policy)",
            dt, allowed);
        break;
    }
  }
  report.dt = step;

  const bool new_gain = step != gain_dt_;
  gain_dt_ = step;
  double* pressure = network.mutable_pressure().data();
  const double inv_dt = 1.0 / step;
  const double* dv = volume_change.empty() ? nullptr : volume_change.data();
  double* node_outflow = tally != nullptr ? tally->node_outflow_m2.data() : nullptr;
  const int threads =
      static_cast<std::ptrdiff_t>(n) >= internal::MinParallelItems() ? internal::CoreThreads() : 1;
  Budget b;
  if (threads > 1) {
    if (owner_threads_ != threads) IndexPipesByShare(network, threads);
    // The shares' sink slots (a thread count set since the refresh may ask for more).
    if (inflow_.size() < WithSinkSlots(n, threads)) inflow_.resize(WithSinkSlots(n, threads));
    if (options_.diagnostics) stored_.resize(n);
    const ShareSweep sweep{.domains = static_cast<std::ptrdiff_t>(n),
                           .threads = threads,
                           .a = network.pipe_domain_a().data(),
                           .b = network.pipe_domain_b().data(),
                           .c = network.pipe_conductance().data(),
                           .owner_start = owner_start_.data(),
                           .owner_pipes = owner_pipes_.data(),
                           .owner_end_a = owner_end_a_.data(),
                           .owner_end_b = owner_end_b_.data(),
                           .rate = rate_.data(),
                           .capacity = capacity_.data(),
                           .volume_change = dv,
                           .gain = gain_.data(),
                           .inflow = inflow_.data(),
                           .stored = stored_.data(),
                           .pressure = pressure,
                           .node_outflow = node_outflow,
                           .step = step,
                           .inv_dt = inv_dt,
                           .new_gain = new_gain};
    SweepOnShares(sweep, options_.diagnostics ? &b : nullptr);
  } else {
    if (new_gain) {
      for (std::size_t d = 0; d < n; ++d) gain_[d] = step * rate_[d];
    }
    AccumulatePipeFlows(network.num_pipes(), network.pipe_domain_a().data(),
                        network.pipe_domain_b().data(), network.pipe_conductance().data(), pressure,
                        inflow_.data());
    if (options_.diagnostics) {
      b = UpdateDomainsWithBudget(n, gain_.data(), capacity_.data(), dv, inv_dt, inflow_.data(),
                                  pressure, node_outflow);
    } else if (dv == nullptr) {
      UpdateDomains(n, gain_.data(), inflow_.data(), pressure);
    } else {
      UpdateDomainsWithVolumeChange(n, gain_.data(), dv, inv_dt, inflow_.data(), pressure);
    }
  }
  double source_inflow = 0.0;
  double source_magnitude = 0.0;
  for (const std::int32_t s : sources_) {
    source_inflow += network.source_rate()[s];
    source_magnitude += std::abs(network.source_rate()[s]);
  }
  if (options_.diagnostics) {
    if (tally != nullptr) {
      tally->source_m2 += step * source_inflow;
      tally->compressed_m2 += b.stored_change;
      tally->pore_growth_m2 += b.volume_change;
      tally->boundary_gross_m2 += step * b.boundary_magnitude;
    }
    report.boundary_inflow = b.boundary_inflow;
    report.source_inflow = source_inflow;
    report.volume_change = b.volume_change;
    report.stored_change = b.stored_change;
    const double expected = step * (b.boundary_inflow + source_inflow) - b.volume_change;
    // Relative to the fluid held as well as to what moved (flow_step_report.h): near
    // equilibrium the step's terms vanish and only the level bounds what P can resolve.
    const double scale = b.stored_level + b.stored_magnitude +
                         step * (b.boundary_magnitude + source_magnitude) + b.volume_magnitude;
    report.mass_balance_error = scale > 0.0 ? std::abs(b.stored_change - expected) / scale : 0.0;
    report.min_pressure = b.min_pressure;
    report.max_pressure = b.max_pressure;
  }
  // Re-arm the accumulator with the sources (and the head inflow) of the next step.
  if (!base_inflow_.empty()) {
    std::copy(base_inflow_.begin(), base_inflow_.end(), inflow_.begin());
  } else {
    for (const std::int32_t s : sources_) inflow_[s] = network.source_rate()[s];
  }

  if (options_.diagnostics &&
      !(std::isfinite(report.min_pressure) && std::isfinite(report.max_pressure))) {
    return FailedPrecondition("flow.explicit: pressure became non-finite (min " +
                              flow_internal::FormatNumber(report.min_pressure) + ", max " +
                              flow_internal::FormatNumber(report.max_pressure) +
                              " Pa); check dt against dt_crit and the dV input");
  }
  return report;
}

Result<FlowAdvanceReport> ExplicitSolver::Advance(FlowNetwork& network, double duration,
                                                  std::span<const double> volume_change,
                                                  FluidTally* tally) {
  if (!(std::isfinite(duration) && duration > 0.0)) {
    return InvalidArgument("flow.explicit.duration: must be finite and > 0 (got " +
                           flow_internal::FormatNumber(duration) + ")");
  }
  if (!volume_change.empty() && volume_change.size() != network.num_domains()) {
    return InvalidArgument("flow.explicit.volume_change: has " +
                           std::to_string(volume_change.size()) + " entries, expected " +
                           std::to_string(network.num_domains()) + " (one per domain, or none)");
  }
  SEEP_RETURN_IF_ERROR(Prepare(network));
  const double allowed = options_.safety_factor * limit_.dt_crit;
  const double n = std::isfinite(allowed) ? std::ceil(duration / allowed) : 1.0;
  // One advance runs inside one step, where neither a cancel nor a run's time limit reaches:
  // beyond a million sub-steps it would hold its thread for minutes to days (1.2e11 of a 0.1 m
  // aperture did), so it is refused, naming the way out.
  if (n > kMaxSubSteps) {
    return FailedPrecondition(
        "flow.explicit: advancing " + flow_internal::FormatNumber(duration) + " s needs " +
        flow_internal::FormatNumber(n) +
        " sub-steps of dt_crit = " + flow_internal::FormatNumber(limit_.dt_crit) +
        " s (limiting domain " + std::to_string(limit_.limiting_domain) + "), more than the " +
        flow_internal::FormatNumber(kMaxSubSteps) +
        " one advance may take; use the implicit solver, or give slivers a storage floor "
        "(scene.solver.storage_floor_fraction, e.g. 0.05)");
  }
  FlowAdvanceReport out;
  out.sub_steps = static_cast<std::int64_t>(std::max(1.0, n));
  out.sub_step = duration / static_cast<double>(out.sub_steps);
  out.dt_crit = limit_.dt_crit;
  out.limiting_domain = limit_.limiting_domain;
  // duration / n can round above the allowed step by an ulp: the governor must not refuse it.
  const double step = std::min(out.sub_step, allowed);
  std::span<const double> dv;
  if (!volume_change.empty()) {
    sub_step_volume_change_.resize(volume_change.size());
    const double share = 1.0 / static_cast<double>(out.sub_steps);
    const auto domains = static_cast<std::ptrdiff_t>(volume_change.size());
    double* sub = sub_step_volume_change_.data();
    const double* whole = volume_change.data();
    internal::ForEachShare(domains, [&](std::ptrdiff_t begin, std::ptrdiff_t end) {
#pragma omp simd
      for (std::ptrdiff_t d = begin; d < end; ++d) sub[d] = whole[d] * share;
    });
    dv = sub_step_volume_change_;
  }
  out.max_mass_balance_error = options_.diagnostics ? 0.0 : FlowStepReport::kNaN;
  for (std::int64_t k = 0; k < out.sub_steps; ++k) {
    SEEP_ASSIGN_OR_RETURN(out.last, Step(network, step, dv, tally));
    if (options_.diagnostics) {
      out.max_mass_balance_error =
          std::max(out.max_mass_balance_error, out.last.mass_balance_error);
    }
  }
  return out;
}

}  // namespace seep::core
