// The coupled problems' grid of choices (see coupled_grid.h).
#include "coupled_grid.h"

#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <limits>
#include <stop_token>
#include <utility>

namespace seep::bench {
namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

// The explicit update's step within the DEM step, as a fraction of dt_crit.
constexpr double kExplicitDtFactor = 0.9;
// Implicit: a dt_factor this large leaves the flow interval to the DEM step and the fluid's
// stiffness (FlowEffectSpec::every_steps = 0) or to every_steps.
constexpr double kImplicitDtFactor = 1e6;

}  // namespace

std::vector<CoupledChoice> CoupledChoices(const CoupledGrid& grid) {
  std::vector<CoupledChoice> out;
  const double base_safety = grid.dt_safety.empty() ? 0.5 : grid.dt_safety.front();
  for (const double k : grid.bulk_moduli) {
    out.push_back({k, core::SolverKind::kImplicit, 0, base_safety, 0});
    if (grid.explicit_solver) out.push_back({k, core::SolverKind::kExplicit, 0, base_safety, 0});
  }
  for (const double k : grid.bulk_moduli) {
    for (const std::uint32_t every : grid.flow_every) {
      out.push_back({k, core::SolverKind::kImplicit, every, base_safety, 0});
    }
    for (std::size_t i = 1; i < grid.dt_safety.size(); ++i) {
      out.push_back({k, core::SolverKind::kImplicit, 0, grid.dt_safety[i], 0});
    }
    for (int size = 1; size < grid.sizes; ++size) {
      out.push_back({k, core::SolverKind::kImplicit, 0, base_safety, size});
    }
  }
  return out;
}

void ApplyChoice(const CoupledChoice& choice, core::SceneSpec* scene) {
  scene->fluid.bulk_modulus_pa = choice.bulk_modulus_pa;
  scene->solver.kind = choice.solver;
  scene->solver.dt_factor =
      choice.solver == core::SolverKind::kExplicit ? kExplicitDtFactor : kImplicitDtFactor;
  for (core::EffectSpec& e : scene->effects) {
    if (auto* flow = std::get_if<core::FlowEffectSpec>(&e)) flow->every_steps = choice.flow_every;
    if (auto* contacts = std::get_if<core::ContactsEffectSpec>(&e)) {
      contacts->dt_safety = choice.dt_safety;
    }
  }
}

CoupledRun RunCoupled(const core::SceneSpec& scene,
                      const std::function<bool(const core::Simulation&)>& at_step_end) {
  CoupledRun out;
  const auto t0 = Clock::now();
  core::Result<core::Simulation> created = core::Simulation::Create(scene);
  const auto t1 = Clock::now();
  out.setup_s = Seconds(t0, t1);
  if (!created.ok()) {
    out.status = created.status();
    return out;
  }
  out.simulation.emplace(std::move(*created));
  std::stop_source stop;
  core::RunControl control;
  control.stop = stop.get_token();
  control.at_step_end = [&](const core::Simulation& now) {
    if (at_step_end && at_step_end(now)) stop.request_stop();
  };
  out.status = out.simulation->Run(control);
  if (stop.stop_requested() && out.status.code() == core::StatusCode::kCancelled) {
    out.status = core::Status::Ok();
  }
  out.wall_s = Seconds(t1, Clock::now());
  return out;
}

core::ContactsEffectSpec SoftLatticeContacts(double dt_safety) {
  core::ContactsEffectSpec c;
  c.law.kn = 1e7;
  c.law.kt = 0.5e7;
  c.law.friction = 0.0;
  c.law.damping_mode = core::NormalDampingMode::kCriticalRatio;
  c.law.damping_ratio = 0.3;
  c.density_kg_m3 = 2650.0;
  c.dt_safety = dt_safety;
  return c;
}

double ReportMetric(const core::RunReport& report, const std::string& name) {
  for (const auto& [key, value] : report.metrics) {
    if (key == name) return value;
  }
  return std::numeric_limits<double>::quiet_NaN();
}

AccuracyRun CoupledRow(const std::string& problem, const CoupledChoice& choice, int particles,
                       const CoupledRun& run, double error, const std::string& error_kind,
                       const std::string& note) {
  AccuracyRun r;
  r.problem = problem;
  r.solver = SolverLabel(choice.solver);
  r.storage = "coupled";
  r.resolution = particles;
  r.bulk_modulus_pa = choice.bulk_modulus_pa;
  r.dem_dt_safety = choice.dt_safety;
  r.error_kind = error_kind;
  r.wall_s = run.wall_s;
  r.setup_s = run.setup_s;
  r.error = run.status.ok() ? error : std::numeric_limits<double>::quiet_NaN();
  r.note = run.status.ok() ? note : "failed: " + run.status.ToString();
  if (run.simulation) {
    const core::RunReport report = run.simulation->Report();
    r.steps = run.simulation->step();
    r.domains =
        static_cast<std::int64_t>(run.simulation->stepper().state().net.domains.num_domains());
    r.flow_every = ReportMetric(report, "flow_every_steps");
    r.stiffness_ratio = ReportMetric(report, "coupling_fluid_to_skeleton_stiffness");
  }
  r.flow_every_asked = choice.flow_every;
  return r;
}

}  // namespace seep::bench
