// seep_stable_step_probe: how fast a coupled scene's disturbances grow, against its step and its
// fluid (issue 49: the cause of real water's instability shown, not assumed).
//
//   seep_stable_step_probe SCENE [--bulk-modulus PA] [--dt-safety S] [--implicit]
//                          [--alpha A] [--damping-ratio Z] [--steps N] [--every K]
//
// Runs the scene in process (the CLI's reader, the service's codec, Simulation) for N steps and
// prints every K steps: the time, the broken bonds, the checkerboard amplitude (the largest
// |p_d - mean of its neighbours' p| over free domains: a row-alternating mode makes it grow while
// a smooth field keeps it near the field's curvature), the kinetic energy, and each wall's stress
// columns, speed, fluid stiffness and stress, and the energy guard's ratio (run/energy_guard.h:
// (K + E_f) / (E_0 + W), which fails the run above EnergyGuard::kAllowedRatio); at the end, the
// run's metrics.
// At the end it prints the process's peak resident memory, per particle (what seepd's admission
// estimate at submit, codec/state_size_estimate.h, rests on), and fits the checkerboard's growth
// rate (per step and per second) over the last half
// of the rows: > 0 and steady is an instability, and its rate against the step is what tells a
// step limit from a physical growth.
#include <fmt/format.h>
#include <sys/resource.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "codec/scene_codec.h"
#include "scene_file.h"
#include "seep/core/run/reversal_guard.h"
#include "seep/core/run/simulation.h"
#include "seep/v1/scene.pb.h"

namespace {

using seep::core::DomainRole;
using seep::core::Simulation;

// The largest |p_d - mean of the neighbours' p| over free domains with at least one neighbour.
double CheckerboardAmplitude(const Simulation& sim) {
  const seep::core::FlowNetwork& flow = sim.network().flow;
  const auto p = flow.pressure();
  const auto role = flow.role();
  const auto a = flow.pipe_domain_a();
  const auto b = flow.pipe_domain_b();
  std::vector<double> sum(p.size(), 0.0);
  std::vector<int> count(p.size(), 0);
  for (std::size_t k = 0; k < a.size(); ++k) {
    sum[a[k]] += p[b[k]];
    sum[b[k]] += p[a[k]];
    ++count[a[k]];
    ++count[b[k]];
  }
  double worst = 0.0;
  for (std::size_t d = 0; d < p.size(); ++d) {
    if (role[d] != DomainRole::kFree || count[d] == 0) continue;
    worst = std::max(worst, std::abs(p[d] - sum[d] / count[d]));
  }
  return worst;
}

// The value of a series column in the newest sample, NaN when the scene has none.
double Column(const Simulation& sim, const std::string& name) {
  const std::vector<std::string>& columns = sim.series().columns;
  const auto it = std::find(columns.begin(), columns.end(), name);
  if (it == columns.end()) return std::nan("");
  return sim.latest_sample()[static_cast<std::size_t>(it - columns.begin())];
}

struct Row {
  std::uint64_t step;
  double time_s;
  double checkerboard;
};

// The least-squares slope of log(checkerboard) against x over the last half of the rows.
double GrowthRate(const std::vector<Row>& rows, bool per_second) {
  const std::size_t first = rows.size() / 2;
  double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (std::size_t k = first; k < rows.size(); ++k) {
    if (!(rows[k].checkerboard > 0.0)) continue;
    const double x = per_second ? rows[k].time_s : static_cast<double>(rows[k].step);
    const double y = std::log(rows[k].checkerboard);
    n += 1;
    sx += x;
    sy += y;
    sxx += x * x;
    sxy += x * y;
  }
  if (n < 2) return std::nan("");
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"seep_stable_step_probe: growth of a coupled scene's disturbances (issue 49)"};
  std::string scene_path;
  double bulk_modulus = 0.0;
  double dt_safety = 0.0;
  bool implicit = false;
  std::uint64_t steps = 20000;
  std::uint64_t every = 500;
  double alpha = -1.0;
  double damping_ratio = -1.0;
  app.add_option("scene", scene_path, "a scene file (.textproto or .json)")->required();
  app.add_option("--bulk-modulus", bulk_modulus, "the fluid's K_f, Pa (default: the scene's)");
  app.add_option("--dt-safety", dt_safety, "contacts.dt_safety (default: the scene's)");
  app.add_flag("--implicit", implicit, "the implicit flow solver instead of the scene's");
  app.add_option("--steps", steps, "steps to run");
  app.add_option("--every", every, "steps between rows");
  app.add_option("--alpha", alpha, "local damping's alpha (default: the scene's)");
  app.add_option("--damping-ratio", damping_ratio,
                 "the contacts' damping ratio (default: the scene's)");
  CLI11_PARSE(app, argc, argv);

