#include "job_printer.h"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <google/protobuf/util/time_util.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <map>
#include <optional>
#include <string_view>
#include <utility>
#include <vector>

namespace seep::client {
namespace {

std::string FormatTime(const google::protobuf::Timestamp& t) {
  if (t.seconds() == 0 && t.nanos() == 0) return "-";
  return google::protobuf::util::TimeUtil::ToString(t);
}

}  // namespace

std::string FormatStage(const v1::Progress& progress) {
  if (progress.stage_count() == 0) return "";
  std::string out = fmt::format("{}/{}", progress.stage_index(), progress.stage_count());
  if (!progress.stage_name().empty()) out += " " + progress.stage_name();
  return out;
}

std::string StateName(v1::JobState state) {
  std::string name = v1::JobState_Name(state);
  const std::string prefix = "JOB_STATE_";
  if (name.rfind(prefix, 0) == 0) name.erase(0, prefix.size());
  return name;
}

std::string FormatJob(const v1::Job& job) {
  std::string out = fmt::format("job       {}\nname      {}\nstate     {}\n", job.id(), job.name(),
                                StateName(job.state()));
  if (job.kind() == v1::JOB_KIND_CALIBRATION) out += "kind      CALIBRATION\n";
  out += fmt::format("created   {}\nstarted   {}\nfinished  {}\n", FormatTime(job.created_at()),
                     FormatTime(job.started_at()), FormatTime(job.finished_at()));
  if (job.kind() == v1::JOB_KIND_CALIBRATION) {
    out += fmt::format("progress  {} permeameter solves, {:.1f}%\n", job.progress().step(),
                       100.0 * job.progress().fraction_done());
  } else {
    out += fmt::format("progress  step {}, t = {:.6g} s, {:.1f}%\n", job.progress().step(),
                       job.progress().time_s(), 100.0 * job.progress().fraction_done());
  }
  if (const std::string stage = FormatStage(job.progress()); !stage.empty()) {
    out += fmt::format("stage     {}\n", stage);
  }
  out += fmt::format("build     {}\nattempt   {}\n", job.build_id(), job.attempt());
  if (job.priority() != 0) out += fmt::format("priority  {}\n", job.priority());
  if (!job.labels().empty()) out += fmt::format("labels    {}\n", FormatLabels(job));
  if (!job.parent_job_id().empty()) {
    out += fmt::format("parent    {} (step {})\n", job.parent_job_id(), job.parent_step());
  }
  if (!job.child_job_ids().empty()) {
    out += fmt::format("children  {}\n", fmt::join(job.child_job_ids(), ", "));
  }
  if (job.has_batch()) {
    // e.g. "slurm     job 4711 on node17, RUNNING"
    out += fmt::format("{:<9} job {}{}{}\n", job.batch().system(), job.batch().job_id(),
                       job.batch().node().empty() ? "" : " on " + job.batch().node(),
                       job.batch().state().empty() ? "" : ", " + job.batch().state());
  }
  if (job.cancel_requested() && job.state() == v1::JOB_STATE_RUNNING) {
    out += "cancel    requested; the job stops at its next step\n";
  }
  if (!job.held_reason().empty()) out += fmt::format("held      {}\n", job.held_reason());
  if (job.has_error()) {
    out += fmt::format("error     {}: {}\n", job.error().code(), job.error().message());
  }
  if (job.has_result()) {
    out += fmt::format("wall time {:.3f} s\nresult\n", job.result().wall_time_s());
    // Sorted by name: protobuf maps have no order.
    const std::map<std::string, double> metrics(job.result().metrics().begin(),
                                                job.result().metrics().end());
    for (const auto& [name, value] : metrics) out += fmt::format("  {:<28} {:.9g}\n", name, value);
    out += FormatAccuracyWarnings(metrics);
  }
  return out;
}

namespace {

// "stage2_X" -> ("2", "X"); nullopt for a name without a stage prefix.
std::optional<std::pair<std::string, std::string>> SplitStagePrefix(const std::string& name) {
  constexpr std::string_view kStage = "stage";
  if (name.rfind(kStage, 0) != 0) return std::nullopt;
  std::size_t i = kStage.size();
  while (i < name.size() && std::isdigit(static_cast<unsigned char>(name[i])) != 0) ++i;
  if (i == kStage.size() || i >= name.size() || name[i] != '_') return std::nullopt;
  return std::make_pair(name.substr(kStage.size(), i - kStage.size()), name.substr(i + 1));
}

}  // namespace

std::string FormatAccuracyWarnings(const std::map<std::string, double>& metrics) {
  // A metric X_safe_above (X_safe_below) carries the bound on the number X beside it below
  // (above) which the accuracy bench measured runs more than 5 % off real water
  // (seep::core::MeasureCouplingNumbers; not every run beyond it was): the client warns without
  // knowing the physics. A stage's copy ("stage2_X") warns for that stage, folded into X's line
  // when the whole run warns of X too (a staged scene would otherwise say it once per stage).
  struct Side {
    std::string_view suffix, word;
    bool below;  // the bound is a floor
  };
  constexpr Side kSides[] = {{"_safe_above", "below", true}, {"_safe_below", "above", false}};
  struct Warning {
    std::string number;
    double value, bound;
    std::string_view word;
  };
  std::vector<Warning> warnings;
  for (const auto& [name, bound] : metrics) {
    for (const Side& side : kSides) {
      const std::string_view suffix = side.suffix;
      if (name.size() <= suffix.size() ||
          name.compare(name.size() - suffix.size(), suffix.size(), suffix) != 0) {
        continue;
      }
      const std::string number = name.substr(0, name.size() - suffix.size());
      const auto it = metrics.find(number);
      if (it == metrics.end()) continue;
      const bool beyond = side.below ? it->second < bound : it->second > bound;
      if (beyond) warnings.push_back({number, it->second, bound, side.word});
    }
  }
  std::string out;
  for (const Warning& w : warnings) {
    if (const auto stage = SplitStagePrefix(w.number)) {
      const auto whole = std::find_if(warnings.begin(), warnings.end(),
                                      [&](const Warning& o) { return o.number == stage->second; });
      if (whole != warnings.end()) continue;  // folded into the whole run's line
    }
    std::vector<std::string> stages;
    for (const Warning& o : warnings) {
      const auto stage = SplitStagePrefix(o.number);
      if (stage && stage->second == w.number) stages.push_back(stage->first);
    }
    out += fmt::format(
        "warning   {} = {:.3g} is {} {:g}{}: the accuracy bench measured runs there more than 5 % "
        "off real water (docs/accuracy.md, \"Coupled runs\")\n",
        w.number, w.value, w.word, w.bound,
        stages.empty() ? "" : fmt::format(" (and in stage {})", fmt::join(stages, ", ")));
  }
  return out;
}

std::string FormatLabels(const v1::Job& job) {
  const std::map<std::string, std::string> sorted(job.labels().begin(), job.labels().end());
  std::string out;
  for (const auto& [key, value] : sorted) out += (out.empty() ? "" : ",") + key + "=" + value;
  return out;
}

std::string FormatJobEvent(const v1::JobHistoryEvent& event) {
  return fmt::format("{:<24}  {:<21} {}", FormatTime(event.at()), event.kind(), event.message());
}

std::string FormatResult(const v1::JobResult& result) {
  std::string out = fmt::format("{:<28} {}\n", "METRIC", "VALUE");
  const std::map<std::string, double> metrics(result.metrics().begin(), result.metrics().end());
  for (const auto& [name, value] : metrics) out += fmt::format("{:<28} {:.9g}\n", name, value);
  out += fmt::format("{:<28} {:.3f}\n", "wall_time_s", result.wall_time_s());
  out += FormatAccuracyWarnings(metrics);
  return out;
}

std::string FormatJobTableHeader() {
  return fmt::format("{:<20} {:<10} {:>7} {:<24} {}", "ID", "STATE", "DONE", "CREATED", "NAME");
}

std::string FormatJobRow(const v1::Job& job) {
  return fmt::format("{:<20} {:<10} {:>6.1f}% {:<24} {}", job.id(), StateName(job.state()),
                     100.0 * job.progress().fraction_done(), FormatTime(job.created_at()),
                     job.name());
}

std::string FormatProgress(const v1::Job& job) {
  const auto& p = job.progress();
  if (job.kind() == v1::JOB_KIND_CALIBRATION) {
    // A calibration has no simulated time: its step counts the permeameter solves.
    return fmt::format("{:<9} solves {:>4}  {:5.1f}%", StateName(job.state()), p.step(),
                       100.0 * p.fraction_done());
  }
  std::string line = fmt::format("{:<9} step {:>9}  t = {:<11.5g} {:5.1f}%", StateName(job.state()),
                                 p.step(), p.time_s(), 100.0 * p.fraction_done());
  if (const std::string stage = FormatStage(p); !stage.empty()) line += "  stage " + stage;
  if (p.eta_s() > 0.0) line += fmt::format("  ETA {:.1f} s", p.eta_s());
  // Key figures of the newest sample, when the server sends them (a running simulation).
  for (const char* key : {"inflow_m2_per_s", "outflow_m2_per_s", "well_flow_rate_m2_per_s",
                          "max_pressure_pa", "mass_balance_error"}) {
    if (const auto it = p.latest().find(key); it != p.latest().end()) {
      line += fmt::format("  {} {:.4g}", key, it->second);
    }
  }
  return line;
}

std::string FormatDuration(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0.0) return "?";
  if (seconds < 60.0) return fmt::format("{:.0f} s", std::max(seconds, 1.0));
  const auto whole = static_cast<long long>(std::llround(seconds));
  if (whole < 3600) return fmt::format("{}m{:02}s", whole / 60, whole % 60);
  return fmt::format("{}h{:02}m", whole / 3600, (whole % 3600) / 60);
}

