// Isometries of a scene, for the metamorphic tests: the physics of a scene has no preferred
// origin, no preferred direction and no handedness, so a translated, a quarter-turned or a
// mirrored scene must give the image of the original's results.
//
// A map acts on the materialised scene: the packing as its particle list (the same ids, so
// particle i of the image is the image of particle i), the walls (a side wall goes to the side it
// is mapped onto, a segment to its mapped end points), gravity, the boundary's axis and its
// inlet and outlet, the hydrostatic reference point and every boundary region's shape. A radial
// boundary is centred on the packing's bounding box, which every map here takes to its image.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "seep/core/spec/scene_spec.h"

namespace seep::core::metamorphic {

// Positions are snapped to a grid of 2^-40 m (about 1e-12 m) when a scene is materialised, and
// translations are multiples of it below 2^12 m: x + t is then exact, so a translated scene starts
// from exactly the image of the original's state and any difference its results show comes from
// arithmetic on absolute coordinates, which is what a translation test is for. Quarter turns and
// mirrors are exact on any double.
inline constexpr double kGrid = 0x1.0p-40;
// Each particle is moved by up to this fraction of its radius (a fixed pattern, the same in every
// map) when a scene is materialised: the laws are checked off the model's exact ties. A lattice
// has disks touching to the last bit, forces that cancel to the bit and velocities that are 0
// exactly, where a contact's onset (its dashpot engages at once) and local damping's sign(v) are
// discontinuous: there one rounding, which every map changes, decides which side the run takes.
// One part in 1e7 of a radius is far below any physical tolerance and well above the grid.
inline constexpr double kJitter = 1e-7;
double SnapToGrid(double v);

// x' = R x + t, with R one of the three below.
enum class Turn {
  kNone,     // R = I
  kQuarter,  // R (x, y) = (-y, x): counter-clockwise by 90 degrees
  kMirrorX,  // R (x, y) = (-x, y): the mirror in the y axis
};

struct SceneMap {
  Turn turn = Turn::kNone;
  double tx = 0.0, ty = 0.0;

  // The point's and the vector's images.
  void Point(double x, double y, double* ox, double* oy) const;
  void Vector(double x, double y, double* ox, double* oy) const;
  std::string Name() const;
};

// The image of `scene` under `map`, or the reason the map cannot be expressed as a scene (e.g. a
// closed inlet that would have to move to the outlet's end: the format puts the inlet at the low
// end of the axis). The packing is materialised (BuildScenePacking) and carried as a list.
struct MappedScene {
  std::optional<SceneSpec> scene;
  std::string why_not;
};
MappedScene MapScene(const SceneSpec& scene, const SceneMap& map);

// The scene with its packing materialised as a particle list (the identity map's image): the
// reference a mapped scene is compared with, so that both start from the same particle list.
SceneSpec MaterialisedScene(const SceneSpec& scene);

// The side a side wall goes to.
WallSide MapSide(WallSide side, Turn turn);

}  // namespace seep::core::metamorphic
