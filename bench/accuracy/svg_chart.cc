// SVG chart of error versus wall time (see svg_chart.h).
#include "svg_chart.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include "pareto.h"

namespace seep::bench {
namespace {

constexpr double kPanelW = 460.0;
constexpr double kPanelH = 330.0;
constexpr double kMarginL = 62.0;
constexpr double kMarginR = 14.0;
constexpr double kMarginT = 30.0;
constexpr double kMarginB = 44.0;
constexpr int kColumns = 2;
// Errors at round-off (a steady solve on a lattice) are drawn at this floor.
constexpr double kErrorFloor = 1e-16;

struct Style {
  const char* label;
  const char* colour;
  const char* shape;  // ring, circle, square, triangle, diamond
};

Style StyleOf(const std::string& solver, const std::string& storage) {
  if (solver == "explicit" && storage == "apparent") {
    return {"explicit, apparent V_d (the paper's scheme)", "#d62728", "ring"};
  }
  if (solver == "explicit") return {"explicit, pore V_p", "#ff7f0e", "square"};
  if (solver == "implicit") return {"backward Euler, pore V_p", "#1f77b4", "triangle"};
  return {"steady", "#2ca02c", "diamond"};
}

std::string Marker(const Style& s, double x, double y, double size) {
  const std::string paint =
      fmt::format("fill=\"{}\" fill-opacity=\"0.55\" stroke=\"{}\"", s.colour, s.colour);
  const std::string shape = s.shape;
  if (shape == "ring") {
    return fmt::format(
        "<circle cx=\"{:.1f}\" cy=\"{:.1f}\" r=\"{:.1f}\" fill=\"none\" stroke=\"{}\" "
        "stroke-width=\"1.5\"/>\n",
        x, y, size, s.colour);
  }
  if (shape == "circle") {
    return fmt::format("<circle cx=\"{:.1f}\" cy=\"{:.1f}\" r=\"{:.1f}\" {}/>\n", x, y, size,
                       paint);
  }
  if (shape == "square") {
    return fmt::format("<rect x=\"{:.1f}\" y=\"{:.1f}\" width=\"{:.1f}\" height=\"{:.1f}\" {}/>\n",
                       x - size, y - size, 2 * size, 2 * size, paint);
  }
  if (shape == "triangle") {
    return fmt::format("<polygon points=\"{:.1f},{:.1f} {:.1f},{:.1f} {:.1f},{:.1f}\" {}/>\n", x,
                       y - 1.2 * size, x - size, y + 0.8 * size, x + size, y + 0.8 * size, paint);
  }
  return fmt::format(
      "<polygon points=\"{:.1f},{:.1f} {:.1f},{:.1f} {:.1f},{:.1f} {:.1f},{:.1f}\" {}/>\n", x,
      y - 1.3 * size, x + size, y, x, y + 1.3 * size, x - size, y, paint);
}

// Decades [lo, hi] covering the values, at least one decade wide.
std::pair<int, int> Decades(double lo, double hi) {
  int a = static_cast<int>(std::floor(std::log10(lo)));
  int b = static_cast<int>(std::ceil(std::log10(hi)));
  if (b <= a) b = a + 1;
  return {a, b};
}

// One panel: the runs of `problem` (at `resolution` only when it is >= 0) under `title`.
void DrawPanel(std::ostringstream& svg, const std::vector<AccuracyRun>& rows,
               const std::string& problem, int resolution, const std::string& title, double ox,
               double oy) {
  std::vector<std::size_t> runs;
  double tmin = 1e300, tmax = 0.0, emin = 1e300, emax = 0.0;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const AccuracyRun& r = rows[i];
    if (r.problem != problem || r.pending || !std::isfinite(r.error) || r.wall_s <= 0.0 ||
        (resolution >= 0 && r.resolution != resolution)) {
      continue;
    }
    runs.push_back(i);
    const double e = std::max(r.error, kErrorFloor);
    tmin = std::min(tmin, r.wall_s);
    tmax = std::max(tmax, r.wall_s);
    emin = std::min(emin, e);
    emax = std::max(emax, e);
  }
  const bool transient = problem.rfind("diffusion", 0) == 0;
  if (transient) {
    emin = std::min(emin, 1e-3);
    emax = std::max(emax, 0.1);
  }
  const double pw = kPanelW - kMarginL - kMarginR;
  const double ph = kPanelH - kMarginT - kMarginB;
  const double x0 = ox + kMarginL;
  const double y0 = oy + kMarginT;
  svg << fmt::format(
      "<text x=\"{:.1f}\" y=\"{:.1f}\" font-size=\"14\" font-weight=\"bold\">{}</text>\n", x0,
      oy + 18, title);
  svg << fmt::format(
      "<rect x=\"{:.1f}\" y=\"{:.1f}\" width=\"{:.1f}\" height=\"{:.1f}\" "
      "fill=\"none\" stroke=\"#444\"/>\n",
      x0, y0, pw, ph);
  if (runs.empty()) {
    svg << fmt::format(
        "<text x=\"{:.1f}\" y=\"{:.1f}\" font-size=\"13\">pending: needs the DEM "
        "coupling (not integrated yet)</text>\n",
        x0 + 20, y0 + ph / 2);
    return;
  }
  const auto [tx0, tx1] = Decades(tmin, tmax);
  const auto [ey0, ey1] = Decades(emin, emax);
  auto X = [&, tx0 = tx0, tx1 = tx1](double t) {
    return x0 + pw * (std::log10(t) - tx0) / (tx1 - tx0);
  };
  auto Y = [&, ey0 = ey0, ey1 = ey1](double e) {
    return y0 + ph * (1.0 - (std::log10(std::max(e, kErrorFloor)) - ey0) / (ey1 - ey0));
  };
  // Decade grid lines and labels; with many decades on the error axis label every other one.
  for (int d = tx0; d <= tx1; ++d) {
    const double x = X(std::pow(10.0, d));
    svg << fmt::format(
        "<line x1=\"{0:.1f}\" y1=\"{1:.1f}\" x2=\"{0:.1f}\" y2=\"{2:.1f}\" "
        "stroke=\"#ddd\"/>\n",
        x, y0, y0 + ph);
    svg << fmt::format(
        "<text x=\"{:.1f}\" y=\"{:.1f}\" font-size=\"11\" "
        "text-anchor=\"middle\">1e{}</text>\n",
        x, y0 + ph + 15, d);
  }
  const int step = ey1 - ey0 > 8 ? 2 : 1;
  for (int d = ey0; d <= ey1; ++d) {
    const double y = Y(std::pow(10.0, d));
    svg << fmt::format(
        "<line x1=\"{0:.1f}\" y1=\"{2:.1f}\" x2=\"{1:.1f}\" y2=\"{2:.1f}\" "
        "stroke=\"#ddd\"/>\n",
        x0, x0 + pw, y);
    if ((d - ey0) % step == 0) {
      svg << fmt::format(
          "<text x=\"{:.1f}\" y=\"{:.1f}\" font-size=\"11\" "
          "text-anchor=\"end\">1e{}</text>\n",
          x0 - 5, y + 4, d);
    }
  }
  svg << fmt::format(
      "<text x=\"{:.1f}\" y=\"{:.1f}\" font-size=\"12\" text-anchor=\"middle\">"
      "wall time of the run, s</text>\n",
      x0 + pw / 2, y0 + ph + 33);
  svg << fmt::format(
      "<text x=\"{0:.1f}\" y=\"{1:.1f}\" font-size=\"12\" text-anchor=\"middle\" "
      "transform=\"rotate(-90 {0:.1f} {1:.1f})\">error</text>\n",
      ox + 16, y0 + ph / 2);
  if (transient) {
    const double y = Y(0.01);
    svg << fmt::format(
        "<line x1=\"{0:.1f}\" y1=\"{2:.1f}\" x2=\"{1:.1f}\" y2=\"{2:.1f}\" "
        "stroke=\"#888\" stroke-dasharray=\"5,4\"/>\n",
        x0, x0 + pw, y);
    svg << fmt::format(
        "<text x=\"{:.1f}\" y=\"{:.1f}\" font-size=\"10\" fill=\"#666\" "
        "text-anchor=\"end\">1% error</text>\n",
        x0 + pw - 4, y - 3);
  }
  // The paper's scheme is drawn last, as rings: in T it lands exactly on the pore-volume runs.
  for (const bool paper : {false, true}) {
    for (const std::size_t i : runs) {
      if ((rows[i].solver == "explicit" && rows[i].storage == "apparent") != paper) continue;
      svg << Marker(StyleOf(rows[i].solver, rows[i].storage), X(rows[i].wall_s), Y(rows[i].error),
                    paper ? 5.0 : 3.5);
    }
  }
  std::string points;
  for (const std::size_t i : ParetoFront(rows, problem, resolution)) {
    points += fmt::format("{:.1f},{:.1f} ", X(rows[i].wall_s), Y(rows[i].error));
  }
  svg << fmt::format(
      "<polyline points=\"{}\" fill=\"none\" stroke=\"#000\" "
      "stroke-width=\"1.5\"/>\n",
      points);
}

}  // namespace

