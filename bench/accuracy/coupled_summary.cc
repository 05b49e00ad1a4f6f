// The coupled problems' summary (see coupled_summary.h).
#include "coupled_summary.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "coupled_grid.h"
#include "pareto.h"

namespace seep::bench {
namespace {

std::string Choice(const AccuracyRun& r) {
  return fmt::format("K_f {:.2g} {} flow every {} ({}), dt_safety {:g}, {} disks",
                     r.bulk_modulus_pa, r.solver, r.flow_every,
                     r.flow_every_asked == 0 ? "auto" : "set", r.dem_dt_safety, r.resolution);
}

// The run every other run of its size is compared with (real water, automatic interval, base
// step): its own distance from real water is 0 by construction, so it is no answer to "what is
// the cheapest run within x % of real water".
bool IsRealWaterReference(const AccuracyRun& r) {
  return r.bulk_modulus_pa == kRealWaterBulkModulusPa && r.flow_every_asked == 0 &&
         r.real_water_error == 0.0;
}

void PrintCheapest(std::FILE* out, const std::vector<AccuracyRun>& rows, const std::string& problem,
                   bool against_real_water) {
  for (const double target : {0.01, 0.05}) {
    std::optional<std::size_t> best;
    for (std::size_t i = 0; i < rows.size(); ++i) {
      const AccuracyRun& r = rows[i];
      const double e = against_real_water ? r.real_water_error : r.error;
      if (r.problem != problem || !std::isfinite(e) || e > target) continue;
      if (against_real_water && IsRealWaterReference(r)) continue;
      if (!best || r.wall_s < rows[*best].wall_s) best = i;
    }
    const char* what = against_real_water ? "vs real water" : "vs analytic ";
    if (!best) {
      fmt::print(out, "  {} <= {:g}%: no run{}\n", what, 100 * target,
                 against_real_water ? " but real water's own" : "");
      continue;
    }
    const AccuracyRun& b = rows[*best];
    fmt::print(
        out, "  {} <= {:g}%: {:.3f} s, error {:.2e} (vs real water {:.2e}), Pi_K {:.3g}: {}\n",
        what, 100 * target, b.wall_s, b.error, b.real_water_error, b.stiffness_ratio, Choice(b));
  }
}

// The rate sweep: the measure at each rate (real water) against the slowest rate's.
void PrintRates(std::FILE* out, const std::vector<AccuracyRun>& rows, const std::string& problem) {
  fmt::print(out, "  against the slowest rate (real water, automatic interval):\n");
  for (const AccuracyRun& r : rows) {
    if (r.problem != problem) continue;
    fmt::print(out, "    {:.2e} off in {:.3f} s: {}\n", r.error, r.wall_s, r.note);
  }
}

// A fixed flow interval against the same run at the automatic one (same K_f, solver, size and
// step): the runs it spoiled (more than 5 % apart, or failed) and those it left within 1 %,
// each with its range of fluid step / interval. The ratio alone does not decide it: a sealed
// sample takes any interval, a bonded sample at a stiff fluid breaks bonds at 1/4.
void PrintFixedIntervals(std::FILE* out, const std::vector<AccuracyRun>& rows,
                         const std::string& problem) {
  struct Range {
    int runs = 0;
    double lo = std::numeric_limits<double>::infinity();
    double hi = 0.0;
    void Add(double ratio) {
      ++runs;
      lo = std::min(lo, ratio);
      hi = std::max(hi, ratio);
    }
  };
  Range spoiled;
  Range kept;
  for (const AccuracyRun& r : rows) {
    if (r.problem != problem || r.flow_every_asked == 0) continue;
    const auto automatic = std::find_if(rows.begin(), rows.end(), [&](const AccuracyRun& a) {
      return a.problem == problem && a.flow_every_asked == 0 &&
             a.bulk_modulus_pa == r.bulk_modulus_pa && a.solver == r.solver &&
             a.resolution == r.resolution && a.dem_dt_safety == r.dem_dt_safety;
    });
    if (automatic == rows.end() || !std::isfinite(automatic->real_water_error)) continue;
    const double apart = std::abs(r.real_water_error - automatic->real_water_error);
    if (!std::isfinite(r.real_water_error) || apart > 0.05) {
      spoiled.Add(r.fluid_step_ratio);
    } else if (apart <= 0.01) {
      kept.Add(r.fluid_step_ratio);
    }
  }
  if (spoiled.runs + kept.runs == 0) return;
  const auto range = [](const Range& g) {
    return g.runs == 0 ? std::string("-") : fmt::format("{:.3g}..{:.3g}", g.lo, g.hi);
  };
  fmt::print(out,
             "  fixed flow intervals against the automatic one: {} runs more than 5 % apart or "
             "failed (fluid step / interval {}), {} within 1 % ({})\n",
             spoiled.runs, range(spoiled), kept.runs, range(kept));
}

}  // namespace

bool IsCoupledProblem(const std::string& problem) {
  return problem == "undrained" || problem == "consolidation" || problem.rfind("breakdown", 0) == 0;
}

void PrintCoupledSummary(std::FILE* out, const std::vector<AccuracyRun>& rows) {
  for (const std::string& problem : Problems(rows)) {
    if (!IsCoupledProblem(problem)) continue;
    fmt::print(out, "\n== {}: real water and the cheapest runs within 1 % and 5 %\n", problem);
    for (const AccuracyRun& r : rows) {
      if (r.problem == problem && r.bulk_modulus_pa == kRealWaterBulkModulusPa &&
          r.flow_every_asked == 0) {
        fmt::print(out, "  real water: {:.3f} s, error {:.2e}, Pi_K {:.3g}: {}\n", r.wall_s,
                   r.error, r.stiffness_ratio, Choice(r));
      }
    }
    if (problem == "breakdown-rate") {
      PrintRates(out, rows, problem);
      continue;
    }
    // The breakdown has no analytic answer: its error is against real water already.
    if (problem.rfind("breakdown", 0) != 0) PrintCheapest(out, rows, problem, false);
    PrintCheapest(out, rows, problem, true);
    // The rule: the error of the runs at each K_f against Pi_K (automatic flow interval), and
    // the smallest Pi_K that kept every run of the problem within 5 % and 1 %.
    fmt::print(out, "  error against Pi_K (automatic flow interval):\n");
    for (const AccuracyRun& r : rows) {
      if (r.problem != problem || r.flow_every_asked != 0) continue;
      fmt::print(out,
                 "    Pi_K {:>9.3g}  K_f {:>8.2g}  {:<8} {:>4} disks  dt_safety {:<4g} error "
                 "{:.2e}  vs real water {:.2e}\n",
                 r.stiffness_ratio, r.bulk_modulus_pa, r.solver, r.resolution, r.dem_dt_safety,
                 r.error, r.real_water_error);
    }
    // The runs that differ from real water in K_f alone: the automatic flow interval and a step
    // safety no larger than the problem's base (the first row's).
    double base_safety = 0.0;
    for (const AccuracyRun& r : rows) {
      if (r.problem == problem) {
        base_safety = r.dem_dt_safety;
        break;
      }
    }
    for (const double target : {0.05, 0.01}) {
      double worst_failing = 0.0;  // the largest Pi_K of a run beyond target
      double lowest = std::numeric_limits<double>::infinity();
      for (const AccuracyRun& r : rows) {
        if (r.problem != problem || r.flow_every_asked != 0 || r.dem_dt_safety > base_safety ||
            !std::isfinite(r.real_water_error)) {
          continue;
        }
        lowest = std::min(lowest, r.stiffness_ratio);
        if (r.real_water_error > target) worst_failing = std::max(worst_failing, r.stiffness_ratio);
      }
      if (worst_failing > 0.0) {
        fmt::print(out,
                   "  every run at the automatic interval and base step with Pi_K above {:.3g} is "
                   "within {:g}% of real water\n",
                   worst_failing, 100 * target);
      } else {
        fmt::print(out,
                   "  every run at the automatic interval and base step is within {:g}% of real "
                   "water, down to Pi_K {:.3g}\n",
                   100 * target, lowest);
      }
    }
    PrintFixedIntervals(out, rows, problem);
  }
}

}  // namespace seep::bench
