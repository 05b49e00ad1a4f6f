// FlowEffect: pipe flow on the network with the scene's solver — the one place the flow solver is
// made. Its mode follows from the scene:
//   kSteady     a frozen packing, steady solver: one solve at step 1;
//   kStepped    a frozen packing, transient solver: one solver step per step of the loop, whose
//               step is dt_factor x dt_crit (the last one lands on end_time_s);
//   kSubCycled  moving particles: one flow update per flow interval of `EverySteps` DEM steps,
//               the explicit solver sub-cycled inside it, the implicit one in one step.
// Either way the explicit governor allows dt_factor x dt_crit.
//
// Fluid weight (network/fluid_weight.h): the flow effect owns the head offsets of the pipes. It
// sets them at Bind (and the hydrostatic start when the scene asks for it), after every
// re-detection (Rebind), and on moving particles before every flow update, from the centroids
// of that moment: one pass over the loops per update, nothing per DEM step.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "seep/core/effects/effect.h"
#include "seep/core/flow/explicit_solver.h"
#include "seep/core/flow/implicit_solver.h"
#include "seep/core/network/fluid_weight.h"

namespace seep::core {

class VolumeChangeEffect;

enum class FlowMode { kSteady, kStepped, kSubCycled };

class FlowEffect final : public EffectWithSpec<FlowEffectSpec> {
 public:
  using EffectWithSpec::EffectWithSpec;
  std::uint32_t Hooks() const override { return kFlowUpdateHook; }

  Status Bind(LiveState& s, const EffectSet& effects) override;
  Status Rebind(LiveState& s) override;
  // A stage changed a boundary pressure or a region's value: the fixed nodes and the regions'
  // sources take the live scene's values.
  Status Reconfigure(LiveState& s) override;
  Status UpdateFlow(LiveState& s, const StepInfo& info) override;

  void SaveTo(EffectStates* out) const override { out->flow = state_; }
  // After the re-bind (Stepper::Restore): the critical step of the last flow update, not the one
  // the re-bind measured on the detection's volumes (a resumed run's dt_crit_s differed); a
  // checkpoint without it (0) keeps the re-bind's.
  void RestoreFrom(const EffectStates& in) override {
    const FlowEffectState rebound = state_;
    state_ = in.flow;
    if (!(in.flow.dt_crit_s > 0.0)) {
      state_.dt_crit_s = rebound.dt_crit_s;
      state_.limiting_domain = rebound.limiting_domain;
    }
  }
  void AddMetrics(const LiveState& s, Metrics* m) const override;
  void AddSeriesColumns(const LiveState& s, std::vector<std::string>* columns) const override;
  void AddSample(const LiveState& s, std::vector<double>* row) const override;

  FlowMode mode() const { return mode_; }
  // The explicit limit V_s/(K_f sum C) at the last update (at set-up before the first).
  double dt_crit_s() const { return state_.dt_crit_s; }
  std::int32_t limiting_domain() const { return state_.limiting_domain; }

  // DEM steps per flow update of a moving scene (FlowEffectSpec::every_steps), given the DEM step
  // and the step the fluid's stiffness allows; fixes the interval the report divides by.
  std::uint64_t SetEverySteps(double dem_dt, double fluid_limited_dt, double dt_factor);
  std::uint64_t every_steps() const { return every_steps_; }
  // The interval a checkpoint's clock carries (the run had set it with SetEverySteps).
  void set_every_steps(std::uint64_t every_steps) { every_steps_ = every_steps; }

 private:
  // Head offsets from the current positions (no-op without fluid weight).
  Status RefreshFluidWeight(LiveState& s);
  // Which flow node is which boundary of the books (at bind and after every re-detection).
  Status MapBoundaries(const LiveState& s);
  // Adds the update's tally to the run's books and clears it for the next.
  void Book(FluidLedger& ledger);
  // k between the two drained platens now (platens_ set).
  double PlatenPermeability(const LiveState& s) const;

  FlowMode mode_ = FlowMode::kSteady;
  std::variant<std::monostate, ExplicitSolver, ImplicitSolver> solver_;
  const VolumeChangeEffect* volume_change_ = nullptr;
  std::uint64_t every_steps_ = 1;
  FlowEffectState state_;
  std::optional<FluidWeight> weight_;
  std::vector<double> node_weight_;  // W_n of the last refresh, Pa
  // The books' boundaries: (fixed node, boundary index) of the current network, and the tally
  // the solver fills over an update (transient modes only).
  std::vector<std::string> boundary_names_;  // FluidBoundaryNames of the scene, set at bind
  std::vector<std::pair<std::int32_t, std::int32_t>> boundary_nodes_;
  FluidTally tally_;
  // Two drained platens facing each other at different pressures: the permeability between them
  // is reported and sampled (src/effects/platen_permeameter.h). Set at bind.
  std::optional<std::pair<std::size_t, std::size_t>> platens_;  // (high, low) wall indices
  bool platens_along_x_ = true;
};

}  // namespace seep::core
