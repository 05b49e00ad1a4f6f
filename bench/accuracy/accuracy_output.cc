// CSV and table output of the accuracy bench (see accuracy_output.h).
#include "accuracy_output.h"

#include <fmt/format.h>

#include <algorithm>
#include <fstream>

namespace seep::bench {
namespace {

// Free text in a CSV cell: commas and quotes would split or break the row.
std::string CsvText(std::string s) {
  std::replace(s.begin(), s.end(), ',', ';');
  std::replace(s.begin(), s.end(), '"', '\'');
  std::replace(s.begin(), s.end(), '\n', ' ');
  return s;
}

}  // namespace

core::Status WriteCsv(const std::string& path, const std::vector<AccuracyRun>& rows) {
  std::ofstream f(path, std::ios::trunc);
  if (!f) return core::InvalidArgument(fmt::format("csv path {}: cannot open for writing", path));
  f << "problem,solver,storage,dt_over_dt_crit,resolution,domains,bulk_modulus_pa,steps,wall_s,"
       "setup_s,error,error_kind,note,dem_dt_safety,flow_every_asked,flow_every,"
       "fluid_to_skeleton_stiffness,real_water_error,fluid_step_over_flow_interval\n";
  for (const AccuracyRun& r : rows) {
    if (r.pending) {
      f << fmt::format("{},{},{},,,,,,,,,{},{},,,,,,\n", r.problem, r.solver, r.storage,
                       CsvText(r.error_kind), CsvText(r.note));
      continue;
    }
    f << fmt::format("{},{},{},{},{},{},{:.3g},{},{:.6e},{:.6e},{:.6e},{},{}", r.problem, r.solver,
                     r.storage, r.dt_over_dt_crit, r.resolution, r.domains, r.bulk_modulus_pa,
                     r.steps, r.wall_s, r.setup_s, r.error, CsvText(r.error_kind), CsvText(r.note));
    if (r.storage == "coupled") {
      f << fmt::format(",{:g},{},{:g},{:.4g},{:.6e},{:.4g}\n", r.dem_dt_safety, r.flow_every_asked,
                       r.flow_every, r.stiffness_ratio, r.real_water_error, r.fluid_step_ratio);
    } else {
      f << ",,,,,,\n";
    }
  }
  f.flush();
  if (!f) return core::Internal(fmt::format("csv path {}: write failed", path));
  return core::Status::Ok();
}

void PrintTable(std::FILE* out, const std::vector<AccuracyRun>& rows,
                const std::vector<std::size_t>& which) {
  fmt::print(out, "{:<16} {:<9} {:<9} {:>8} {:>5} {:>7} {:>8} {:>8} {:>11} {:>10}  {}\n", "problem",
             "solver", "storage", "dt/dtc", "res", "domains", "K_f", "steps", "wall_s", "error",
             "note");
  for (const std::size_t i : which) {
    const AccuracyRun& r = rows[i];
    if (r.pending) {
      fmt::print(out, "{:<16} {:<9} {}\n", r.problem, r.solver, r.note);
      continue;
    }
    fmt::print(out,
               "{:<16} {:<9} {:<9} {:>8g} {:>5} {:>7} {:>8.2g} {:>8} {:>11.4e} {:>10.3e}  {}\n",
               r.problem, r.solver, r.storage, r.dt_over_dt_crit, r.resolution, r.domains,
               r.bulk_modulus_pa, r.steps, r.wall_s, r.error, r.note);
  }
}

}  // namespace seep::bench
