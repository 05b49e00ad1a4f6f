// One row of the accuracy bench: a verification problem run once with one choice of solver,
// storage, step, resolution and fluid stiffness, with its wall time and its error against the
// analytic answer.
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "seep/core/spec/scene_spec.h"

namespace seep::bench {

struct AccuracyRun {
  std::string problem;           // e.g. "diffusion_T0.2", "darcy", "thiem", "terzaghi"
  std::string solver;            // "explicit", "implicit" (BE), "cn", "steady" or "pending"
  std::string storage;           // "apparent", "pore", "-" (steady) or "coupled"
  double dt_over_dt_crit = 0.0;  // 0 for steady
  int resolution = 0;            // domains along the sample (radially: across the annulus)
  std::int64_t domains = 0;      // free domains of the whole network
  double bulk_modulus_pa = 0.0;  // 0 when K_f does not enter (steady)
  std::uint64_t steps = 0;
  double wall_s = 0.0;   // Simulation::Run only (best of the repeats)
  double setup_s = 0.0;  // Simulation::Create: packing, contacts, domains, network
  double error = 0.0;    // see error_kind
  std::string error_kind;
  std::string note;      // free text without commas
  bool pending = false;  // a problem listed but not run (no numbers)
  // Coupled problems only (coupled_grid.h); 0 / NaN elsewhere.
  double dem_dt_safety = 0.0;          // contacts.dt_safety
  std::uint32_t flow_every_asked = 0;  // FlowEffectSpec::every_steps (0 = automatic)
  double flow_every = 0.0;             // DEM steps per flow update the run chose
  double stiffness_ratio = 0.0;        // coupling_fluid_to_skeleton_stiffness, Pi_K
  double fluid_step_ratio = 0.0;       // coupling_fluid_step_over_flow_interval
  // The same measure against the same problem's run at real water (base choices, same size).
  double real_water_error = std::numeric_limits<double>::quiet_NaN();
};

// Crank–Nicolson (SolverKind::kCrankNicolson: ImplicitSolver at theta = 1/2).
inline constexpr const char* kCrankNicolsonLabel = "cn";

// One solver choice of a transient grid: scheme, storage volume and the step factors to sweep.
struct SolverChoice {
  core::SolverKind kind;
  core::StorageVolume storage;
  const std::vector<double>* factors;
};

// The four schemes every transient problem sweeps: PFC's explicit update (apparent
// volume), explicit with the pore volume, backward Euler and Crank-Nicolson (both pore volume).
inline std::array<SolverChoice, 4> TransientChoices(const std::vector<double>& explicit_factors,
                                                    const std::vector<double>& implicit_factors,
                                                    const std::vector<double>& cn_factors) {
  using core::SolverKind;
  using core::StorageVolume;
  return {{{SolverKind::kExplicit, StorageVolume::kApparent, &explicit_factors},
           {SolverKind::kExplicit, StorageVolume::kPore, &explicit_factors},
           {SolverKind::kImplicit, StorageVolume::kPore, &implicit_factors},
           {SolverKind::kCrankNicolson, StorageVolume::kPore, &cn_factors}}};
}

// Short labels for the CSV and the table.
inline std::string SolverLabel(core::SolverKind kind) {
  switch (kind) {
    case core::SolverKind::kExplicit:
      return "explicit";
    case core::SolverKind::kImplicit:
      return "implicit";
    case core::SolverKind::kCrankNicolson:
      return kCrankNicolsonLabel;
    case core::SolverKind::kSteady:
    default:
      return "steady";
  }
}

inline std::string StorageLabel(const core::SolverSpec& solver) {
  if (solver.kind == core::SolverKind::kSteady) return "-";
  return solver.storage == core::StorageVolume::kPore ? "pore" : "apparent";
}

}  // namespace seep::bench