core::Status WriteSvgChart(const std::string& path, const std::vector<AccuracyRun>& rows) {
  // A panel per problem, then the last diffusion problem at its finest resolution: the case of a
  // DEM packing, whose resolution is not the user's choice.
  struct Panel {
    std::string problem;
    int resolution;
    std::string title;
  };
  std::vector<Panel> panels;
  std::string last_diffusion;
  for (const std::string& problem : Problems(rows)) {
    panels.push_back({problem, -1, problem});
    if (problem.rfind("diffusion", 0) == 0) last_diffusion = problem;
  }
  if (!last_diffusion.empty()) {
    int finest = -1;
    for (const AccuracyRun& r : rows) {
      if (r.problem == last_diffusion) finest = std::max(finest, r.resolution);
    }
    panels.push_back(
        {last_diffusion, finest, fmt::format("{}, {} domains along only", last_diffusion, finest)});
  }
  const int panel_rows = static_cast<int>((panels.size() + kColumns - 1) / kColumns);
  const double legend_h = 56.0;
  const double width = kColumns * kPanelW;
  const double height = panel_rows * kPanelH + legend_h;
  std::ostringstream svg;
  svg << fmt::format(
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{:.0f}\" height=\"{:.0f}\" "
      "viewBox=\"0 0 {:.0f} {:.0f}\" font-family=\"sans-serif\">\n",
      width, height, width, height);
  svg << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  for (std::size_t p = 0; p < panels.size(); ++p) {
    const double ox = static_cast<double>(p % kColumns) * kPanelW;
    const double oy = static_cast<double>(p / kColumns) * kPanelH;
    DrawPanel(svg, rows, panels[p].problem, panels[p].resolution, panels[p].title, ox, oy);
  }
  // Legend: the four marker styles and the front.
  const double ly = panel_rows * kPanelH + 22.0;
  const Style styles[] = {StyleOf("explicit", "apparent"), StyleOf("explicit", "pore"),
                          StyleOf("implicit", "pore"), StyleOf("steady", "-")};
  // Two rows of three entries, in fixed columns.
  const double columns_x[] = {20.0, 340.0, 600.0};
  double lx = columns_x[0];
  double row_y = ly;
  for (std::size_t k = 0; k <= std::size(styles); ++k) {
    lx = columns_x[k % 3];
    row_y = ly + (k < 3 ? 0.0 : 20.0);
    if (k == std::size(styles)) break;  // the front goes in the next slot
    svg << Marker(styles[k], lx, row_y, 5.0);
    svg << fmt::format("<text x=\"{:.1f}\" y=\"{:.1f}\" font-size=\"12\">{}</text>\n", lx + 10,
                       row_y + 4, styles[k].label);
  }
  lx += 5.0;
  svg << fmt::format(
      "<line x1=\"{:.1f}\" y1=\"{:.1f}\" x2=\"{:.1f}\" y2=\"{:.1f}\" "
      "stroke=\"#000\" stroke-width=\"1.5\"/>\n",
      lx - 5, row_y, lx + 20, row_y);
  svg << fmt::format("<text x=\"{:.1f}\" y=\"{:.1f}\" font-size=\"12\">Pareto front</text>\n",
                     lx + 26, row_y + 4);
  svg << "</svg>\n";
  std::ofstream f(path, std::ios::trunc);
  if (!f) return core::InvalidArgument(fmt::format("svg path {}: cannot open for writing", path));
  f << svg.str();
  f.flush();
  if (!f) return core::Internal(fmt::format("svg path {}: write failed", path));
  return core::Status::Ok();
}

}  // namespace seep::bench
