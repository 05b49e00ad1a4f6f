// The coupled problems' summary (see coupled_summary.h).
#include "coupled_summary.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
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

void PrintCheapest(std::FILE* out, const std::vector<AccuracyRun>& rows, const std::string& problem,
                   bool against_real_water) {
  for (const double target : {0.01, 0.05}) {
    std::optional<std::size_t> best;
    for (std::size_t i = 0; i < rows.size(); ++i) {
      const AccuracyRun& r = rows[i];
      const double e = against_real_water ? r.real_water_error : r.error;
      if (r.problem != problem || !std::isfinite(e) || e > target) continue;
      if (!best || r.wall_s < rows[*best].wall_s) best = i;
    }
    const char* what = against_real_water ? "vs real water" : "vs analytic ";
    if (!best) {
      fmt::print(out, "  {} <= {:g}%: no run\n", what, 100 * target);
      continue;
    }
    const AccuracyRun& b = rows[*best];
    fmt::print(
        out, "  {} <= {:g}%: {:.3f} s, error {:.2e} (vs real water {:.2e}), Pi_K {:.3g}: {}\n",
        what, 100 * target, b.wall_s, b.error, b.real_water_error, b.stiffness_ratio, Choice(b));
  }
}

}  // namespace

bool IsCoupledProblem(const std::string& problem) {
  return problem == "undrained" || problem == "consolidation";
}

void PrintCoupledSummary(std::FILE* out, const std::vector<AccuracyRun>& rows) {
  for (const std::string& problem : Problems(rows)) {
    if (!IsCoupledProblem(problem)) continue;
    fmt::print(out, "\n== {}: real water and the cheapest runs within 1 % and 5 %\n", problem);
    for (const AccuracyRun& r : rows) {
      if (r.problem == problem && r.bulk_modulus_pa == kRealWaterBulkModulusPa &&
          r.solver == "implicit" && r.flow_every_asked == 0) {
        fmt::print(out, "  real water: {:.3f} s, error {:.2e}, Pi_K {:.3g}: {}\n", r.wall_s,
                   r.error, r.stiffness_ratio, Choice(r));
      }
    }
    PrintCheapest(out, rows, problem, false);
    PrintCheapest(out, rows, problem, true);
    // The rule: the largest error of the runs at each K_f against Pi_K (base flow interval and
    // step), and the smallest Pi_K that kept every run of the problem within 5 % and 1 %.
    fmt::print(out, "  error against Pi_K (base step and interval):\n");
    for (const AccuracyRun& r : rows) {
      if (r.problem != problem || r.solver != "implicit" || r.flow_every_asked != 0) continue;
      fmt::print(out,
                 "    Pi_K {:>9.3g}  K_f {:>8.2g}  {:>4} disks  dt_safety {:<4g} error {:.2e}  vs "
                 "real water {:.2e}\n",
                 r.stiffness_ratio, r.bulk_modulus_pa, r.resolution, r.dem_dt_safety, r.error,
                 r.real_water_error);
    }
    for (const double target : {0.05, 0.01}) {
      double worst_failing = 0.0;  // the largest Pi_K of a run beyond target
      for (const AccuracyRun& r : rows) {
        if (r.problem == problem && std::isfinite(r.real_water_error) &&
            r.real_water_error > target) {
          worst_failing = std::max(worst_failing, r.stiffness_ratio);
        }
      }
      fmt::print(out, "  every run with Pi_K above {:.3g} is within {:g}% of real water\n",
                 worst_failing, 100 * target);
    }
  }
}

}  // namespace seep::bench
