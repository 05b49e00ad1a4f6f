// Area shared by two overlapping disks (the "lens"), used to count overlap areas once when pore
// volumes are computed from disk sectors.
#pragma once

namespace seep::core {

// Area of the intersection of two disks of radii r1, r2 whose centres are `distance` apart:
// 0 when they do not overlap, pi*min(r1,r2)^2 when one contains the other. Same unit^2 as the
// inputs. The line of centres splits the lens into two halves of equal area.
double LensArea(double r1, double r2, double distance);

}  // namespace seep::core