  seep::v1::Scene message;
  if (const std::string error = seep::client::LoadSceneFile(scene_path, &message); !error.empty()) {
    std::fprintf(stderr, "%s\n", error.c_str());
    return 2;
  }
  auto spec = seep::service::DecodeScene(message);
  if (!spec.ok()) {
    std::fprintf(stderr, "%s\n", spec.status().ToString().c_str());
    return 2;
  }
  if (bulk_modulus > 0.0) spec->fluid.bulk_modulus_pa = bulk_modulus;
  if (implicit) spec->solver.kind = seep::core::SolverKind::kImplicit;
  for (seep::core::EffectSpec& e : spec->effects) {
    if (auto* c = std::get_if<seep::core::ContactsEffectSpec>(&e)) {
      if (dt_safety > 0.0) c->dt_safety = dt_safety;
      if (damping_ratio >= 0.0) c->law.damping_ratio = damping_ratio;
    }
    if (auto* d = std::get_if<seep::core::LocalDampingEffectSpec>(&e); d && alpha >= 0.0) {
      d->alpha = alpha;
    }
  }
  auto sim = Simulation::Create(*spec);
  if (!sim.ok()) {
    std::fprintf(stderr, "%s\n", sim.status().ToString().c_str());
    return 2;
  }
  std::printf("# %s\n# K_f %.4g Pa, dt %.6g s\n", sim->stepper().Describe().c_str(),
              spec->fluid.bulk_modulus_pa, sim->dt_s());
  std::vector<std::string> wall_columns;
  for (const std::string& c : sim->series().columns) {
    if (c.find("_wall_") != std::string::npos && c.find("stress") != std::string::npos) {
      wall_columns.push_back(c);
    }
  }
  std::printf("%10s %12s %8s %12s %12s %10s %10s", "step", "time_s", "broken", "checker_pa",
              "kinetic_j", "energy_ratio", "reversal");
  for (const std::string& c : wall_columns) std::printf(" %s", c.c_str());
  std::printf("\n");
  std::vector<Row> rows;
  const auto start = std::chrono::steady_clock::now();
  seep::core::RunControl control;
  std::stop_source stop;
  control.stop = stop.get_token();
  control.at_step_end = [&](const Simulation& s) {
    if (s.step() % every != 0) return;
    const Row row{s.step(), s.time_s(), CheckerboardAmplitude(s)};
    rows.push_back(row);
    std::printf("%10llu %12.6g %8.0f %12.5g %12.5g %10.4g %10.4g",
                static_cast<unsigned long long>(row.step), row.time_s, Column(s, "bonds_broken"),
                row.checkerboard, seep::core::KineticEnergy(s.stepper().state().particles),
                s.stepper().EnergyRatio(),
                seep::core::ReversalGuard::DiskRatio(s.stepper().state().particles, s.dt_s()));
    for (const std::string& c : wall_columns) std::printf(" %.5g", Column(s, c));
    const seep::core::LiveState& live = s.stepper().state();
    for (std::size_t w = 0; w < live.walls.size(); ++w) {
      std::printf(" | w%zu v %.3g k_f %.3g s %.4g", w,
                  live.walls[w].vx * live.walls[w].nx + live.walls[w].vy * live.walls[w].ny,
                  w < live.wall_fluid_stiffness.size() ? live.wall_fluid_stiffness[w] : 0.0,
                  w < live.wall_stress_pa.size() ? live.wall_stress_pa[w] : 0.0);
    }
    std::printf("\n");
    std::fflush(stdout);
    if (s.step() >= steps) stop.request_stop();
  };
  const seep::core::Status ran = sim->Run(control);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("# ended: %s after %llu steps, %.1f s wall\n",
              ran.ok() ? "finished" : ran.ToString().c_str(),
              static_cast<unsigned long long>(sim->step()), seconds);
  for (const auto& [name, value] : sim->Report().metrics) {
    std::printf("# metric %s %.9g\n", name.c_str(), value);
  }
  std::printf("# checkerboard growth over the last half: %.4g per step, %.4g per s\n",
              GrowthRate(rows, false), GrowthRate(rows, true));
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  const double peak_bytes = static_cast<double>(usage.ru_maxrss) * 1024.0;
  const auto particles = sim->stepper().state().particles.size();
  std::printf("# peak resident memory %.1f MiB, %.0f bytes a particle (%zu particles)\n",
              peak_bytes / (1 << 20), peak_bytes / std::max<std::size_t>(1, particles), particles);
  return 0;
}
