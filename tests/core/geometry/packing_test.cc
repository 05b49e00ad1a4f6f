// Packing containers, lattice generators, validation and the text loader.
#include "seep/core/geometry/packing.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <string>

#include "seep/core/geometry/packing_file.h"

namespace seep::core {
namespace {

TEST(Packing, SquareLatticeLayout) {
  const double R = 0.25;
  const Packing p = SquareLattice(4, 3, R).value();
  ASSERT_EQ(p.size(), 12u);
  // Particle (i, j) has id j * nx + i and centre ((2i+1)R, (2j+1)R).
  EXPECT_DOUBLE_EQ(p.x[1 * 4 + 2], 5 * R);
  EXPECT_DOUBLE_EQ(p.y[1 * 4 + 2], 3 * R);
  EXPECT_DOUBLE_EQ(p.radius[7], R);
  EXPECT_FALSE(SquareLattice(0, 3, R).ok());
  EXPECT_FALSE(SquareLattice(3, 3, -1.0).ok());
}

TEST(Packing, HexLatticeLayout) {
  const double R = 2.0;
  const Packing p = HexLattice(5, 4, R).value();
  ASSERT_EQ(p.size(), 20u);
  EXPECT_DOUBLE_EQ(p.x[0], R);
  EXPECT_DOUBLE_EQ(p.x[5], 2 * R);  // odd row shifted by R
  EXPECT_DOUBLE_EQ(p.y[5], R + std::sqrt(3.0) * R);
  // Cross-row neighbours are exactly 2R apart.
  EXPECT_NEAR(std::hypot(p.x[5] - p.x[0], p.y[5] - p.y[0]), 2 * R, 1e-14);
  EXPECT_NEAR(std::hypot(p.x[5] - p.x[1], p.y[5] - p.y[1]), 2 * R, 1e-14);
}

TEST(Packing, ValidationNamesTheField) {
  Packing p = SquareLattice(2, 2, 1.0).value();
  EXPECT_TRUE(ValidatePacking(p).ok());
  p.radius[3] = 0.0;
  Status s = ValidatePacking(p);
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(s.message().find("radius[3]"), std::string::npos) << s.message();
  p.radius[3] = 1.0;
  p.y[2] = std::numeric_limits<double>::quiet_NaN();
  s = ValidatePacking(p);
  EXPECT_NE(s.message().find("y[2]"), std::string::npos) << s.message();
  p.y[2] = 0.0;
  p.x.push_back(1.0);
  EXPECT_FALSE(ValidatePacking(p).ok());
}

TEST(PackingFile, ParsesCommentsAndBlankLines) {
  const Result<Packing> p =
      ParsePackingText("# header\n\n1 2 0.5\n  3\t4 0.25  # trailing\n\r\n5 6 +1e-1\n", "mem");
  ASSERT_TRUE(p.ok()) << p.status().ToString();
  ASSERT_EQ(p->size(), 3u);
  EXPECT_DOUBLE_EQ(p->x[1], 3.0);
  EXPECT_DOUBLE_EQ(p->y[1], 4.0);
  EXPECT_DOUBLE_EQ(p->radius[2], 0.1);
}

void ExpectError(const std::string& text, const std::string& needle) {
  const Result<Packing> p = ParsePackingText(text, "bed.txt");
  ASSERT_FALSE(p.ok()) << "accepted: " << text;
  EXPECT_EQ(p.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(p.status().message().find("bed.txt"), std::string::npos) << p.status().message();
  EXPECT_NE(p.status().message().find(needle), std::string::npos) << p.status().message();
}

TEST(PackingFile, ErrorsNameFileLineAndReason) {
  ExpectError("1 2 0.5\n# c\n1 x 0.5\n", "line 3: y is not a number");
  ExpectError("1 2 0.5\n1 2 0\n", "line 2: radius must be > 0");
  ExpectError("1 2 -3\n", "line 1: radius must be > 0");
  ExpectError("\n1 2\n", "line 2: expected 3 fields");
  ExpectError("1 2 3 4\n", "line 1: expected 3 fields 'x y radius', got 4");
  ExpectError("1 2 0.5abc\n", "line 1: radius is not a number");
  ExpectError("inf 2 0.5\n", "line 1: x must be finite");
  ExpectError("# only comments\n\n", "no particles");
  ExpectError("", "no particles");
}

TEST(PackingFile, LoadsFromDiskAndReportsMissingFile) {
  const std::string path = ::testing::TempDir() + "/seep_packing_file_test.txt";
  {
    std::ofstream out(path);
    out << "# x y r\n0 0 1\n2 0 1\n";
  }
  const Result<Packing> p = LoadPackingFile(path);
  ASSERT_TRUE(p.ok()) << p.status().ToString();
  EXPECT_EQ(p->size(), 2u);
  {
    std::ofstream out(path);
    out << "0 0 1\n2 0 one\n";
  }
  const Result<Packing> bad = LoadPackingFile(path);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find(path + "' line 2"), std::string::npos)
      << bad.status().message();
  std::remove(path.c_str());
  EXPECT_EQ(LoadPackingFile(path).status().code(), StatusCode::kNotFound);
}

}  // namespace
}  // namespace seep::core
