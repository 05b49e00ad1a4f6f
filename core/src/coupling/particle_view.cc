// Size check of the particle arrays shared by the coupling functions.
#include "seep/core/coupling/particle_view.h"

#include <string>

namespace seep::core {

Status CheckParticleView(const ParticleView& particles, const char* what) {
  if (particles.y.size() != particles.x.size() || particles.radius.size() != particles.x.size()) {
    return InvalidArgument(std::string(what) + ": x, y and radius differ in length (" +
                           std::to_string(particles.x.size()) + ", " +
                           std::to_string(particles.y.size()) + ", " +
                           std::to_string(particles.radius.size()) + ")");
  }
  return Status::Ok();
}

}  // namespace seep::core
