// Packing: a set of 2D disks stored field by field (structure of arrays), plus the regular
// lattices used by the verification tests.
//
// Ids and units:
//   - A particle's id is its index in the arrays: 0 .. size()-1. Every other geometry object
//     (contacts, domain loops, pipes) refers to particles by this id.
//   - x, y are the disk centre, radius its radius; SI lengths (m) in a physical scene, or the
//     reduced units of the input file. Nothing here assumes a unit.
//
// The arrays are separate vectors rather than a vector of structs because the hot loops (contact
// detection, face tracing, later the DEM step) read one or two fields of many particles.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "seep/core/status.h"

namespace seep::core {

struct Packing {
  std::vector<double> x;       // centre x
  std::vector<double> y;       // centre y
  std::vector<double> radius;  // > 0

  std::size_t size() const { return x.size(); }
  void Reserve(std::size_t n);
  void Add(double px, double py, double r);
  void Clear();
  // Heap bytes held by the arrays (capacity, not size), for memory reports.
  std::size_t MemoryBytes() const;
};

// Checks that the three arrays have equal length, every coordinate is finite and every radius is
// finite and > 0. The message names the field and the particle, e.g.
//   "packing: radius[12] must be finite and > 0 (got -0.5)".
Status ValidatePacking(const Packing& packing);

// nx * ny touching equal disks on a square lattice. Particle (i, j), i in [0, nx), j in [0, ny),
// has id j * nx + i (row-major, rows along x) and centre ((2i+1)R, (2j+1)R), so the lattice fills
// [0, 2 nx R] x [0, 2 ny R] and neighbours are exactly 2R apart.
Result<Packing> SquareLattice(int nx, int ny, double radius);

// nx * ny touching equal disks on a hexagonal (triangular) lattice. Particle (i, j) has id
// j * nx + i and centre ((2i+1+(j mod 2))R, (1+j*sqrt(3))R): odd rows are shifted right by R and
// rows are sqrt(3)R apart, so each disk touches two disks on its own row and two on each of the
// neighbouring rows (fewer on the edges).
Result<Packing> HexLattice(int nx, int ny, double radius);

}  // namespace seep::core
