// CellGrid neighbour queries against an O(N^2) reference, open and periodic.
#include "seep/core/geometry/cell_grid.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <tuple>
#include <vector>

#include "seep/core/geometry/random_packing.h"

namespace seep::core {
namespace {

struct Points {
  std::vector<double> x, y;
  void Add(double px, double py) {
    x.push_back(px);
    y.push_back(py);
  }
};

struct Pair {
  std::int32_t a, b;
  double dx, dy;
  bool operator==(const Pair&) const = default;
};

bool ByIds(const Pair& p, const Pair& q) { return std::tie(p.a, p.b) < std::tie(q.a, q.b); }

// The shortest of the images d - m L, m = -2..2, written out on its own (not by rounding).
double ShortestImage(double d, const CellGridAxis& axis) {
  if (!axis.periodic) return d;
  double best = d;
  for (int m = -2; m <= 2; ++m) {
    const double image = d - axis.period * static_cast<double>(m);
    if (std::abs(image) < std::abs(best)) best = image;
  }
  return best;
}

std::vector<Pair> BruteForcePairs(const Points& p, const CellGridOptions& o) {
  std::vector<Pair> out;
  for (std::size_t a = 0; a < p.x.size(); ++a) {
    for (std::size_t b = a + 1; b < p.x.size(); ++b) {
      const double dx = ShortestImage(p.x[b] - p.x[a], o.x);
      const double dy = ShortestImage(p.y[b] - p.y[a], o.y);
      if (dx * dx + dy * dy < o.reach * o.reach) {
        out.push_back({static_cast<std::int32_t>(a), static_cast<std::int32_t>(b), dx, dy});
      }
    }
  }
  return out;
}

// Every visited pair once (b > a), filtered by distance and sorted.
std::vector<Pair> GridPairs(const Points& p, const CellGridOptions& o) {
  CellGrid grid;
  EXPECT_TRUE(grid.Build(p.x, p.y, o).ok());
  std::vector<Pair> visited, near;
  for (std::size_t a = 0; a < p.x.size(); ++a) {
    const auto ia = static_cast<std::int32_t>(a);
    grid.ForEachNeighbour(ia, [&](std::int32_t b, double dx, double dy) {
      visited.push_back({ia, b, dx, dy});
      if (dx * dx + dy * dy < o.reach * o.reach) near.push_back({ia, b, dx, dy});
    });
  }
  std::sort(visited.begin(), visited.end(), ByIds);
  for (std::size_t k = 0; k < visited.size(); ++k) {
    EXPECT_LT(visited[k].a, visited[k].b);
    if (k > 0) {
      EXPECT_TRUE(ByIds(visited[k - 1], visited[k])) << "pair visited twice";
    }
  }
  std::sort(near.begin(), near.end(), ByIds);
  return near;
}

// Uniform random points over [x0, x0 + lx) x [y0, y0 + ly).
Points RandomPoints(std::size_t n, std::uint64_t seed, double x0, double lx, double y0, double ly) {
  std::mt19937_64 rng(seed);
  Points p;
  for (std::size_t k = 0; k < n; ++k) {
    p.Add(x0 + lx * UniformUnit(rng()), y0 + ly * UniformUnit(rng()));
  }
  return p;
}

bool HasPair(const std::vector<Pair>& pairs, std::int32_t a, std::int32_t b) {
  return std::any_of(pairs.begin(), pairs.end(),
                     [&](const Pair& p) { return p.a == a && p.b == b; });
}

TEST(CellGrid, OpenGridMatchesBruteForce) {
  const Points p = RandomPoints(2000, 7, -3.0, 40.0, 2.0, 25.0);
  CellGridOptions o;
  o.reach = 1.1;
  const std::vector<Pair> want = BruteForcePairs(p, o);
  ASSERT_GT(want.size(), 1000u);
  EXPECT_EQ(GridPairs(p, o), want);
}

TEST(CellGrid, PeriodicPairsAcrossEachBoundaryAndTheCornersMatchBruteForce) {
  const double x0 = -2.0, lx = 10.0, y0 = 1.0, ly = 8.0;
  Points p = RandomPoints(300, 11, x0, lx, y0, ly);
  const auto first = static_cast<std::int32_t>(p.x.size());
  p.Add(x0 + 0.1, y0 + 4.0);  // across x = x0
  p.Add(x0 + lx - 0.2, y0 + 4.1);
  p.Add(x0 + 5.0, y0 + 0.05);  // across y = y0
  p.Add(x0 + 5.1, y0 + ly - 0.3);
  p.Add(x0 + 0.1, y0 + 0.1);  // across the corner (x0, y0)
  p.Add(x0 + lx - 0.1, y0 + ly - 0.1);
  p.Add(x0 + 0.2, y0 + ly - 0.2);  // across the other diagonal
  p.Add(x0 + lx - 0.15, y0 + 0.15);
  p.Add(x0 + lx + 0.3, y0 + 6.0);  // one period outside in x, near the next point's image
  p.Add(x0 + 0.1, y0 + 6.2);
  for (const auto& [px, py] :
       {std::pair{true, true}, std::pair{true, false}, std::pair{false, true}}) {
    CellGridOptions o;
    o.reach = 0.9;
    o.x = {px, x0, lx};
    o.y = {py, y0, ly};
    SCOPED_TRACE(::testing::Message() << "periodic x " << px << ", y " << py);
    const std::vector<Pair> want = BruteForcePairs(p, o);
    EXPECT_EQ(GridPairs(p, o), want);
    EXPECT_EQ(HasPair(want, first, first + 1), px);
    EXPECT_EQ(HasPair(want, first + 2, first + 3), py);
    EXPECT_EQ(HasPair(want, first + 4, first + 5), px && py);
    EXPECT_EQ(HasPair(want, first + 6, first + 7), px && py);
    EXPECT_EQ(HasPair(want, first + 8, first + 9), px);
  }
}

TEST(CellGrid, SparsePointsWidenTheCells) {
  Points p = RandomPoints(200, 3, 0.0, 5.0, 0.0, 5.0);
  p.Add(1e7, -1e7);
  CellGridOptions o;
  o.reach = 0.5;
  EXPECT_EQ(GridPairs(p, o), BruteForcePairs(p, o));
  CellGrid grid;
  ASSERT_TRUE(grid.Build(p.x, p.y, o).ok());
  EXPECT_LT(grid.MemoryBytes(), 20000u);
}

TEST(CellGrid, RejectsBadOptionsAndHandlesEmpty) {
  CellGrid grid;
  const std::vector<double> none;
  CellGridOptions o;
  o.reach = 1.0;
  EXPECT_TRUE(grid.Build(none, none, o).ok());
  EXPECT_EQ(grid.size(), 0u);
  const std::vector<double> one{0.0}, two{0.0, 1.0};
  EXPECT_FALSE(grid.Build(one, two, o).ok());
  o.reach = 0.0;
  EXPECT_FALSE(grid.Build(one, one, o).ok());
  // A subnormal reach: its inverse is inf (it binned points at NaN, outside the cells).
  o.reach = 5e-324;
  const std::vector<double> tiny{0.0, 1e-323, 2e-323};
  const Status subnormal = grid.Build(tiny, tiny, o);
  EXPECT_EQ(subnormal.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(subnormal.message().find("finite normal number > 0 (got 5e-324)"), std::string::npos)
      << subnormal.message();
  o.reach = 1.0;
  o.x = {true, 0.0, 2.9};  // fewer than 3 cells of the reach
  const Status short_period = grid.Build(one, one, o);
  EXPECT_EQ(short_period.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(short_period.message().find("at least 3 cells"), std::string::npos);
  o.x = {true, 0.0, 3.0};
  EXPECT_TRUE(grid.Build(one, one, o).ok());
}

}  // namespace
}  // namespace seep::core
