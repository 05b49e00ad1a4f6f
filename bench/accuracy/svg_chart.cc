// SVG chart of error versus wall time (see svg_chart.h), drawn with plot/svg_chart (seep_svg).
#include "svg_chart.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <string>
#include <utility>
#include <vector>

#include "coupled_summary.h"
#include "pareto.h"
#include "plot/svg_chart.h"

namespace seep::bench {
namespace {

// Errors at round-off (a steady solve on a lattice) are drawn at this floor.
constexpr double kErrorFloor = 1e-16;

plot::Style MakeStyle(const char* label, const char* colour, plot::Marker marker) {
  plot::Style s;
  s.label = label;
  s.colour = colour;
  s.marker = marker;
  return s;
}

plot::Style StyleOf(const std::string& solver, const std::string& storage) {
  if (solver == "explicit" && storage == "apparent") {
    return MakeStyle("explicit, apparent V_d (PFC's scheme)", "#d62728", plot::Marker::kRing);
  }
  if (solver == "explicit")
    return MakeStyle("explicit, pore V_p", "#ff7f0e", plot::Marker::kSquare);
  if (solver == "implicit") {
    return MakeStyle("backward Euler, pore V_p", "#1f77b4", plot::Marker::kTriangle);
  }
  if (solver == kCrankNicolsonLabel) {
    return MakeStyle("Crank-Nicolson, pore V_p", "#9467bd", plot::Marker::kCircle);
  }
  return MakeStyle("steady", "#2ca02c", plot::Marker::kDiamond);
}

// Coupled rows: a colour per K_f (real water to scaled), a marker per solver.
plot::Style CoupledStyleOf(const AccuracyRun& r) {
  static const char* const kColours[] = {"#1f77b4", "#2ca02c", "#ff7f0e", "#d62728", "#9467bd"};
  static const double kBulk[] = {2.2e9, 2.2e8, 2.2e7, 4e6, 1e6};
  std::size_t k = 0;
  while (k + 1 < std::size(kBulk) && r.bulk_modulus_pa < kBulk[k] * 0.999) ++k;
  plot::Style s;
  s.label = fmt::format("K_f = {:.2g} Pa, {}", r.bulk_modulus_pa, r.solver);
  s.colour = kColours[k];
  s.marker = r.solver == "explicit" ? plot::Marker::kSquare : plot::Marker::kTriangle;
  return s;
}

plot::Style FrontStyle() {
  plot::Style s = MakeStyle("Pareto front", "#000000", plot::Marker::kNone);
  s.line = true;
  return s;
}

bool IsPfcScheme(const AccuracyRun& r) { return r.solver == "explicit" && r.storage == "apparent"; }

// What a coupled panel's error is measured against; the problem's name elsewhere.
std::string PanelTitle(const std::string& problem) {
  if (problem == "undrained") return "undrained: du/dsigma vs analytic";
  if (problem == "consolidation") return "consolidation: vs the Terzaghi series";
  if (problem == "breakdown") return "breakdown at 2e-5 m2/s: P_i vs real water";
  if (problem == "breakdown-slow") return "breakdown at 2.5e-6 m2/s: P_i vs real water";
  if (problem == "breakdown-rate") return "real water: P_i vs the slowest rate";
  return problem;
}

// A coupled problem's error is against one of its own runs (real water, or the slowest rate):
// that run's error is 0 by construction and has no place on a log axis.
bool IsOwnReference(const AccuracyRun& r) { return r.storage == "coupled" && r.error == 0.0; }

// One panel: the runs of `problem` (at `resolution` only when it is >= 0).
plot::Panel MakePanel(const std::vector<AccuracyRun>& rows, const std::string& problem,
                      int resolution, const std::string& title) {
  plot::Panel panel;
  panel.title = title;
  panel.x.label = "wall time of the run, s";
  panel.x.scale = plot::Scale::kLog10;
  panel.y.label = "error";
  panel.y.scale = plot::Scale::kLog10;
  panel.empty_note = "no run produced a finite error";
  const bool transient = problem.rfind("diffusion", 0) == 0 || problem == "terzaghi";
  if (IsCoupledProblem(problem)) {
    panel.y.include_min = 1e-3;
    panel.y.include_max = 1.0;
    panel.rules.push_back({0.01, "1% error"});
    panel.rules.push_back({0.05, "5% error"});
  } else if (transient) {
    panel.y.include_min = 1e-3;
    panel.y.include_max = 0.1;
    panel.rules.push_back({0.01, "1% error"});
  }
  // One series per style; PFC's scheme last, as bigger rings: in T it lands exactly on the
  // pore-volume runs.
  std::vector<plot::Series> by_style;
  for (const bool pfc : {false, true}) {
    for (const AccuracyRun& r : rows) {
      if (r.problem != problem || r.pending || !std::isfinite(r.error) || r.wall_s <= 0.0 ||
          (resolution >= 0 && r.resolution != resolution) || IsPfcScheme(r) != pfc ||
          IsOwnReference(r)) {
        continue;
      }
      plot::Style style = r.storage == "coupled" ? CoupledStyleOf(r) : StyleOf(r.solver, r.storage);
      style.marker_size = pfc ? 5.0 : 3.5;
      auto it = std::find_if(by_style.begin(), by_style.end(),
                             [&](const plot::Series& s) { return s.style.label == style.label; });
      if (it == by_style.end()) {
        it = by_style.insert(by_style.end(), plot::Series());
        it->style = style;
      }
      it->x.push_back(r.wall_s);
      it->y.push_back(std::max(r.error, kErrorFloor));
    }
  }
  if (by_style.empty()) return panel;
  panel.series = std::move(by_style);
  plot::Series front;
  front.style = FrontStyle();
  for (const std::size_t i : ParetoFront(rows, problem, resolution)) {
    if (IsOwnReference(rows[i])) continue;
    front.x.push_back(rows[i].wall_s);
    front.y.push_back(std::max(rows[i].error, kErrorFloor));
  }
  panel.series.push_back(std::move(front));
  return panel;
}

}  // namespace

core::Status WriteSvgChart(const std::string& path, const std::vector<AccuracyRun>& rows) {
  plot::Chart chart;
  chart.columns = 2;
  // A panel per problem, then the last diffusion problem at its finest resolution: the case of a
  // DEM packing, whose resolution is not the user's choice.
  std::string last_diffusion;
  for (const std::string& problem : Problems(rows)) {
    chart.panels.push_back(MakePanel(rows, problem, -1, PanelTitle(problem)));
    if (problem.rfind("diffusion", 0) == 0) last_diffusion = problem;
  }
  if (!last_diffusion.empty()) {
    int finest = -1;
    for (const AccuracyRun& r : rows) {
      if (r.problem == last_diffusion) finest = std::max(finest, r.resolution);
    }
    chart.panels.push_back(
        MakePanel(rows, last_diffusion, finest,
                  fmt::format("{}, {} domains along only", last_diffusion, finest)));
  }
  // The legend: each style drawn, in order of first use, and the front.
  for (const plot::Panel& panel : chart.panels) {
    for (const plot::Series& series : panel.series) {
      if (series.style.label == FrontStyle().label) continue;
      const bool listed =
          std::any_of(chart.legend.begin(), chart.legend.end(),
                      [&](const plot::Style& s) { return s.label == series.style.label; });
      if (!listed) chart.legend.push_back(series.style);
    }
  }
  chart.legend.push_back(FrontStyle());
  if (const std::string error = plot::WriteSvgFile(path, plot::RenderSvg(chart)); !error.empty()) {
    return core::InvalidArgument(error);
  }
  return core::Status::Ok();
}

}  // namespace seep::bench
