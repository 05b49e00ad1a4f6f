// VTK XML ASCII writers (see vtk_writer.h).
#include "vtk_writer.h"

#include <fmt/format.h>

#include <cstddef>

namespace seep::client {
namespace {

// <DataArray> with the values on one line per 6 numbers (readable, and short lines for diff).
template <typename T>
void AppendArray(std::string* out, const char* type, const std::string& name, int components,
                 const std::vector<T>& values) {
  *out += fmt::format("        <DataArray type=\"{}\" Name=\"{}\"", type, name);
  if (components > 1) *out += fmt::format(" NumberOfComponents=\"{}\"", components);
  *out += " format=\"ascii\">\n";
  for (std::size_t i = 0; i < values.size(); ++i) {
    *out += (i % 6 == 0 ? "          " : " ") + fmt::format("{}", values[i]);
    if (i % 6 == 5 || i + 1 == values.size()) *out += "\n";
  }
  *out += "        </DataArray>\n";
}

std::string PointsSection(const std::vector<double>& x, const std::vector<double>& y) {
  std::vector<double> xyz;
  xyz.reserve(3 * x.size());
  for (std::size_t i = 0; i < x.size(); ++i) {
    xyz.push_back(x[i]);
    xyz.push_back(y[i]);
    xyz.push_back(0.0);
  }
  std::string out = "      <Points>\n";
  AppendArray(&out, "Float64", "Points", 3, xyz);
  return out + "      </Points>\n";
}

// Point or cell data; the first array is the active scalar.
std::string DataSection(const char* tag, const std::vector<VtkArray>& arrays) {
  if (arrays.empty()) return {};
  std::string out = fmt::format("      <{} Scalars=\"{}\">\n", tag, arrays.front().name);
  for (const VtkArray& a : arrays) AppendArray(&out, "Float64", a.name, 1, a.values);
  return out + fmt::format("      </{}>\n", tag);
}

// connectivity + offsets (VTK's offsets are the end of each cell).
std::string CellArrays(const char* tag, const std::vector<std::int64_t>& connectivity,
                       const std::vector<std::int64_t>& ends) {
  std::string out = fmt::format("      <{}>\n", tag);
  AppendArray(&out, "Int64", "connectivity", 1, connectivity);
  AppendArray(&out, "Int64", "offsets", 1, ends);
  return out;
}

std::string Document(const char* type, const std::string& piece) {
  return fmt::format(
      "<?xml version=\"1.0\"?>\n"
      "<VTKFile type=\"{0}\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
      "  <{0}>\n{1}  </{0}>\n</VTKFile>\n",
      type, piece);
}

}  // namespace

std::string VtkPointCloud(const std::vector<double>& x, const std::vector<double>& y,
                          const std::vector<VtkArray>& point_data) {
  std::vector<std::int64_t> ids(x.size());
  std::vector<std::int64_t> ends(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) {
    ids[i] = static_cast<std::int64_t>(i);
    ends[i] = static_cast<std::int64_t>(i + 1);
  }
  std::string piece = fmt::format(
      "    <Piece NumberOfPoints=\"{}\" NumberOfVerts=\"{}\" NumberOfLines=\"0\" "
      "NumberOfStrips=\"0\" NumberOfPolys=\"0\">\n",
      x.size(), x.size());
  piece += PointsSection(x, y);
  piece += CellArrays("Verts", ids, ends) + "      </Verts>\n";
  piece += DataSection("PointData", point_data);
  return Document("PolyData", piece + "    </Piece>\n");
}

std::string VtkSegments(const std::vector<double>& x0, const std::vector<double>& y0,
                        const std::vector<double>& x1, const std::vector<double>& y1,
                        const std::vector<VtkArray>& cell_data) {
  const std::size_t n = x0.size();
  std::vector<double> px;
  std::vector<double> py;
  std::vector<std::int64_t> ids;
  std::vector<std::int64_t> ends;
  for (std::size_t k = 0; k < n; ++k) {
    px.insert(px.end(), {x0[k], x1[k]});
    py.insert(py.end(), {y0[k], y1[k]});
    ids.insert(ids.end(), {static_cast<std::int64_t>(2 * k), static_cast<std::int64_t>(2 * k + 1)});
    ends.push_back(static_cast<std::int64_t>(2 * k + 2));
  }
  std::string piece = fmt::format(
      "    <Piece NumberOfPoints=\"{}\" NumberOfVerts=\"0\" NumberOfLines=\"{}\" "
      "NumberOfStrips=\"0\" NumberOfPolys=\"0\">\n",
      2 * n, n);
  piece += PointsSection(px, py);
  piece += CellArrays("Lines", ids, ends) + "      </Lines>\n";
  piece += DataSection("CellData", cell_data);
  return Document("PolyData", piece + "    </Piece>\n");
}

std::string VtkPolygons(const std::vector<double>& x, const std::vector<double>& y,
                        const std::vector<std::int32_t>& offsets,
                        const std::vector<std::int32_t>& connectivity,
                        const std::vector<VtkArray>& cell_data) {
  constexpr int kVtkPolygon = 7;
  const std::size_t cells = offsets.empty() ? 0 : offsets.size() - 1;
  const std::vector<std::int64_t> ids(connectivity.begin(), connectivity.end());
  const std::vector<std::int64_t> ends(offsets.begin() + (offsets.empty() ? 0 : 1), offsets.end());
  const std::vector<int> types(cells, kVtkPolygon);
  std::string piece =
      fmt::format("    <Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">\n", x.size(), cells);
  piece += PointsSection(x, y);
  piece += CellArrays("Cells", ids, ends);
  AppendArray(&piece, "UInt8", "types", 1, types);
  piece += "      </Cells>\n";
  piece += DataSection("CellData", cell_data);
  return Document("UnstructuredGrid", piece + "    </Piece>\n");
}

}  // namespace seep::client
