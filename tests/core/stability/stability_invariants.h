// The invariants every hard case of the stability suite asserts (issue 7, "Hard cases"): finite
// pressures, the discrete maximum principle, and the fluid budget per step and over a whole run.
//
// Budget. The fluid that changes is the stored excess E = sum_i V_s,i P_i / K_f over non-fixed
// domains (StoredFluidExcess, m^2); the rest of the mass proxy sum V_s (1 + P/K_f) is constant on a
// rigid network. Over a run, E(t) - E(0) must equal the fluid the steps transported,
// sum_n dt_n (boundary_inflow_n + source_inflow_n) - volume_change_n, as each step's own report
// states it. The relative error divides by the fluid held (sum V_s |P| / K_f, the largest of the
// start and the end) plus the magnitude of everything transported (gross boundary throughput,
// sources, dV): each pressure update rounds P at eps |P| and each flux at eps |q|, so these bound
// what any run can resolve — the scale flow_step_report.h defines per step. 1e-10 leaves a 1e4
// margin over n * eps for the runs here.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <limits>
#include <string>

#include "seep/core/flow/flow_diagnostics.h"
#include "seep/core/flow/flow_network.h"
#include "seep/core/flow/flow_step_report.h"
#include "seep/core/flow/fluid.h"
#include "seep/core/flow/storage_volume.h"
#include "seep/core/status.h"

namespace seep::core::stability {

// The mass tolerance of the suite (issue 7): relative, per step and cumulative.
inline constexpr double kMassTolerance = 1e-10;

// Water's bulk modulus K_f, Pa: the stiff fluid the suite's scenes use.
inline constexpr double kWater = 2.2e9;

struct PressureBounds {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
};

// min/max over every domain's current pressure (initial values of free domains and the values
// held at fixed ones): what the maximum principle allows a source-free run.
inline PressureBounds BoundsOf(const FlowNetwork& network) {
  PressureBounds b;
  for (const double p : network.pressure()) {
    b.lo = std::min(b.lo, p);
    b.hi = std::max(b.hi, p);
  }
  return b;
}

inline bool HasSource(const FlowNetwork& network) {
  for (std::size_t d = 0; d < network.num_domains(); ++d) {
    if (network.role()[d] == DomainRole::kSource && network.source_rate()[d] != 0.0) return true;
  }
  return false;
}

inline ::testing::AssertionResult AllFinite(const FlowNetwork& network) {
  for (std::size_t d = 0; d < network.num_domains(); ++d) {
    if (!std::isfinite(network.pressure()[d])) {
      return ::testing::AssertionFailure()
             << "pressure[" << d << "] = " << network.pressure()[d] << " is not finite";
    }
  }
  return ::testing::AssertionSuccess();
}

// Every pressure in [lo - slack, hi + slack]; slack = 1e-12 (hi - lo) absorbs the rounding of a
// convex combination (a few ulps of the range), nothing more.
inline ::testing::AssertionResult WithinBounds(const FlowNetwork& network, PressureBounds b) {
  const double slack = 1e-12 * std::max(b.hi - b.lo, std::max(std::abs(b.lo), std::abs(b.hi)));
  for (std::size_t d = 0; d < network.num_domains(); ++d) {
    const double p = network.pressure()[d];
    if (!(p >= b.lo - slack && p <= b.hi + slack)) {
      return ::testing::AssertionFailure() << "pressure[" << d << "] = " << p << " leaves [" << b.lo
                                           << ", " << b.hi << "] (maximum principle)";
    }
  }
  return ::testing::AssertionSuccess();
}

// Sum V_s |P| / K_f over non-fixed domains, m^2: the fluid held beyond the reference state.
inline double FluidHeld(const FlowNetwork& network, double bulk_modulus,
                        const StorageModel& storage) {
  double held = 0.0;
  for (std::size_t d = 0; d < network.num_domains(); ++d) {
    if (network.role()[d] == DomainRole::kFixedPressure) continue;
    held += StorageVolumeOf(network, storage, d) * std::abs(network.pressure()[d]);
  }
  return held / bulk_modulus;
}

// Gross rate through the fixed-pressure nodes (in plus out, m^2/s) at the current pressures: the
// throughput whose rounding (eps per flux) no scheme can beat, so it belongs in the scale.
inline double GrossBoundaryRate(const FlowNetwork& network) {
  const BoundaryFluxes f = ComputeBoundaryFluxes(network);
  return f.total_inflow + f.total_outflow;
}

// The fluid budget of a run, per step and cumulative, measured here from the pressures (see the
// file comment) and independent of the solvers' own diagnostic, which is kept alongside. Every
// step of the network must go through Step() (or Record() right after the solver's step).
class FluidLedger {
 public:
  FluidLedger(const FlowNetwork& network, double bulk_modulus, const StorageModel& storage)
      : bulk_modulus_(bulk_modulus), storage_(storage) {
    start_excess_ = StoredFluidExcess(network, bulk_modulus, storage).value();
    last_excess_ = start_excess_;
    start_held_ = FluidHeld(network, bulk_modulus, storage);
  }

