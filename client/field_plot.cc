// Charts of `seep plot` (see field_plot.h).
#include "field_plot.h"

#include <fmt/format.h>

#include <algorithm>
#include <cstddef>
#include <numeric>

namespace seep::client {
namespace {

plot::Style MakeStyle(const std::string& label, const char* colour, plot::Marker marker,
                      bool line) {
  plot::Style s;
  s.label = label;
  s.colour = colour;
  s.marker = marker;
  s.line = line;
  return s;
}

}  // namespace

plot::Chart ProfileChart(const std::string& job_id, const v1::GetJobFieldsResponse& response) {
  const v1::JobFields& f = response.fields();
  const bool analytic = !f.analytic_kind().empty() &&
                        f.domain_analytic_pressure_pa_size() == f.domain_pressure_pa_size() &&
                        f.domain_axis_coordinate_m_size() == f.domain_pressure_pa_size();
  const auto n = static_cast<std::size_t>(f.domain_pressure_pa_size());
  plot::Series computed;
  computed.style = MakeStyle("domain pressure", "#1f77b4", plot::Marker::kCircle, false);
  computed.style.marker_size = 2.5;
  for (std::size_t d = 0; d < n; ++d) {
    const int i = static_cast<int>(d);
    computed.x.push_back(analytic ? f.domain_axis_coordinate_m(i) : f.domain_centroid_x_m(i));
    computed.y.push_back(f.domain_pressure_pa(i));
  }
  plot::Panel panel;
  panel.title = fmt::format("job {}: pressure at step {} (t = {:.6g} s)", job_id, response.step(),
                            response.time_s());
  if (!analytic) {
    panel.x.label = "centroid x, m";
  } else if (f.axis_name() == "r") {
    panel.x.label = "distance from the well centre, m";
  } else {
    panel.x.label = fmt::format("distance along {} from the inlet reservoir, m", f.axis_name());
  }
  panel.y.label = "pressure, Pa";
  panel.empty_note = "no domains";
  panel.series.push_back(computed);
  plot::Chart chart;
  chart.panel_width = 720.0;
  chart.panel_height = 440.0;
  chart.legend.push_back(computed.style);
  if (analytic) {
    // The analytic pressure at the domains, joined in order of the coordinate.
    std::vector<std::size_t> order(n);
    std::iota(order.begin(), order.end(), std::size_t{0});
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
      return f.domain_axis_coordinate_m(static_cast<int>(a)) <
             f.domain_axis_coordinate_m(static_cast<int>(b));
    });
    plot::Series curve;
    curve.style = MakeStyle(fmt::format("analytic ({})", f.analytic_kind()), "#d62728",
                            plot::Marker::kNone, true);
    for (const std::size_t d : order) {
      curve.x.push_back(f.domain_axis_coordinate_m(static_cast<int>(d)));
      curve.y.push_back(f.domain_analytic_pressure_pa(static_cast<int>(d)));
    }
    panel.series.push_back(curve);
    chart.legend.push_back(curve.style);
  }
  chart.panels.push_back(std::move(panel));
  return chart;
}

plot::Chart SeriesChart(const std::string& job_id, const v1::TimeSeries& series,
                        const std::vector<std::string>& columns, std::string* error) {
  const auto width = static_cast<std::size_t>(series.columns_size());
  const auto column_of = [&](const std::string& name) -> int {
    for (int c = 0; c < series.columns_size(); ++c) {
      if (series.columns(c) == name) return c;
    }
    return -1;
  };
  std::vector<std::string> wanted = columns;
  if (wanted.empty()) {
    for (const std::string& c : series.columns()) {
      if (c != "time_s") wanted.push_back(c);
    }
  }
  const int time_column = column_of("time_s");
  for (const std::string& name : wanted) {
    if (column_of(name) < 0 || time_column < 0) {
      std::string available;
      for (const std::string& c : series.columns()) {
        if (!available.empty()) available += ", ";
        available += c;
      }
      *error = fmt::format("--column {}: not a column of job {}'s time series (columns: {})", name,
                           job_id, available.empty() ? "none" : available);
      return {};
    }
  }
  const char* colours[] = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b"};
  plot::Chart chart;
  chart.columns = wanted.size() > 1 ? 2 : 1;
  const std::size_t rows = width == 0 ? 0 : static_cast<std::size_t>(series.values_size()) / width;
  for (std::size_t k = 0; k < wanted.size(); ++k) {
    const auto c = static_cast<std::size_t>(column_of(wanted[k]));
    plot::Series line;
    line.style = MakeStyle(wanted[k], colours[k % std::size(colours)], plot::Marker::kCircle, true);
    line.style.marker_size = 2.0;
    for (std::size_t r = 0; r < rows; ++r) {
      line.x.push_back(series.values(static_cast<int>(r * width) + time_column));
      line.y.push_back(series.values(static_cast<int>(r * width + c)));
    }
    plot::Panel panel;
    panel.title = fmt::format("job {}: {}", job_id, wanted[k]);
    panel.x.label = "time, s";
    panel.y.label = wanted[k];
    panel.empty_note = "no samples";
    panel.series.push_back(std::move(line));
    chart.panels.push_back(std::move(panel));
  }
  return chart;
}

}  // namespace seep::client
