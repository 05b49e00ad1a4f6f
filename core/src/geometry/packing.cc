#include "seep/core/geometry/packing.h"

#include <cmath>
#include <string>

namespace seep::core {

void Packing::Reserve(std::size_t n) {
  x.reserve(n);
  y.reserve(n);
  radius.reserve(n);
}

void Packing::Add(double px, double py, double r) {
  x.push_back(px);
  y.push_back(py);
  radius.push_back(r);
}

void Packing::Clear() {
  x.clear();
  y.clear();
  radius.clear();
}

std::size_t Packing::MemoryBytes() const {
  return sizeof(double) * (x.capacity() + y.capacity() + radius.capacity());
}

Status ValidatePacking(const Packing& packing) {
  if (packing.y.size() != packing.x.size() || packing.radius.size() != packing.x.size()) {
    return InvalidArgument("packing: x, y and radius must have the same length (got " +
                           std::to_string(packing.x.size()) + ", " +
                           std::to_string(packing.y.size()) + ", " +
                           std::to_string(packing.radius.size()) + ")");
  }
  for (std::size_t i = 0; i < packing.size(); ++i) {
    if (!std::isfinite(packing.x[i])) {
      return InvalidArgument("packing: x[" + std::to_string(i) + "] must be finite (got " +
                             std::to_string(packing.x[i]) + ")");
    }
    if (!std::isfinite(packing.y[i])) {
      return InvalidArgument("packing: y[" + std::to_string(i) + "] must be finite (got " +
                             std::to_string(packing.y[i]) + ")");
    }
    const double r = packing.radius[i];
    if (!std::isfinite(r) || !(r > 0.0)) {
      return InvalidArgument("packing: radius[" + std::to_string(i) +
                             "] must be finite and > 0 (got " + std::to_string(r) + ")");
    }
  }
  return Status::Ok();
}

namespace {

Status CheckLatticeArguments(const char* name, int nx, int ny, double radius) {
  if (nx < 1 || ny < 1) {
    return InvalidArgument(std::string(name) + ": nx and ny must be >= 1 (got " +
                           std::to_string(nx) + ", " + std::to_string(ny) + ")");
  }
  if (!std::isfinite(radius) || !(radius > 0.0)) {
    return InvalidArgument(std::string(name) + ": radius must be finite and > 0 (got " +
                           std::to_string(radius) + ")");
  }
  return Status::Ok();
}

}  // namespace

Result<Packing> SquareLattice(int nx, int ny, double radius) {
  SEEP_RETURN_IF_ERROR(CheckLatticeArguments("SquareLattice", nx, ny, radius));
  Packing p;
  p.Reserve(static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny));
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      p.Add((2 * i + 1) * radius, (2 * j + 1) * radius, radius);
    }
  }
  return p;
}

Result<Packing> HexLattice(int nx, int ny, double radius) {
  SEEP_RETURN_IF_ERROR(CheckLatticeArguments("HexLattice", nx, ny, radius));
  const double row_spacing = std::sqrt(3.0) * radius;
  Packing p;
  p.Reserve(static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny));
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      p.Add((2 * i + 1 + (j % 2)) * radius, radius + j * row_spacing, radius);
    }
  }
  return p;
}

}  // namespace seep::core
