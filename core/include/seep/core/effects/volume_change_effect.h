// VolumeChangeEffect: deformation -> the dV term of the pressure update (seed eq. 4). At every
// flow update the domain volumes are recomputed from the moving particles; dV of the storage
// volume over the interval is what the flow effect reads (change()).
#pragma once

#include <span>
#include <vector>

#include "seep/core/coupling/domain_volume_update.h"
#include "seep/core/effects/effect.h"

namespace seep::core {

class VolumeChangeEffect final : public Effect {
 public:
  VolumeChangeEffect() : Effect(kEffectKind<VolumeChangeEffectSpec>) {}
  std::uint32_t Hooks() const override { return kFlowUpdateHook; }

  Status Bind(LiveState& s, const EffectSet& effects) override;
  Status Rebind(LiveState& s) override;
  Status UpdateFlow(LiveState& s, const StepInfo& info) override;

  // dV per flow node over the current flow interval (reservoirs 0).
  std::span<const double> change() const { return change_; }

  // V_p of every flow node at the particles now: with apparent storage the network keeps the
  // detected V_p (see UpdateFlow), so it is computed here from the positions.
  std::vector<double> CurrentPoreVolumes(const LiveState& s) const;

 private:
  DomainVolumeUpdater updater_;
  std::vector<double> apparent_, pore_;
  std::vector<double> change_;
};

// V_p of every flow node as a report, an export or a snapshot shows it: current when the volumes
// follow the particles (`volume_change` listed), else the network's.
std::vector<double> ReportedPoreVolumes(const LiveState& s,
                                        const VolumeChangeEffect* volume_change);

}  // namespace seep::core
