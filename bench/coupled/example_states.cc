// seep_example_states: the "no regression" check of issue 19. Runs every example scene of
// examples/ in process (as a seepd worker does: the CLI's reader, the service's codec,
// Simulation::Create and Run) and prints, per example, the SHA-256 of its final state (the bytes
// a job's result hash covers) and its metrics, as JSON lines.
//
//   seep_example_states [--threads N] > before.jsonl     record (on the build before a change)
//   seep_example_states --compare before.jsonl           check a build against a record
//
// --compare passes an example whose hash is unchanged, or whose hash changed but every metric
// is within --tolerance (default 1e-12, issue 19's bound for an unavoidable change of summation
// order) of the record: relative, or absolute for the error metrics (MetricDifference); it prints
// the largest relative difference either way, and fails on a missing metric or example. Sweeps and
// calibrations are skipped: their scenes are the examples' others.
//
//   seep_example_states --nudge-bulk-modulus --compare before.jsonl
//
// runs every scene with its fluid's bulk modulus one ulp higher (2.2e-16 of it): a change of
// the input as small as one rounding, so the metric differences it prints are what any change
// of rounding in the fluid passes (a summation order, a fused pass) may do to each example.
// Coupled examples with contacts that open and close amplify it far beyond 1e-12 (the figures:
// docs/performance.md §4), which is why the fluid passes keep their arithmetic bit for bit.
#include <fmt/format.h>
#include <omp.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "codec/scene_codec.h"
#include "codec/simulation_state_codec.h"
#include "scene_file.h"
#include "seep/core/run/simulation.h"
#include "seep/v1/scene.pb.h"
#include "store/sha256.h"

