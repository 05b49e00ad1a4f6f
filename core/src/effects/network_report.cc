#include "network_report.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <optional>

#include "seep/core/flow/flow_diagnostics.h"
#include "seep/core/flow/pipe_head.h"

namespace seep::core::effects_internal {
namespace {

// The rate into fixed-pressure node `node` out of the sample; 0 - x rather than -x, so that no
// flow reads 0 and not -0.
double NodeOutflow(const BoundaryFluxes& fluxes, std::int32_t node) {
  return 0.0 - NodeInflow(fluxes, node);
}

// The rate out of the well into the sample through its pipes (> 0 when it feeds the sample). A
// well held at a pressure is a fixed node of the boundary fluxes; an injected well is a source
// whose pipes carry its rate on (read from the boundary fluxes, it was 0 while injecting).
double WellOutflow(const SceneNetwork& net, const BoundaryFluxes& fluxes) {
  const std::int32_t well = net.well_domain;
  if (well < 0) return 0.0;
  const FlowNetwork& f = net.flow;
  if (f.role()[static_cast<std::size_t>(well)] == DomainRole::kFixedPressure) {
    return NodeInflow(fluxes, well);
  }
  const auto a = f.pipe_domain_a();
  const auto b = f.pipe_domain_b();
  double out = 0.0;
  for (std::size_t k = 0; k < f.num_pipes(); ++k) {
    if (a[k] == well) out -= PipeInflowToA(f, k);
    if (b[k] == well) out += PipeInflowToA(f, k);
  }
  return out;
}

void AddPressureRange(const FlowNetwork& network, Metrics& m) {
  const PressureRange range = ComputePressureRange(network);
  m["min_pressure_pa"] = range.min;
  m["max_pressure_pa"] = range.max;
}

// The exact permeability of a rigid lattice with uniform aperture a (docs/physics.md §1.3, L = 2R).
std::optional<double> LatticePermeability(const SceneSpec& scene) {
  const auto* lattice = std::get_if<LatticePackingSpec>(&scene.packing.source);
  if (lattice == nullptr) return std::nullopt;
  const double a = scene.aperture.residual_aperture_m;
  const double k = a * a * a / (24.0 * lattice->radius_m);
  return lattice->kind == LatticeKind::kSquare ? k : k / std::sqrt(3.0);
}

void AddDarcyMetrics(const SceneSpec& scene, const SceneNetwork& net,
                     std::span<const double> node_weight, Metrics& m) {
  const BoundaryFluxes fluxes = ComputeBoundaryFluxes(net.flow);
  const double inflow = NodeInflow(fluxes, net.inlet_node);
  const double outflow = NodeOutflow(fluxes, net.outlet_node);
  m["inflow_m2_per_s"] = inflow;
  m["outflow_m2_per_s"] = outflow;
  double dp = scene.boundary.inlet_pressure_pa - scene.boundary.outlet_pressure_pa;
  if (!node_weight.empty() && net.inlet_node >= 0 && net.outlet_node >= 0) {
    // The drop of the head P - W that drives the flow (the pressure drop minus the weight of
    // the fluid column between the two reservoirs' reference points; a closed reservoir has no
    // node, and no column to weigh: read at index -1, it was the heap's bytes before the array).
    dp -= node_weight[static_cast<std::size_t>(net.inlet_node)] -
          node_weight[static_cast<std::size_t>(net.outlet_node)];
    m["head_drop_pa"] = dp;
  }
  if (const auto k = DarcyPermeability(scene.fluid.viscosity_pa_s, 0.5 * (inflow + outflow),
                                       net.length_m, net.width_m, dp);
      k.ok()) {
    m["permeability_m2"] = *k;
    if (const auto exact = LatticePermeability(scene)) {
      m["lattice_permeability_m2"] = *exact;
      m["permeability_relative_error"] = std::abs(*k - *exact) / *exact;
    }
  }
  AddPressureRange(net.flow, m);
  m["sample_length_m"] = net.length_m;
  m["sample_width_m"] = net.width_m;
}

// Radial boundary: the rate out of the well into the sample and into the outer reservoir.
void AddRadialMetrics(const SceneNetwork& net, Metrics& m) {
  const BoundaryFluxes fluxes = ComputeBoundaryFluxes(net.flow);
  m["well_flow_rate_m2_per_s"] = WellOutflow(net, fluxes);
  m["outer_flow_rate_m2_per_s"] = NodeOutflow(fluxes, net.outer_node);
  m["outer_reservoir_radius_m"] = net.outer_reservoir_radius_m;
  if (net.well_domain >= 0) {
    m["well_area_m2"] = net.flow.apparent_volume()[static_cast<std::size_t>(net.well_domain)];
  }
  AddPressureRange(net.flow, m);
}

// Per boundary region: region_<name>_domains, the domains it holds now, and
// region_<name>_flow_m2_per_s: for a pressure region the net rate out of the sample into it
// (> 0: it drains the sample, like fluid_left_region_<name>_m2; flow between two of its domains,
// both fixed, is not counted), for a flux region the rate its domains receive (> 0: it injects;
// its rate_m2_s, or 0 while it holds no domain).
void AddRegionMetrics(const SceneSpec& scene, const SceneNetwork& net, Metrics& m) {
  const auto& regions = scene.boundary.regions;
  if (regions.empty()) return;
  const BoundaryFluxes fluxes = ComputeBoundaryFluxes(net.flow);
  const std::span<const double> source_rate = net.flow.source_rate();
  for (std::size_t r = 0; r < regions.size() && r < net.regions.size(); ++r) {
    const std::vector<std::int32_t>& nodes = net.regions[r].nodes;
    const bool pressure = std::holds_alternative<FixedPressure>(regions[r].condition);
    double flow = 0.0;
    for (const std::int32_t d : nodes) {
      flow += pressure ? NodeOutflow(fluxes, d) : source_rate[static_cast<std::size_t>(d)];
    }
    m[fmt::format("region_{}_flow_m2_per_s", regions[r].name)] = flow;
    m[fmt::format("region_{}_domains", regions[r].name)] = static_cast<double>(nodes.size());
  }
}

}  // namespace

void AddNetworkSeriesColumns(const SceneSpec& scene, std::vector<std::string>* columns) {
  if (scene.boundary.radial) {
    columns->insert(columns->end(), {"well_flow_rate_m2_per_s", "outer_flow_rate_m2_per_s",
                                     "min_pressure_pa", "max_pressure_pa", "mass_balance_error"});
  } else {
    columns->insert(columns->end(), {"inflow_m2_per_s", "outflow_m2_per_s", "min_pressure_pa",
                                     "max_pressure_pa", "mass_balance_error"});
  }
}

void AddNetworkSample(const SceneSpec& scene, const SceneNetwork& net, double step_error,
                      std::vector<double>* row) {
  const BoundaryFluxes fluxes = ComputeBoundaryFluxes(net.flow);
  const PressureRange range = ComputePressureRange(net.flow);
  const bool radial = scene.boundary.radial.has_value();
  const double first = radial ? WellOutflow(net, fluxes) : NodeInflow(fluxes, net.inlet_node);
  const double second = NodeOutflow(fluxes, radial ? net.outer_node : net.outlet_node);
  row->insert(row->end(), {first, second, range.min, range.max, step_error});
}

void AddNetworkMetrics(const SceneSpec& scene, const SceneNetwork& net,
                       std::span<const double> pore_volume, std::span<const double> node_weight,
                       Metrics* m) {
  if (scene.boundary.radial) {
    AddRadialMetrics(net, *m);
  } else {
    AddDarcyMetrics(scene, net, node_weight, *m);
  }
  AddRegionMetrics(scene, net, *m);
  double pore = 0.0;
  double apparent = 0.0;
  const std::span<const double> apparent_volume = net.flow.apparent_volume();
  for (std::size_t d = 0; d < net.domains.num_domains(); ++d) {
    pore += pore_volume[d];
    apparent += apparent_volume[d];
  }
  (*m)["particle_count"] = static_cast<double>(net.packing.size());
  (*m)["contact_count"] = static_cast<double>(net.contacts.size());
  (*m)["domain_count"] = static_cast<double>(net.domains.num_domains());
  (*m)["pipe_count"] = static_cast<double>(net.flow.num_pipes());
  (*m)["porosity_2d"] = apparent > 0.0 ? pore / apparent : 0.0;
}

}  // namespace seep::core::effects_internal
