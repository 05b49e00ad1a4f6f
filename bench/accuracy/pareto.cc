// Pareto fronts of the accuracy runs (see pareto.h).
#include "pareto.h"

#include <algorithm>
#include <cmath>

namespace seep::bench {

std::vector<std::size_t> ParetoFront(const std::vector<AccuracyRun>& rows,
                                     const std::string& problem, int resolution) {
  std::vector<std::size_t> candidates;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    if (rows[i].problem == problem && !rows[i].pending && std::isfinite(rows[i].error) &&
        (resolution < 0 || rows[i].resolution == resolution)) {
      candidates.push_back(i);
    }
  }
  // By wall time, then error, then input order: a stable, deterministic sweep.
  std::stable_sort(candidates.begin(), candidates.end(), [&](std::size_t a, std::size_t b) {
    if (rows[a].wall_s != rows[b].wall_s) return rows[a].wall_s < rows[b].wall_s;
    return rows[a].error < rows[b].error;
  });
  std::vector<std::size_t> front;
  for (const std::size_t i : candidates) {
    if (front.empty() || rows[i].error < rows[front.back()].error) front.push_back(i);
  }
  return front;
}

std::vector<std::string> Problems(const std::vector<AccuracyRun>& rows) {
  std::vector<std::string> out;
  for (const AccuracyRun& r : rows) {
    if (std::find(out.begin(), out.end(), r.problem) == out.end()) out.push_back(r.problem);
  }
  return out;
}

}  // namespace seep::bench
