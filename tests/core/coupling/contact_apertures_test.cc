// Pipe apertures from per-contact force and gap (physics.md §2.3, seed eqs. 2-3).
#include "seep/core/coupling/contact_apertures.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "coupling_test_util.h"

namespace seep::core {
namespace {

constexpr double kA0 = 1e-5;
constexpr double kF0 = 200.0;
constexpr double kM = 0.5;
constexpr double kMu = 1e-3;

ApertureLaw Law() {
  ApertureLaw law;
  law.residual_aperture = kA0;
  law.reference_force = kF0;
  law.gap_multiplier = kM;
  return law;
}

// A square lattice's domain pipes as a FlowNetwork, all apertures a0; pipe p is contact
// domains.pipe_contact[p].
struct LatticePipes {
  coupling_test::Detected d;
  FlowNetwork flow;
  std::vector<std::int32_t> pipe_contact;
};

LatticePipes MakeLatticePipes() {
  LatticePipes s{coupling_test::Detect(coupling_test::Square(6, 5, 1e-3)), FlowNetwork(), {}};
  const DomainNetwork& n = s.d.domains;
  FlowNetworkData data;
  data.apparent_volume = n.apparent_volume;
  data.pore_volume = n.pore_volume;
  data.pressure.assign(n.num_domains(), 0.0);
  data.role.assign(n.num_domains(), DomainRole::kFree);
  data.source_rate.assign(n.num_domains(), 0.0);
  data.pipe_domain_a = n.pipe_domain_a;
  data.pipe_domain_b = n.pipe_domain_b;
  data.pipe_length = n.pipe_length;
  data.pipe_aperture.assign(n.num_pipes(), kA0);
  for (double length : n.pipe_length)
    data.pipe_conductance.push_back(PipeConductance(kA0, kMu, length));
  auto flow = FlowNetwork::Create(std::move(data));
  EXPECT_TRUE(flow.ok()) << flow.status().ToString();
  s.flow = std::move(*flow);
  s.pipe_contact = n.pipe_contact;
  return s;
}

TEST(ContactApertures, UnchangedContactsLeaveTheNetworkUntouched) {
  LatticePipes s = MakeLatticePipes();
  auto updater = ContactApertureUpdater::Create(Law(), kMu);
  ASSERT_TRUE(updater.ok());
  ASSERT_TRUE(updater->Bind(s.flow, s.pipe_contact).ok());
  const std::vector<double> force(s.d.contacts.size(), 0.0), gap(s.d.contacts.size(), 0.0);
  const std::uint64_t stamp = s.flow.coefficient_version();
  auto report = updater->Update(s.flow, force, gap);
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  EXPECT_EQ(report->pipes_changed, 0);
  EXPECT_FALSE(report->network_written);
  EXPECT_EQ(s.flow.coefficient_version(), stamp);
}

// One compressed and one opened contact: exactly their pipes change, to the law's values
// (eq. 2: a0 F0/(F+F0); eq. 3: a0 + m g), conductance a^3/(12 mu L) (same expression as the
// flow area, so bit-equal); every other pipe keeps a0.
TEST(ContactApertures, ChangedContactsGetTheLawsAperture) {
  LatticePipes s = MakeLatticePipes();
  auto updater = ContactApertureUpdater::Create(Law(), kMu);
  ASSERT_TRUE(updater.ok());
  ASSERT_TRUE(updater->Bind(s.flow, s.pipe_contact).ok());
  std::vector<double> force(s.d.contacts.size(), 0.0), gap(s.d.contacts.size(), 0.0);
  const std::size_t compressed = 3, opened = 7;
  const auto c1 = static_cast<std::size_t>(s.pipe_contact[compressed]);
  const auto c2 = static_cast<std::size_t>(s.pipe_contact[opened]);
  force[c1] = 600.0;  // 3 F0: a = a0 / 4
  force[c2] = -50.0;  // tensile, open by 4e-6: a = a0 + 2e-6
  gap[c2] = 4e-6;
  gap[c1] = 1e-3;  // ignored in compression
  const std::uint64_t stamp = s.flow.coefficient_version();
  auto report = updater->Update(s.flow, force, gap);
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  EXPECT_EQ(report->pipes_changed, 2);
  EXPECT_TRUE(report->network_written);
  EXPECT_NE(s.flow.coefficient_version(), stamp);
  for (std::size_t p = 0; p < s.flow.num_pipes(); ++p) {
    const double expected = p == compressed ? kA0 * kF0 / (600.0 + kF0)
                            : p == opened   ? kA0 + kM * 4e-6
                                            : kA0;
    EXPECT_DOUBLE_EQ(s.flow.pipe_aperture()[p], expected) << "pipe " << p;
    EXPECT_EQ(s.flow.pipe_conductance()[p],
              PipeConductance(s.flow.pipe_aperture()[p], kMu, s.flow.pipe_length()[p]));
  }
  EXPECT_DOUBLE_EQ(s.flow.pipe_aperture()[compressed], kA0 / 4.0);
}

TEST(ContactApertures, BadInputLeavesTheNetworkUntouched) {
  LatticePipes s = MakeLatticePipes();
  auto updater = ContactApertureUpdater::Create(Law(), kMu);
  ASSERT_TRUE(updater.ok());
  ASSERT_TRUE(updater->Bind(s.flow, s.pipe_contact).ok());
  std::vector<double> force(s.d.contacts.size(), 1e3), gap(s.d.contacts.size(), 0.0);
  force[static_cast<std::size_t>(s.pipe_contact[5])] = std::nan("");
  const std::vector<double> before(s.flow.pipe_aperture().begin(), s.flow.pipe_aperture().end());
  auto report = updater->Update(s.flow, force, gap);
  EXPECT_EQ(report.status().code(), StatusCode::kInvalidArgument);
  const std::vector<double> short_force(2, 0.0), short_gap(2, 0.0);
  EXPECT_EQ(updater->Update(s.flow, short_force, short_gap).status().code(),
            StatusCode::kInvalidArgument);
  EXPECT_EQ(std::vector<double>(s.flow.pipe_aperture().begin(), s.flow.pipe_aperture().end()),
            before);

  ApertureLaw bad = Law();
  bad.reference_force = -1.0;
  auto rejected = ContactApertureUpdater::Create(bad, kMu);
  EXPECT_EQ(rejected.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(rejected.status().message().find("flow.aperture_law.reference_force"),
            std::string::npos);
  const std::vector<std::int32_t> wrong_size(3, 0);
  EXPECT_EQ(updater->Bind(s.flow, wrong_size).code(), StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace seep::core
