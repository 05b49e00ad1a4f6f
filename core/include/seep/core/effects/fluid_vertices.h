// The vertices the loops of the fluid network name: the particles, then (with walls in the
// fluid) the wall vertices (domain_walls.h). Effects that measure the loops (volumes, pressure
// forces, the fluid's stiffness) read them through one of these.
#pragma once

#include <cstdint>
#include <vector>

#include "seep/core/coupling/particle_view.h"
#include "seep/core/geometry/domain_walls.h"

namespace seep::core {

struct LiveState;

class FluidVertices {
 public:
  // The particles now and the wall vertices on the walls now. Without wall vertices this is the
  // particles' own arrays (no copy); with them, the view is valid until the next call.
  ParticleView Current(const LiveState& s);
  // As Current, but a second call within the same step (LiveState::step_stamp, the same network)
  // returns the first call's arrays: from the drift to the end of a step neither the particles
  // nor the walls move (the second half-kick and the servo change velocities only), so the view
  // would be the same bits. The fluid forces and the volume change of one step share one copy.
  ParticleView CurrentInStep(const LiveState& s);
  // As the network was detected: the detection positions and the detection's wall vertices.
  ParticleView AtDetection(const LiveState& s);

 private:
  ParticleView Fill(const LiveState& s, std::span<const double> x, std::span<const double> y,
                    bool detected);
  std::vector<double> x_, y_, radius_;
  std::vector<WallLine> lines_;
  // What the arrays hold, for CurrentInStep: the step stamp and the topology of a Current fill
  // (stamp 0: none).
  std::uint64_t filled_stamp_ = 0;
  std::uint64_t filled_topology_ = 0;
};

}  // namespace seep::core
