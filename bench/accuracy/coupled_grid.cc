// The coupled problems' grid of choices (see coupled_grid.h).
#include "coupled_grid.h"

#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <cstdio>
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

// The grid's base DEM step safety: its first, 0.5 when it lists none.
double BaseSafety(const CoupledGrid& grid) {
  return grid.dt_safety.empty() ? 0.5 : grid.dt_safety.front();
}

}  // namespace

std::vector<CoupledChoice> CoupledChoices(const CoupledGrid& grid) {
  std::vector<CoupledChoice> out;
  const double base_safety = BaseSafety(grid);
  const core::SolverKind base = grid.base_solver;
  const core::SolverKind other = base == core::SolverKind::kImplicit ? core::SolverKind::kExplicit
                                                                     : core::SolverKind::kImplicit;
  for (const double k : grid.bulk_moduli) {
    out.push_back({k, base, 0, base_safety, 0});
    if (grid.both_solvers) out.push_back({k, other, 0, base_safety, 0});
  }
  for (const double k : grid.bulk_moduli) {
    for (const std::uint32_t every : grid.flow_every) {
      out.push_back({k, base, every, base_safety, 0});
    }
    for (std::size_t i = 1; i < grid.dt_safety.size(); ++i) {
      out.push_back({k, base, 0, grid.dt_safety[i], 0});
    }
    for (int size = 1; size < grid.sizes; ++size) {
      out.push_back({k, base, 0, base_safety, size});
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

void PrintCoupledProgress(const AccuracyRun& row, const CoupledChoice& choice, int particles,
                          const std::string& detail, bool error_known) {
  const std::string error = error_known ? fmt::format(", error {:.3e}", row.error) : "";
  std::fprintf(
      stderr, "%s\n",
      fmt::format("{} {:4d} disks K_f {:.2g} {} every {} safety {:.2f}: Pi_K {:.3g}{} "
                  "({:.2f} s, {} steps) {}",
                  row.problem, particles, choice.bulk_modulus_pa, row.solver, choice.flow_every,
                  choice.dt_safety, row.stiffness_ratio, error, row.wall_s, row.steps, detail)
          .c_str());
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

core::SceneSpec WalledLattice(const std::string& name, std::uint32_t columns, std::uint32_t rows,
                              double viscosity_pa_s, core::WallsEffectSpec walls,
                              double end_time_s) {
  constexpr double kRadius = 1e-3;  // m
  core::SceneSpec s;
  s.name = name;
  s.packing.source = core::LatticePackingSpec{core::LatticeKind::kHex, columns, rows, kRadius};
  s.packing.contact_gap_m = 1e-6;
  s.fluid.viscosity_pa_s = viscosity_pa_s;
  s.aperture.residual_aperture_m = 1e-5;
  s.aperture.reference_force_n = 1e3;
  s.boundary.walls_only = true;
  s.solver.kind = core::SolverKind::kImplicit;
  s.solver.dt_factor = kImplicitDtFactor;
  s.solver.storage = core::StorageVolume::kApparent;
  s.solver.storage_factor = kLatticeStoragePorosity;
  s.solver.end_time_s = end_time_s;
  s.effects = {SoftLatticeContacts(0.5),          std::move(walls),
               core::LocalDampingEffectSpec{0.3}, core::FlowEffectSpec{},
               core::FluidForcesEffectSpec{},     core::VolumeChangeEffectSpec{}};
  return s;
}

std::vector<std::size_t> RealWaterBaseIndices(const std::vector<CoupledChoice>& choices,
                                              const CoupledGrid& grid) {
  const double base_safety = BaseSafety(grid);
  std::vector<std::size_t> base_of_size;  // per size index; choices.size() = none
  for (std::size_t i = 0; i < choices.size(); ++i) {
    const CoupledChoice& c = choices[i];
    const auto size = static_cast<std::size_t>(c.size);
    if (base_of_size.size() <= size) base_of_size.resize(size + 1, choices.size());
    if (base_of_size[size] == choices.size() && c.bulk_modulus_pa == kRealWaterBulkModulusPa &&
        c.solver == grid.base_solver && c.flow_every == 0 && c.dt_safety == base_safety) {
      base_of_size[size] = i;
    }
  }
  std::vector<std::size_t> out(choices.size());
  for (std::size_t i = 0; i < choices.size(); ++i) {
    const std::size_t base = base_of_size[static_cast<std::size_t>(choices[i].size)];
    out[i] = base < choices.size() ? base : i;
  }
  return out;
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
    r.fluid_step_ratio = ReportMetric(report, "coupling_fluid_step_over_flow_interval");
  }
  r.flow_every_asked = choice.flow_every;
  return r;
}

}  // namespace seep::bench
