// SVG charts (see svg_chart.h): axis ranges and ticks, markers, series, legend.
#include "svg_chart.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <utility>

namespace seep::plot {
namespace {

constexpr double kMarginL = 70.0;
constexpr double kMarginR = 14.0;
constexpr double kMarginT = 30.0;
constexpr double kMarginB = 44.0;
constexpr double kLegendRowH = 20.0;

bool Usable(double v, Scale scale) {
  return std::isfinite(v) && (scale == Scale::kLinear || v > 0.0);
}

// The drawn range of an axis and its tick positions (in data units).
struct AxisMap {
  Scale scale = Scale::kLinear;
  double lo = 0.0;  // in log10 units for a log axis
  double hi = 1.0;
  std::vector<double> ticks;  // data values
  std::vector<std::string> tick_labels;

  double Fraction(double v) const {
    const double t = scale == Scale::kLog10 ? std::log10(v) : v;
    return (t - lo) / (hi - lo);
  }
};

AxisMap MapAxis(const Axis& axis, double data_min, double data_max) {
  AxisMap m;
  m.scale = axis.scale;
  double lo = data_min;
  double hi = data_max;
  if (Usable(axis.include_min, axis.scale)) lo = std::min(lo, axis.include_min);
  if (Usable(axis.include_max, axis.scale)) hi = std::max(hi, axis.include_max);
  if (!(lo <= hi)) {  // no data at all
    lo = axis.scale == Scale::kLog10 ? 1.0 : 0.0;
    hi = axis.scale == Scale::kLog10 ? 10.0 : 1.0;
  }
  if (axis.scale == Scale::kLog10) {
    // Whole decades, at least one wide; with many decades label every other one.
    const int a = static_cast<int>(std::floor(std::log10(lo)));
    int b = static_cast<int>(std::ceil(std::log10(hi)));
    if (b <= a) b = a + 1;
    m.lo = a;
    m.hi = b;
    const int every = b - a > 8 ? 2 : 1;
    for (int d = a; d <= b; ++d) {
      m.ticks.push_back(std::pow(10.0, d));
      m.tick_labels.push_back((d - a) % every == 0 ? fmt::format("1e{}", d) : "");
    }
    return m;
  }
  if (hi - lo <= 0.0) {
    const double pad = lo != 0.0 ? 0.1 * std::abs(lo) : 1.0;
    lo -= pad;
    hi += pad;
  }
  // About six ticks at 1, 2 or 5 times a power of ten.
  const double raw = (hi - lo) / 6.0;
  const double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
  double step = magnitude;
  for (const double f : {1.0, 2.0, 5.0, 10.0}) {
    step = f * magnitude;
    if (step >= raw) break;
  }
  const double first = std::floor(lo / step);
  const double last = std::ceil(hi / step);
  m.lo = first * step;
  m.hi = last * step;
  for (double k = first; k <= last; k += 1.0) {
    double v = k * step;
    if (std::abs(v) < 1e-9 * step) v = 0.0;
    m.ticks.push_back(v);
    m.tick_labels.push_back(fmt::format("{:.6g}", v));
  }
  return m;
}

std::string MarkerSvg(const Style& s, double x, double y) {
  const double size = s.marker_size;
  const std::string paint =
      fmt::format("fill=\"{}\" fill-opacity=\"0.55\" stroke=\"{}\"", s.colour, s.colour);
  switch (s.marker) {
    case Marker::kNone:
      return {};
    case Marker::kRing:
      return fmt::format(
          "<circle cx=\"{:.1f}\" cy=\"{:.1f}\" r=\"{:.1f}\" fill=\"none\" stroke=\"{}\" "
          "stroke-width=\"1.5\"/>\n",
          x, y, size, s.colour);
    case Marker::kCircle:
      return fmt::format("<circle cx=\"{:.1f}\" cy=\"{:.1f}\" r=\"{:.1f}\" {}/>\n", x, y, size,
                         paint);
    case Marker::kSquare:
      return fmt::format(
          "<rect x=\"{:.1f}\" y=\"{:.1f}\" width=\"{:.1f}\" height=\"{:.1f}\" {}/>\n", x - size,
          y - size, 2 * size, 2 * size, paint);
    case Marker::kTriangle:
      return fmt::format("<polygon points=\"{:.1f},{:.1f} {:.1f},{:.1f} {:.1f},{:.1f}\" {}/>\n", x,
                         y - 1.2 * size, x - size, y + 0.8 * size, x + size, y + 0.8 * size, paint);
    case Marker::kDiamond:
      return fmt::format(
          "<polygon points=\"{:.1f},{:.1f} {:.1f},{:.1f} {:.1f},{:.1f} {:.1f},{:.1f}\" {}/>\n", x,
          y - 1.3 * size, x + size, y, x, y + 1.3 * size, x - size, y, paint);
  }
  return {};
}

std::string LineAttributes(const Style& s) {
  return fmt::format("fill=\"none\" stroke=\"{}\" stroke-width=\"{:.1f}\"{}", s.colour,
                     s.line_width, s.dashed ? " stroke-dasharray=\"6,4\"" : "");
}

void DrawPanel(std::ostringstream& svg, const Panel& panel, double ox, double oy, double width,
               double height) {
  double xmin = HUGE_VAL, xmax = -HUGE_VAL, ymin = HUGE_VAL, ymax = -HUGE_VAL;
  bool any = false;
  for (const Series& s : panel.series) {
    for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      if (!Usable(s.x[i], panel.x.scale) || !Usable(s.y[i], panel.y.scale)) continue;
      any = true;
      xmin = std::min(xmin, s.x[i]);
      xmax = std::max(xmax, s.x[i]);
      ymin = std::min(ymin, s.y[i]);
      ymax = std::max(ymax, s.y[i]);
    }
  }
  const double pw = width - kMarginL - kMarginR;
  const double ph = height - kMarginT - kMarginB;
  const double x0 = ox + kMarginL;
  const double y0 = oy + kMarginT;
  svg << fmt::format(
      "<text x=\"{:.1f}\" y=\"{:.1f}\" font-size=\"14\" font-weight=\"bold\">{}</text>\n", x0,
      oy + 18, EscapeXml(panel.title));
  svg << fmt::format(
      "<rect x=\"{:.1f}\" y=\"{:.1f}\" width=\"{:.1f}\" height=\"{:.1f}\" fill=\"none\" "
      "stroke=\"#444\"/>\n",
      x0, y0, pw, ph);
  if (!any) {
    svg << fmt::format("<text x=\"{:.1f}\" y=\"{:.1f}\" font-size=\"13\">{}</text>\n", x0 + 20,
                       y0 + ph / 2, EscapeXml(panel.empty_note));
    return;
  }
  for (const Rule& r : panel.rules) {
    if (Usable(r.y, panel.y.scale)) {
      ymin = std::min(ymin, r.y);
      ymax = std::max(ymax, r.y);
    }
  }
  const AxisMap xm = MapAxis(panel.x, xmin, xmax);
  const AxisMap ym = MapAxis(panel.y, ymin, ymax);
  const auto X = [&](double v) { return x0 + pw * xm.Fraction(v); };
  const auto Y = [&](double v) { return y0 + ph * (1.0 - ym.Fraction(v)); };
  for (std::size_t k = 0; k < xm.ticks.size(); ++k) {
    const double x = X(xm.ticks[k]);
    svg << fmt::format(
        "<line x1=\"{0:.1f}\" y1=\"{1:.1f}\" x2=\"{0:.1f}\" y2=\"{2:.1f}\" stroke=\"#ddd\"/>\n", x,
        y0, y0 + ph);
    svg << fmt::format(
        "<text x=\"{:.1f}\" y=\"{:.1f}\" font-size=\"11\" text-anchor=\"middle\">{}</text>\n", x,
        y0 + ph + 15, xm.tick_labels[k]);
  }
  for (std::size_t k = 0; k < ym.ticks.size(); ++k) {
    const double y = Y(ym.ticks[k]);
    svg << fmt::format(
        "<line x1=\"{0:.1f}\" y1=\"{2:.1f}\" x2=\"{1:.1f}\" y2=\"{2:.1f}\" stroke=\"#ddd\"/>\n", x0,
        x0 + pw, y);
    svg << fmt::format(
        "<text x=\"{:.1f}\" y=\"{:.1f}\" font-size=\"11\" text-anchor=\"end\">{}</text>\n", x0 - 5,
        y + 4, ym.tick_labels[k]);
  }
  svg << fmt::format(
      "<text x=\"{:.1f}\" y=\"{:.1f}\" font-size=\"12\" text-anchor=\"middle\">{}</text>\n",
      x0 + pw / 2, y0 + ph + 33, EscapeXml(panel.x.label));
  svg << fmt::format(
      "<text x=\"{0:.1f}\" y=\"{1:.1f}\" font-size=\"12\" text-anchor=\"middle\" "
      "transform=\"rotate(-90 {0:.1f} {1:.1f})\">{2}</text>\n",
      ox + 14, y0 + ph / 2, EscapeXml(panel.y.label));
  for (const Rule& r : panel.rules) {
    if (!Usable(r.y, panel.y.scale)) continue;
    const double y = Y(r.y);
    svg << fmt::format(
        "<line x1=\"{0:.1f}\" y1=\"{2:.1f}\" x2=\"{1:.1f}\" y2=\"{2:.1f}\" stroke=\"#888\" "
        "stroke-dasharray=\"5,4\"/>\n",
        x0, x0 + pw, y);
    svg << fmt::format(
        "<text x=\"{:.1f}\" y=\"{:.1f}\" font-size=\"10\" fill=\"#666\" "
        "text-anchor=\"end\">{}</text>\n",
        x0 + pw - 4, y - 3, EscapeXml(r.label));
  }
  for (const Series& s : panel.series) {
    std::string points;
    std::string markers;
    for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      if (!Usable(s.x[i], panel.x.scale) || !Usable(s.y[i], panel.y.scale)) continue;
      points += fmt::format("{:.1f},{:.1f} ", X(s.x[i]), Y(s.y[i]));
      markers += MarkerSvg(s.style, X(s.x[i]), Y(s.y[i]));
    }
    if (s.style.line && !points.empty()) {
      svg << fmt::format("<polyline class=\"series\" data-label=\"{}\" points=\"{}\" {}/>\n",
                         EscapeXml(s.style.label), points, LineAttributes(s.style));
    }
    svg << markers;
  }
}

}  // namespace