std::string FormatProgressBar(const v1::Job& job, int columns) {
  const auto& p = job.progress();
  const double fraction = std::clamp(p.fraction_done(), 0.0, 1.0);
  constexpr int kBarWidth = 24;
  const int filled = static_cast<int>(std::floor(fraction * kBarWidth));
  std::string line =
      fmt::format("{:<9} [{}{}] {:5.1f}%", StateName(job.state()),
                  std::string(static_cast<std::size_t>(filled), '#'),
                  std::string(static_cast<std::size_t>(kBarWidth - filled), '.'), 100.0 * fraction);
  // Before step and time: the line is cut at the terminal's width, and the stage matters more.
  if (const std::string stage = FormatStage(p); !stage.empty()) line += "  stage " + stage;
  if (job.kind() == v1::JOB_KIND_CALIBRATION) {
    line += fmt::format("  solves {}", p.step());
  } else {
    line += fmt::format("  step {}  t = {:.4g} s", p.step(), p.time_s());
  }
  if (p.eta_s() > 0.0 && job.state() == v1::JOB_STATE_RUNNING) {
    line += "  ETA " + FormatDuration(p.eta_s());
  }
  // Short names: the bar has one line for everything.
  static constexpr std::pair<const char*, const char*> kKeyMetrics[] = {
      {"inflow_m2_per_s", "q_in"},
      {"outflow_m2_per_s", "q_out"},
      {"well_flow_rate_m2_per_s", "q_well"},
      {"max_pressure_pa", "p_max"},
      {"mass_balance_error", "mass_err"}};
  for (const auto& [key, label] : kKeyMetrics) {
    if (const auto it = p.latest().find(key); it != p.latest().end()) {
      line += fmt::format("  {} {:.3g}", label, it->second);
    }
  }
  if (columns > 1 && static_cast<int>(line.size()) >= columns) {
    line.resize(static_cast<std::size_t>(columns - 1));
  }
  return line;
}

}  // namespace seep::client
