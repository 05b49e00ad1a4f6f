// Helpers shared by the coupling tests: packings with their contacts and domains.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <utility>

#include "seep/core/geometry/contact_detection.h"
#include "seep/core/geometry/domain_detection.h"
#include "seep/core/geometry/packing.h"
#include "seep/core/geometry/random_packing.h"

namespace seep::core::coupling_test {

struct Detected {
  Packing packing;
  ContactList contacts;
  DomainNetwork domains;
};

// Contacts within `gap_ratio` mean radii (lattice disks touch exactly only in theory, so a tiny
// positive tolerance keeps them in contact) and the faces of their graph.
inline Detected Detect(Packing packing, double gap_ratio = 1e-9) {
  Detected d;
  d.packing = std::move(packing);
  double mean = 0.0;
  for (double r : d.packing.radius) mean += r;
  mean /= static_cast<double>(d.packing.size());
  auto contacts = DetectContacts(d.packing, gap_ratio * mean);
  EXPECT_TRUE(contacts.ok()) << contacts.status().ToString();
  d.contacts = std::move(*contacts);
  auto domains = DetectDomains(d.packing, d.contacts);
  EXPECT_TRUE(domains.ok()) << domains.status().ToString();
  d.domains = std::move(*domains);
  return d;
}

inline Packing Square(int nx, int ny, double r) {
  auto p = SquareLattice(nx, ny, r);
  EXPECT_TRUE(p.ok());
  return std::move(*p);
}

inline Packing Hex(int nx, int ny, double r) {
  auto p = HexLattice(nx, ny, r);
  EXPECT_TRUE(p.ok());
  return std::move(*p);
}

// A seeded polydisperse packing (radii 0.8-1.0 before growth, porosity 0.2: a few rattlers).
inline Packing Random(std::uint64_t seed, int count = 300) {
  RandomPackingOptions o;
  o.count = count;
  o.width = 34.0;
  o.height = 17.0;
  o.seed = seed;
  o.porosity = 0.2;
  auto p = GenerateRandomPacking(o);
  EXPECT_TRUE(p.ok()) << p.status().ToString();
  return std::move(p->packing);
}

// `count` touching disks of radius r on a ring about the origin (ids 0 .. count-1, disk k at
// angle 2 pi k / count), enclosing one large void domain.
inline void AddRing(Packing* p, int count, double r) {
  const double pi = 3.14159265358979323846;
  const double ring_radius = r / std::sin(pi / count);
  for (int k = 0; k < count; ++k) {
    const double a = 2.0 * pi * k / count;
    p->Add(ring_radius * std::cos(a), ring_radius * std::sin(a), r);
  }
}

// Three touching disks of radius r about (cx, cy), rotated by `angle`: a one-domain island.
inline void AddTriangle(Packing* p, double cx, double cy, double r, double angle) {
  const double pi = 3.14159265358979323846;
  const double arm = 2.0 * r / std::sqrt(3.0);
  for (int k = 0; k < 3; ++k) {
    const double a = angle + 2.0 * pi * k / 3.0;
    p->Add(cx + arm * std::cos(a), cy + arm * std::sin(a), r);
  }
}

}  // namespace seep::core::coupling_test
