// The vertices the loops of the fluid network name: the particles, then (with walls in the
// fluid) the wall vertices (domain_walls.h). Effects that measure the loops (volumes, pressure
// forces, the fluid's stiffness) read them through one of these.
#pragma once

#include <vector>

#include "seep/core/coupling/particle_view.h"
#include "seep/core/effects/live_state.h"

namespace seep::core {

class FluidVertices {
 public:
  // The particles now and the wall vertices on the walls now. Without wall vertices this is the
  // particles' own arrays (no copy); with them, the view is valid until the next call.
  ParticleView Current(const LiveState& s);
  // As the network was detected: the detection positions and the detection's wall vertices.
  ParticleView AtDetection(const LiveState& s);

 private:
  ParticleView Fill(const LiveState& s, std::span<const double> x, std::span<const double> y,
                    bool detected);
  std::vector<double> x_, y_, radius_;
  std::vector<WallLine> lines_;
};

}  // namespace seep::core
