// SVG charts written by hand (no plotting library in Debian that fits a CLI without a GUI): a
// grid of panels, each with scatter and line series on linear or log10 axes, optional dashed
// horizontal rules, and a legend under the panels. Used by the accuracy bench (error versus wall
// time) and by `seep plot` (pressure profiles and time series).
#pragma once

#include <limits>
#include <string>
#include <vector>

namespace seep::plot {

enum class Scale { kLinear, kLog10 };
enum class Marker { kNone, kRing, kCircle, kSquare, kTriangle, kDiamond };

struct Style {
  std::string label;  // legend text; empty = not in the legend
  std::string colour = "#000000";
  Marker marker = Marker::kNone;
  double marker_size = 3.5;
  bool line = false;  // join the points in the given order
  bool dashed = false;
  double line_width = 1.5;
};

struct Series {
  Style style;
  std::vector<double> x;
  std::vector<double> y;  // non-finite points (and <= 0 on a log axis) are skipped
};

struct Axis {
  std::string label;
  Scale scale = Scale::kLinear;
  // The axis covers at least [include_min, include_max] besides the data (NaN = no demand).
  double include_min = std::numeric_limits<double>::quiet_NaN();
  double include_max = std::numeric_limits<double>::quiet_NaN();
};

// A dashed horizontal line across a panel, labelled at its right end.
struct Rule {
  double y = 0.0;
  std::string label;
};

struct Panel {
  std::string title;
  Axis x;
  Axis y;
  std::vector<Series> series;  // drawn in order: later ones on top
  std::vector<Rule> rules;
  std::string empty_note;  // shown when no series has a point
};

struct Chart {
  std::vector<Panel> panels;
  int columns = 1;
  double panel_width = 460.0;
  double panel_height = 330.0;
  std::vector<Style> legend;  // entries under the panels
  int legend_columns = 3;
};

// The whole document, starting with <svg ...>.
std::string RenderSvg(const Chart& chart);

// `text` with &, <, > and " escaped, for SVG text and attribute values.
std::string EscapeXml(const std::string& text);

// Writes `svg` to `path`; returns an empty string, or what went wrong ("svg path X: ...").
std::string WriteSvgFile(const std::string& path, const std::string& svg);

}  // namespace seep::plot