std::string RenderSvg(const Chart& chart) {
  const int columns = std::max(chart.columns, 1);
  const auto panels = static_cast<int>(chart.panels.size());
  const int rows = std::max((panels + columns - 1) / columns, 1);
  const int legend_columns = std::max(chart.legend_columns, 1);
  const auto entries = static_cast<int>(chart.legend.size());
  const int legend_rows = (entries + legend_columns - 1) / legend_columns;
  const double legend_h = entries > 0 ? 16.0 + legend_rows * kLegendRowH : 0.0;
  const double width = columns * chart.panel_width;
  const double height = rows * chart.panel_height + legend_h;
  std::ostringstream svg;
  svg << fmt::format(
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{:.0f}\" height=\"{:.0f}\" "
      "viewBox=\"0 0 {:.0f} {:.0f}\" font-family=\"sans-serif\">\n",
      width, height, width, height);
  svg << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  for (int p = 0; p < panels; ++p) {
    DrawPanel(svg, chart.panels[static_cast<std::size_t>(p)], (p % columns) * chart.panel_width,
              (p / columns) * chart.panel_height, chart.panel_width, chart.panel_height);
  }
  // Legend: fixed columns, a sample of each style (a short line and/or its marker) and its label.
  const double column_w = (width - 20.0) / legend_columns;
  for (int k = 0; k < entries; ++k) {
    const Style& s = chart.legend[static_cast<std::size_t>(k)];
    const double lx = 20.0 + (k % legend_columns) * column_w;
    const double ly = rows * chart.panel_height + 22.0 + (k / legend_columns) * kLegendRowH;
    if (s.line) {
      svg << fmt::format("<line x1=\"{:.1f}\" y1=\"{:.1f}\" x2=\"{:.1f}\" y2=\"{:.1f}\" {}/>\n",
                         lx - 5, ly, lx + 20, ly, LineAttributes(s));
    }
    svg << MarkerSvg(s, s.line ? lx + 7.5 : lx, ly);
    svg << fmt::format("<text x=\"{:.1f}\" y=\"{:.1f}\" font-size=\"12\">{}</text>\n",
                       lx + (s.line ? 26.0 : 10.0), ly + 4, EscapeXml(s.label));
  }
  svg << "</svg>\n";
  return svg.str();
}

std::string EscapeXml(const std::string& text) {
  std::string out;
  for (const char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string WriteSvgFile(const std::string& path, const std::string& svg) {
  std::ofstream f(path, std::ios::trunc);
  if (!f) return fmt::format("svg path {}: cannot open for writing", path);
  f << svg;
  f.flush();
  if (!f) return fmt::format("svg path {}: write failed", path);
  return {};
}

}  // namespace seep::plot
