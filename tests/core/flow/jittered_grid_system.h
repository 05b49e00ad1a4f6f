// The tests' and seep_refactorization_bench's pressure-like system: a conductance Laplacian on a
// jittered grid (with one diagonal link in three cells, so that supernodes are irregular) plus a
// storage diagonal, as its lower triangle.
#pragma once

#include <Eigen/SparseCore>
#include <algorithm>
#include <cstdint>
#include <random>
#include <vector>

namespace seep::core::flow_test {

// The system on a width x height grid (numbered row by row); `seed` draws its conductances and
// storage.
inline Eigen::SparseMatrix<double, Eigen::ColMajor, int> GridSystem(int width, int height,
                                                                    std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> conductance(1e-3, 1.0);
  std::uniform_real_distribution<double> storage(1e-6, 1e-2);
  const int n = width * height;
  std::vector<Eigen::Triplet<double, int>> entries;
  std::vector<double> diagonal(static_cast<std::size_t>(n), 0.0);
  const auto link = [&](int a, int b) {
    const double c = conductance(rng);
    diagonal[a] += c;
    diagonal[b] += c;
    entries.emplace_back(std::max(a, b), std::min(a, b), -c);
  };
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const int u = y * width + x;
      if (x + 1 < width) link(u, u + 1);
      if (y + 1 < height) link(u, u + width);
      if (x + 1 < width && y + 1 < height && (x + y) % 3 == 0) link(u, u + width + 1);
    }
  }
  for (int u = 0; u < n; ++u) entries.emplace_back(u, u, diagonal[u] + storage(rng));
  Eigen::SparseMatrix<double, Eigen::ColMajor, int> lower(n, n);
  lower.setFromTriplets(entries.begin(), entries.end());
  lower.makeCompressed();
  return lower;
}

// The system on a side x side grid.
inline Eigen::SparseMatrix<double, Eigen::ColMajor, int> GridSystem(int side, std::uint64_t seed) {
  return GridSystem(side, side, seed);
}

}  // namespace seep::core::flow_test
