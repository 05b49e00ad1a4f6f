// RunScene: builds the packing, the contact graph, the domains and pipes of a scene, then runs
// its solver to the end and measures what the scene asks for. The one entry point the job
// service calls.
#pragma once

#include <spdlog/logger.h>

#include <cstdint>
#include <functional>
#include <memory>
#include <stop_token>
#include <string>
#include <utility>
#include <vector>

#include "seep/core/scene/scene_spec.h"
#include "seep/core/status.h"

namespace seep::core {

struct RunProgress {
  std::uint64_t step = 0;
  double time_s = 0.0;         // simulated time
  double fraction_done = 0.0;  // 0..1
};

struct RunControl {
  // Called from the running thread at the scene's progress interval; must not block for long.
  std::function<void(const RunProgress&)> on_progress;
  // A stop request ends the run at the next step boundary with a kCancelled status.
  std::stop_token stop;
  // Where the run logs (the service passes a logger named after the job); null = core::Logger().
  std::shared_ptr<spdlog::logger> logger;
};

struct RunReport {
  // Named measurements, sorted by name. Linear boundary: inflow/outflow_m2_per_s,
  // permeability_m2 (k = mu Q L / (H dP) with sample_length_m and sample_width_m, see
  // scene_network.h), and for lattices lattice_permeability_m2 and permeability_relative_error.
  // Radial boundary: well_flow_rate_m2_per_s (out of the well into the sample, > 0 when
  // p_w > p_e), outer_flow_rate_m2_per_s (into the outer reservoir), outer_reservoir_radius_m,
  // well_area_m2. Always: counts, porosity_2d, min/max_pressure_pa, steps, simulated_time_s.
  std::vector<std::pair<std::string, double>> metrics;
  std::uint64_t steps = 0;
  double time_s = 0.0;
};

Result<RunReport> RunScene(const SceneSpec& scene, const RunControl& control);

}  // namespace seep::core
