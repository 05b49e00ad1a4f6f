// Domain detection on the shared gravity-settled bed of 9,900 disks
// (SEEP_SHARED_DIR/bench/settled_bed_9900.txt). Skipped when the file is absent.
//
// Edge threshold: the bed was settled with a stiff linear spring, so touching disks overlap
// slightly (gap < 0) and a few neighbours hover just apart. Edges are pairs with
// gap <= 1e-3 * mean radius: every overlap counts, plus near-touching pairs whose gap is far
// below what changes a loop (1e-3 R moves no disk visibly), while open pores are not bridged.
#include <gtest/gtest.h>

#include <string>

#include "geometry_test_util.h"
#include "seep/core/geometry/contact_detection.h"
#include "seep/core/geometry/domain_detection.h"
#include "seep/core/geometry/packing_file.h"

namespace seep::core {
namespace {

class SettledBed : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string path = SEEP_SHARED_DIR "/bench/settled_bed_9900.txt";
    Result<Packing> loaded = LoadPackingFile(path);
    if (!loaded.ok() && loaded.status().code() == StatusCode::kNotFound) {
      GTEST_SKIP() << "shared bed not found: " << path;
    }
    ASSERT_TRUE(loaded.ok()) << loaded.status().ToString();
    packing_ = std::move(loaded).value();
    ASSERT_TRUE(ValidatePacking(packing_).ok());
    double mean = 0.0;
    for (const double r : packing_.radius) mean += r;
    mean /= static_cast<double>(packing_.size());
    max_gap_ = 1e-3 * mean;
    ASSERT_TRUE(detector_.Detect(packing_, max_gap_, &contacts_).ok());
    ASSERT_TRUE(domains_.Detect(packing_, contacts_, {}, &network_).ok());
  }

  Packing packing_;
  double max_gap_ = 0.0;
  ContactDetector detector_;
  ContactList contacts_;
  DomainDetector domains_;
  DomainNetwork network_;
};

TEST_F(SettledBed, LoadsAllDisks) {
  EXPECT_EQ(packing_.size(), 9900u);
  EXPECT_GT(network_.num_domains(), 4000u);  // about one domain per two disks in 2D
}

TEST_F(SettledBed, ContactsMatchBruteForce) {
  const ContactList want = testing::BruteForceContacts(packing_, max_gap_);
  EXPECT_EQ(contacts_.i, want.i);
  EXPECT_EQ(contacts_.j, want.j);
  EXPECT_EQ(contacts_.gap, want.gap);
}

TEST_F(SettledBed, EulerRelationHolds) {
  EXPECT_TRUE(testing::EulerHolds(network_))
      << "V " << network_.euler.vertices << " E " << network_.euler.edges << " F "
      << network_.euler.cycles << " C " << network_.euler.components;
  EXPECT_EQ(network_.num_outer_faces(), static_cast<std::size_t>(network_.euler.components));
  EXPECT_EQ(network_.num_nonpositive_domains, 0);
}

TEST_F(SettledBed, DomainAreasSumToOuterLoopArea) {
  const double outer = testing::SumTopLevelOuterArea(network_);
  EXPECT_NEAR(testing::Sum(network_.apparent_volume), outer, 1e-12 * outer);
}

TEST_F(SettledBed, PoreVolumesSumToOuterAreaMinusSolid) {
  const ContactList overlaps = testing::BruteForceContacts(packing_, 0.0);
  const double solid = testing::SolidInsideOuterLoops(packing_, overlaps, network_);
  const double sum_vd = testing::Sum(network_.apparent_volume);
  EXPECT_NEAR(testing::Sum(network_.pore_volume), sum_vd - solid, 1e-12 * sum_vd);
  for (std::size_t d = 0; d < network_.num_domains(); ++d) {
    EXPECT_GT(network_.pore_volume[d], 0.0) << "domain " << d;
  }
}

TEST_F(SettledBed, EveryContactIsPipeBoundaryPipeBridgeOrPruned) {
  // Pipes + boundary pipes + bridges (+ pruned edges) = edges of the pruned graph, and each pipe
  // joins two different domains.
  std::size_t live_edges = static_cast<std::size_t>(network_.euler.edges);
  EXPECT_LE(network_.num_pipes() + network_.num_boundary_pipes(), live_edges);
  for (std::size_t p = 0; p < network_.num_pipes(); ++p) {
    EXPECT_NE(network_.pipe_domain_a[p], network_.pipe_domain_b[p]);
  }
  // Each domain loop contact is either a pipe or a boundary pipe or a bridge: count loop sides.
  std::size_t sides = network_.loop_contacts.size();
  EXPECT_GE(sides, 2 * network_.num_pipes() + network_.num_boundary_pipes());
}

TEST_F(SettledBed, RedetectionIsIdentical) {
  DomainNetwork again;
  ASSERT_TRUE(domains_.Detect(packing_, contacts_, {}, &again).ok());
  EXPECT_EQ(again.loop_offsets, network_.loop_offsets);
  EXPECT_EQ(again.loop_particles, network_.loop_particles);
  EXPECT_EQ(again.loop_contacts, network_.loop_contacts);
  EXPECT_EQ(again.apparent_volume, network_.apparent_volume);
  EXPECT_EQ(again.pore_volume, network_.pore_volume);
  EXPECT_EQ(again.centroid_x, network_.centroid_x);
  EXPECT_EQ(again.pipe_domain_a, network_.pipe_domain_a);
  EXPECT_EQ(again.pipe_domain_b, network_.pipe_domain_b);
  EXPECT_EQ(again.pipe_contact, network_.pipe_contact);
  EXPECT_EQ(again.boundary_pipe_contact, network_.boundary_pipe_contact);
  EXPECT_EQ(again.outer_particles, network_.outer_particles);
  // A fresh detector agrees too (no state leaks between calls).
  const Result<DomainNetwork> fresh = DetectDomains(packing_, contacts_);
  ASSERT_TRUE(fresh.ok());
  EXPECT_EQ(fresh->loop_particles, network_.loop_particles);
  EXPECT_EQ(fresh->pore_volume, network_.pore_volume);
}

}  // namespace
}  // namespace seep::core