  // One solver step, booked. Explicit steps move fluid at the old pressures, backward Euler at the
  // new ones: the throughput scale takes the larger of the two gross boundary rates.
  template <typename Solver>
  Result<FlowStepReport> Step(Solver& solver, FlowNetwork& network, double dt) {
    const double gross_before = GrossBoundaryRate(network);
    auto r = solver.Step(network, dt);
    if (r.ok()) Record(network, *r, std::max(gross_before, GrossBoundaryRate(network)));
    return r;
  }

  // Books a step the caller ran: `network` holds the pressures after it.
  void Record(const FlowNetwork& network, const FlowStepReport& r, double gross_boundary_rate) {
    const double excess = StoredFluidExcess(network, bulk_modulus_, storage_).value();
    const double moved = r.dt * (r.boundary_inflow + r.source_inflow) - r.volume_change;
    const double magnitude =
        r.dt * gross_boundary_rate + std::abs(r.dt * r.source_inflow) + std::abs(r.volume_change);
    const double stored = excess - last_excess_;
    const double scale = FluidHeld(network, bulk_modulus_, storage_) + std::abs(stored) + magnitude;
    const double step_error = scale > 0.0 ? std::abs(stored - moved) / scale : 0.0;
    if (!(step_error <= kMassTolerance)) ++step_failures_;  // NaN counts as a failure
    worst_step_ = std::max(worst_step_, step_error);
    if (std::isnan(r.mass_balance_error)) ++reported_nan_;
    worst_reported_ = std::max(worst_reported_, r.mass_balance_error);
    transported_ += moved;
    transported_magnitude_ += magnitude;
    last_excess_ = excess;
    ++steps_;
  }

  double CumulativeError(const FlowNetwork& network) const {
    const double excess = StoredFluidExcess(network, bulk_modulus_, storage_).value();
    const double scale =
        std::max(start_held_, FluidHeld(network, bulk_modulus_, storage_)) + transported_magnitude_;
    const double error = std::abs(excess - start_excess_ - transported_);
    return scale > 0.0 ? error / scale : error;
  }

  double worst_step_error() const { return worst_step_; }
  // The worst of the solvers' own FlowStepReport::mass_balance_error values (NaN-free runs).
  double worst_reported_error() const { return worst_reported_; }
  long steps() const { return steps_; }
  double transported() const { return transported_; }  // net fluid moved in, m^2

  // The solvers' own per-step figure, where it is meaningful (see mass_balance_report_test.cc).
  ::testing::AssertionResult SolverReportWithin() const {
    if (worst_reported_ <= kMassTolerance && reported_nan_ == 0) {
      return ::testing::AssertionSuccess();
    }
    return ::testing::AssertionFailure() << "worst FlowStepReport::mass_balance_error "
                                         << worst_reported_ << " (" << reported_nan_ << " NaN)";
  }

  // Per step and cumulative, with the numbers in the message.
  ::testing::AssertionResult Conserved(const FlowNetwork& network) const {
    const double cumulative = CumulativeError(network);
    if (step_failures_ == 0 && cumulative <= kMassTolerance) {
      return ::testing::AssertionSuccess();
    }
    return ::testing::AssertionFailure()
           << step_failures_ << " of " << steps_ << " steps above " << kMassTolerance << " (worst "
           << worst_step_ << "), cumulative " << cumulative;
  }

 private:
  double bulk_modulus_;
  StorageModel storage_;
  double start_excess_ = 0.0;
  double last_excess_ = 0.0;
  double start_held_ = 0.0;
  double transported_ = 0.0;
  double transported_magnitude_ = 0.0;
  double worst_step_ = 0.0;
  double worst_reported_ = 0.0;
  long step_failures_ = 0;
  long reported_nan_ = 0;
  long steps_ = 0;
};

// Worst-case numbers the suite measured, printed once per test for the report.
inline void PrintMeasured(const std::string& what, double value) {
  std::printf("[ measured ] %s = %.3e\n", what.c_str(), value);
}

}  // namespace seep::core::stability