namespace {

struct ExampleState {
  std::string name;
  std::string sha256;
  std::map<std::string, double> metrics;
  double seconds = 0.0;
};

// Scene files only: a sweep or calibration file does not parse as a Scene.
std::vector<std::filesystem::path> SceneFiles(const std::string& folder) {
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) {
    if (entry.path().extension() != ".textproto") continue;
    seep::v1::Scene scene;
    if (!seep::client::LoadSceneFile(entry.path().string(), &scene).empty()) continue;
    files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

std::optional<ExampleState> Run(const std::filesystem::path& path, bool nudge_bulk_modulus) {
  seep::v1::Scene scene;
  if (const std::string error = seep::client::LoadSceneFile(path.string(), &scene);
      !error.empty()) {
    std::fprintf(stderr, "%s\n", error.c_str());
    return std::nullopt;
  }
  const auto start = std::chrono::steady_clock::now();
  auto spec = seep::service::DecodeScene(scene);
  if (spec.ok() && nudge_bulk_modulus) {
    double& bulk = spec->fluid.bulk_modulus_pa;
    bulk = std::nextafter(bulk, std::numeric_limits<double>::infinity());
  }
  auto sim = spec.ok() ? seep::core::Simulation::Create(*spec)
                       : seep::core::Result<seep::core::Simulation>(spec.status());
  if (!sim.ok()) {
    std::fprintf(stderr, "%s: %s\n", path.c_str(), sim.status().ToString().c_str());
    return std::nullopt;
  }
  if (const seep::core::Status ran = sim->Run({}); !ran.ok()) {
    std::fprintf(stderr, "%s: %s\n", path.c_str(), ran.ToString().c_str());
    return std::nullopt;
  }
  ExampleState out;
  out.name = path.stem().string();
  out.sha256 =
      seep::service::HexSha256(seep::service::SerializeSimulationState(sim->TakeSnapshot()));
  for (const auto& [name, value] : sim->Report().metrics) out.metrics[name] = value;
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

nlohmann::json ToJson(const ExampleState& s) {
  return {{"example", s.name}, {"state_sha256", s.sha256}, {"metrics", s.metrics}};
}

// The difference of a metric between two builds: relative, except for the error metrics
// (mass_balance_error, fluid_balance_error, ...). Those are already dimensionless fractions at
// round-off level (1e-16 to 1e-13), so any change of summation order changes them by 100 % of
// themselves; their absolute difference is what says whether the books still close.
double MetricDifference(const std::string& name, double a, double b) {
  if (a == b) return 0.0;
  if (std::isnan(a) && std::isnan(b)) return 0.0;
  if (name.find("error") != std::string::npos) return std::abs(a - b);
  return std::abs(a - b) / std::max({std::abs(a), std::abs(b), 1e-300});
}

// Prints the comparison of one example; true when it passes.
bool Compare(const ExampleState& now, const nlohmann::json& record, double tolerance,
             bool verbose) {
  const bool same_hash = record.at("state_sha256").get<std::string>() == now.sha256;
  double worst = 0.0;
  std::string worst_name = "-";
  bool missing = false;
  for (const auto& [name, value] : record.at("metrics").items()) {
    const auto it = now.metrics.find(name);
    if (it == now.metrics.end()) {
      std::printf("  %s: metric %s missing\n", now.name.c_str(), name.c_str());
      missing = true;
      continue;
    }
    // JSON has no NaN: nlohmann writes it as null.
    const double recorded = value.is_null() ? std::nan("") : value.get<double>();
    const double d = MetricDifference(name, recorded, it->second);
    if (verbose && d > tolerance) {
      std::printf("  %s: %s %.17g -> %.17g (%.3g)\n", now.name.c_str(), name.c_str(), recorded,
                  it->second, d);
    }
    if (d > worst || std::isnan(d)) {
      worst = d;
      worst_name = name;
    }
  }
  const bool pass = !missing && (same_hash || worst <= tolerance);
  std::printf("%-28s %s  largest metric difference %.3g (%s)  %.1f s  %s\n", now.name.c_str(),
              same_hash ? "hash unchanged" : "HASH CHANGED  ", worst, worst_name.c_str(),
              now.seconds, pass ? "PASS" : "FAIL");
  return pass;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"seep_example_states: every example's final-state hash and metrics (issue 19)"};
  std::string examples = SEEP_EXAMPLES_DIR;
  std::string compare;
  int threads = 1;
  double tolerance = 1e-12;
  std::vector<std::string> only;
  bool verbose = false;
  bool nudge_bulk_modulus = false;
  app.add_option("--examples", examples, "the examples folder");
  app.add_option("--compare", compare, "a record (JSON lines) to check against")
      ->check(CLI::ExistingFile);
  app.add_option("--threads", threads, "OpenMP threads of the runs")->check(CLI::Range(1, 256));
  app.add_option("--tolerance", tolerance, "largest relative metric difference of a changed hash");
  app.add_option("--only", only, "example names (file stems) to run; default all");
  app.add_flag("--verbose", verbose, "list every metric beyond the tolerance");
  app.add_flag("--nudge-bulk-modulus", nudge_bulk_modulus,
               "run each scene with its fluid bulk modulus one ulp higher (sensitivity to one "
               "rounding)");
  CLI11_PARSE(app, argc, argv);
  omp_set_num_threads(threads);

  std::map<std::string, nlohmann::json> record;
  if (!compare.empty()) {
    std::ifstream in(compare);
    for (std::string line; std::getline(in, line);) {
      if (line.empty()) continue;
      nlohmann::json j = nlohmann::json::parse(line);
      record[j.at("example").get<std::string>()] = j;
    }
  }
  bool all_pass = true;
  int compared = 0;
  for (const auto& path : SceneFiles(examples)) {
    const std::string name = path.stem().string();
    if (!only.empty() && std::find(only.begin(), only.end(), name) == only.end()) continue;
    const std::optional<ExampleState> state = Run(path, nudge_bulk_modulus);
    if (!state) {
      all_pass = false;
      continue;
    }
    if (compare.empty()) {
      std::printf("%s\n", ToJson(*state).dump().c_str());
      std::fflush(stdout);
      continue;
    }
    const auto it = record.find(name);
    if (it == record.end()) {
      std::printf("%-28s not in the record  FAIL\n", name.c_str());
      all_pass = false;
      continue;
    }
    all_pass = Compare(*state, it->second, tolerance, verbose) && all_pass;
    ++compared;
  }
  if (!compare.empty()) {
    std::printf("%d example(s) compared: %s\n", compared, all_pass ? "PASS" : "FAIL");
  }
  return all_pass ? 0 : 1;
}
