#include "sweep_table.h"

#include <fmt/format.h>

#include <algorithm>
#include <optional>
#include <set>

#include "job_printer.h"

namespace seep::client {
namespace {

std::optional<double> Metric(const v1::SweepJob& member, const std::string& name) {
  const auto& metrics = member.job().result().metrics();
  const auto it = metrics.find(name);
  if (it == metrics.end()) return std::nullopt;
  return it->second;
}

std::string SweepStateWord(const v1::SweepStatus& sweep) {
  const v1::SweepCounts& c = sweep.counts();
  if (c.running() > 0) return "RUNNING";
  if (c.queued() > 0) return "QUEUED";
  if (c.failed() == 0 && c.cancelled() == 0) return "SUCCEEDED";
  return "FINISHED";
}

// Every cell of the table as text, header row first.
std::vector<std::vector<std::string>> Cells(const v1::SweepStatus& sweep,
                                            const std::vector<std::string>& metrics, bool csv) {
  std::vector<std::vector<std::string>> rows;
  std::vector<std::string> header;
  if (csv) {
    header = {"position", "job_id", "state"};
  } else {
    header = {"POSITION", "JOB", "STATE"};
  }
  for (const std::string& p : sweep.parameters()) header.push_back(p);
  for (const std::string& m : metrics) header.push_back(m);
  rows.push_back(std::move(header));
  for (const v1::SweepJob& member : sweep.jobs()) {
    std::vector<std::string> row = {std::to_string(member.position()), member.job().id(),
                                    StateName(member.job().state())};
    for (const v1::SweepSetting& setting : member.settings()) row.push_back(SettingText(setting));
    for (const std::string& m : metrics) {
      const std::optional<double> value = Metric(member, m);
      row.push_back(!value ? (csv ? "" : "-")
                    : csv  ? fmt::format("{}", *value)
                           : fmt::format("{:.9g}", *value));
    }
    rows.push_back(std::move(row));
  }
  return rows;
}

// A CSV field, quoted when it holds a comma, a quote or a line break.
std::string CsvField(const std::string& text) {
  if (text.find_first_of(",\"\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (const char c : text) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
  return quoted + "\"";
}

}  // namespace

std::string SettingText(const v1::SweepSetting& setting) {
  switch (setting.value_case()) {
    case v1::SweepSetting::kNumber:
      return fmt::format("{}", setting.number());
    case v1::SweepSetting::kText:
      return setting.text();
    case v1::SweepSetting::kFlag:
      return setting.flag() ? "true" : "false";
    case v1::SweepSetting::VALUE_NOT_SET:
      break;
  }
  return "";
}

bool SweepFinished(const v1::SweepStatus& sweep) {
  return sweep.counts().queued() == 0 && sweep.counts().running() == 0;
}

std::string FormatSweepProgress(const v1::SweepStatus& sweep) {
  const v1::SweepCounts& c = sweep.counts();
  return fmt::format(
      "{:<9} {:5.1f}%  sweep {}  {} jobs: {} queued, {} running, {} succeeded, {} failed, {} "
      "cancelled",
      SweepStateWord(sweep), 100.0 * sweep.fraction_done(), sweep.id(), sweep.jobs_size(),
      c.queued(), c.running(), c.succeeded(), c.failed(), c.cancelled());
}

std::vector<std::string> SweepMetricColumns(const v1::SweepStatus& sweep,
                                            const std::vector<std::string>& requested,
                                            std::string* error) {
  std::set<std::string> present;
  for (const v1::SweepJob& member : sweep.jobs()) {
    for (const auto& [name, value] : member.job().result().metrics()) present.insert(name);
  }
  if (requested.empty()) return {present.begin(), present.end()};
  for (const std::string& name : requested) {
    if (!present.empty() && present.count(name) == 0) {
      std::string known;
      for (const std::string& p : present) {
        if (!known.empty()) known += ", ";
        known += p;
      }
      *error = fmt::format("--metrics {}: no job of sweep {} has this metric (they have: {})", name,
                           sweep.id(), known);
      return {};
    }
  }
  return requested;
}

std::string FormatSweepTable(const v1::SweepStatus& sweep,
                             const std::vector<std::string>& metrics) {
  const auto rows = Cells(sweep, metrics, /*csv=*/false);
  std::vector<std::size_t> widths(rows.front().size(), 0);
  for (const auto& row : rows) {
    for (std::size_t c = 0; c < row.size(); ++c) widths[c] = std::max(widths[c], row[c].size());
  }
  std::string out;
  for (const auto& row : rows) {
    std::string line;
    for (std::size_t c = 0; c < row.size(); ++c) {
      line += c + 1 == row.size() ? row[c] : fmt::format("{:<{}}  ", row[c], widths[c]);
    }
    out += line + "\n";
  }
  return out;
}

std::string FormatSweepCsv(const v1::SweepStatus& sweep, const std::vector<std::string>& metrics) {
  std::string out;
  for (const auto& row : Cells(sweep, metrics, /*csv=*/true)) {
    for (std::size_t c = 0; c < row.size(); ++c) {
      if (c > 0) out += ',';
      out += CsvField(row[c]);
    }
    out += "\n";
  }
  return out;
}

}  // namespace seep::client
