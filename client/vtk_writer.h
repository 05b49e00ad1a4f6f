// VTK XML files in ASCII (the formats ParaView and python3-vtk9 read), written by hand: Debian
// has no library lighter than VTK itself for writing them. Values are printed in their shortest
// round-trip form, so nothing is lost. 2D data: every point gets z = 0.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace seep::client {

// One value per point (or per cell) under `name`.
struct VtkArray {
  std::string name;
  std::vector<double> values;
};

// PolyData of free points (one vertex cell each), e.g. particle centres with their radius as
// point data (ParaView: Glyph filter, sphere, scale by "radius_m", factor 2).
std::string VtkPointCloud(const std::vector<double>& x, const std::vector<double>& y,
                          const std::vector<VtkArray>& point_data);

// PolyData of straight segments (x0, y0) -> (x1, y1), one line cell each, with cell data.
std::string VtkSegments(const std::vector<double>& x0, const std::vector<double>& y0,
                        const std::vector<double>& x1, const std::vector<double>& y1,
                        const std::vector<VtkArray>& cell_data);

// UnstructuredGrid of polygons over shared points: polygon k has the point ids
// connectivity[offsets[k] .. offsets[k + 1] - 1] (CSR, offsets.size() = polygons + 1).
std::string VtkPolygons(const std::vector<double>& x, const std::vector<double>& y,
                        const std::vector<std::int32_t>& offsets,
                        const std::vector<std::int32_t>& connectivity,
                        const std::vector<VtkArray>& cell_data);

}  // namespace seep::client
