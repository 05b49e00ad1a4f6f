// Timing, percentile, logger and scene helpers of seep_service_bench (see service_bench.h).
#include <spdlog/sinks/null_sink.h>

#include <algorithm>
#include <cmath>
#include <stop_token>

#include "service_bench.h"

namespace seep::bench {

double Percentile(std::vector<double> samples, double q) {
  if (samples.empty()) return 0.0;
  std::sort(samples.begin(), samples.end());
  // Nearest rank: the smallest sample with at least q of the samples at or below it.
  const double rank = std::ceil(q * static_cast<double>(samples.size()));
  const std::size_t index = rank < 1.0 ? 0 : static_cast<std::size_t>(rank) - 1;
  return samples[std::min(index, samples.size() - 1)];
}

double Median(const std::vector<double>& samples) { return Percentile(samples, 0.5); }

const char* Verdict(bool met) { return met ? "PASS" : "MISS"; }

std::shared_ptr<spdlog::logger> QuietLogger(const std::string& name) {
  return std::make_shared<spdlog::logger>(name, std::make_shared<spdlog::sinks::null_sink_mt>());
}

namespace {

// Water on a rigid lattice with the residual aperture only (examples/darcy_square_lattice,
// docs/physics.md §1.3).
void FillCommon(v1::Scene& scene, std::uint32_t columns, std::uint32_t rows) {
  auto* lattice = scene.mutable_packing()->mutable_lattice();
  lattice->set_kind(v1::LATTICE_KIND_SQUARE);
  lattice->set_columns(columns);
  lattice->set_rows(rows);
  lattice->set_radius_m(1e-3);
  scene.mutable_fluid()->set_viscosity_pa_s(1e-3);
  scene.mutable_fluid()->set_bulk_modulus_pa(2.2e9);
  scene.mutable_aperture()->set_residual_aperture_m(1e-5);
  scene.mutable_aperture()->set_reference_force_n(1e3);
  scene.mutable_aperture()->set_gap_multiplier(0.5);
  scene.mutable_boundary()->set_axis(v1::FLOW_AXIS_X);
  scene.mutable_boundary()->set_inlet_pressure_pa(1e5);
  scene.mutable_boundary()->set_outlet_pressure_pa(0.0);
}

}  // namespace

v1::Scene TransientLatticeScene(std::uint32_t columns, std::uint32_t rows, double end_time_s) {
  v1::Scene scene;
  scene.set_name("bench-transient-lattice");
  FillCommon(scene, columns, rows);
  auto* solver = scene.mutable_solver();
  solver->set_kind(v1::SOLVER_KIND_EXPLICIT);
  solver->set_storage(v1::STORAGE_VOLUME_PORE);
  solver->set_dt_factor(0.9);
  solver->set_end_time_s(end_time_s);
  return scene;
}

v1::Scene TransientLatticeScene(std::uint32_t side) {
  // dt_crit is about 2 us here: 1000 s of simulated time is ~5e8 steps, never reached.
  return TransientLatticeScene(side, side, 1000.0);
}

v1::Scene QuickSteadyScene(const std::string& name) {
  v1::Scene scene;
  scene.set_name(name);
  FillCommon(scene, 6, 4);
  scene.mutable_solver()->set_kind(v1::SOLVER_KIND_STEADY);
  return scene;
}

std::uint64_t RunFor(core::Simulation& sim, std::uint64_t max_steps, double max_seconds,
                     const std::function<void(const core::Simulation&)>& at_step_end) {
  std::stop_source stop;
  const std::uint64_t first = sim.step();
  const auto start = Clock::now();
  core::RunControl control;
  control.stop = stop.get_token();
  control.logger = QuietLogger("bench-run");
  control.at_step_end = [&](const core::Simulation& at) {
    if (at_step_end) at_step_end(at);
    if (at.step() - first >= max_steps || Seconds(start, Clock::now()) >= max_seconds) {
      stop.request_stop();
    }
  };
  (void)sim.Run(control);  // kCancelled when stopped: the state sits at a step boundary
  return sim.step() - first;
}

}  // namespace seep::bench
