#include "sweep_plot.h"

#include <fmt/format.h>

#include <algorithm>
#include <map>
#include <numeric>

#include "sweep_table.h"

namespace seep::client {
namespace {

std::string Joined(const google::protobuf::RepeatedPtrField<std::string>& names) {
  std::string out;
  for (const std::string& n : names) {
    if (!out.empty()) out += ", ";
    out += n;
  }
  return out;
}

// The other parameters' values of a job: the name of the line it belongs to.
std::string GroupName(const v1::SweepJob& member, int x_index,
                      const google::protobuf::RepeatedPtrField<std::string>& parameters) {
  std::string name;
  for (int i = 0; i < member.settings_size() && i < parameters.size(); ++i) {
    if (i == x_index) continue;
    name += fmt::format("{}{} = {}", name.empty() ? "" : ", ", parameters[i],
                        SettingText(member.settings(i)));
  }
  return name;
}

}  // namespace

plot::Chart SweepChart(const v1::SweepStatus& sweep, const SweepChartRequest& request,
                       std::string* error) {
  const std::string& x_path = request.x_path;
  const std::string& y_metric = request.y_metric;
  const auto& parameters = sweep.parameters();
  const auto found = std::find(parameters.begin(), parameters.end(), x_path);
  if (found == parameters.end()) {
    *error = fmt::format("--x {}: not a swept parameter of sweep {} (its parameters: {})", x_path,
                         sweep.id(), Joined(parameters));
    return {};
  }
  const int x_index = static_cast<int>(found - parameters.begin());
  // Lines in the order their first job comes, points along each in order of x.
  std::vector<std::string> order;
  std::map<std::string, std::vector<std::pair<double, double>>> lines;
  bool any_metric = false;
  for (const v1::SweepJob& member : sweep.jobs()) {
    if (member.settings_size() <= x_index) continue;
    const v1::SweepSetting& x = member.settings(x_index);
    if (!x.has_number()) {
      *error =
          fmt::format("--x {}: its values are not numbers (e.g. '{}')", x_path, SettingText(x));
      return {};
    }
    if (member.job().state() != v1::JOB_STATE_SUCCEEDED) continue;
    const auto& metrics = member.job().result().metrics();
    const auto y = metrics.find(y_metric);
    if (y == metrics.end()) continue;
    any_metric = true;
    const std::string group = GroupName(member, x_index, parameters);
    if (lines.find(group) == lines.end()) order.push_back(group);
    lines[group].emplace_back(x.number(), y->second);
  }
  if (!any_metric) {
    *error =
        fmt::format("--y {}: no succeeded job of sweep {} has this metric", y_metric, sweep.id());
    return {};
  }
  const char* colours[] = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b"};
  const plot::Marker markers[] = {plot::Marker::kCircle, plot::Marker::kSquare,
                                  plot::Marker::kTriangle, plot::Marker::kDiamond};
  plot::Panel panel;
  panel.title = fmt::format("{} against {}", y_metric, x_path);  // the file names the sweep
  panel.x.label = x_path;
  panel.y.label = y_metric;
  if (request.log_x) panel.x.scale = plot::Scale::kLog10;
  if (request.log_y) panel.y.scale = plot::Scale::kLog10;
  panel.empty_note = "no succeeded jobs";
  plot::Chart chart;
  chart.panel_width = 720.0;
  chart.panel_height = 440.0;
  for (std::size_t k = 0; k < order.size(); ++k) {
    auto points = lines[order[k]];
    std::stable_sort(points.begin(), points.end());
    plot::Series series;
    series.style.label = order[k].empty() ? y_metric : order[k];
    series.style.colour = colours[k % std::size(colours)];
    series.style.marker = markers[k % std::size(markers)];
    series.style.line = true;
    for (const auto& [x, y] : points) {
      series.x.push_back(x);
      series.y.push_back(y);
    }
    chart.legend.push_back(series.style);
    panel.series.push_back(std::move(series));
  }
  chart.legend_columns = order.size() > 2 ? 2 : 1;
  chart.panels.push_back(std::move(panel));
  return chart;
}

}  // namespace seep::client
