// Pipe apertures from per-contact force and gap (docs/physics.md §2.3, seed eqs. 2-3).
#include "seep/core/coupling/contact_apertures.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <span>
#include <string>
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

// Per-contact data of a lattice: compressed, tensile and open, overlapping (negative gap) and
// zero contacts, varied with `round` so that every update changes apertures.
void FillContacts(std::size_t round, std::vector<double>* force, std::vector<double>* gap) {
  for (std::size_t c = 0; c < force->size(); ++c) {
    const double k = static_cast<double>((c * 7 + round * 3) % 11);
    switch ((c + round) % 4) {
      case 0:  // compressed: eq. 2, the gap ignored
        (*force)[c] = 37.0 * k + 1.0;
        (*gap)[c] = -1e-6 * k;
        break;
      case 1:  // tensile and open: eq. 3, capped at a_max for the widest gaps
        (*force)[c] = -5.0 * k;
        (*gap)[c] = 3e-6 * k;
        break;
      case 2:  // untouched but overlapping: eq. 3 with g counted as 0
        (*force)[c] = 0.0;
        (*gap)[c] = -2e-7 * k;
        break;
      default:  // open without force
        (*force)[c] = 0.0;
        (*gap)[c] = 1e-6 * k;
        break;
    }
  }
}

std::vector<double> Copy(std::span<const double> v) {
  return std::vector<double>(v.begin(), v.end());
}

// UpdatePerPipe is what the coupled loop calls with force and gap read per pipe from the DEM pair
// table; Update gathers the per-contact arrays into the same per-pipe form. On two identical
// networks, one updated each way over three rounds of data, apertures and conductances must be
// the same bits, each bound aperture the law's (aperture_law.h Aperture, bit for bit: the
// branch-free kernel must not round differently), and a pipe bound to contact -1 keeps its own
// aperture even when its per-pipe entries are NaN (they are ignored).
TEST(ContactApertures, PerPipeUpdateIsBitIdenticalToPerContactUpdate) {
  ApertureLaw law = Law();
  law.max_aperture = 2e-5;  // reached by the wider open gaps: the clamp is exercised
  LatticePipes by_contact = MakeLatticePipes();
  LatticePipes by_pipe = MakeLatticePipes();
  const std::size_t num_pipes = by_pipe.flow.num_pipes();
  ASSERT_GT(num_pipes, 20u);
  // Pipe 4 stands for no contact and starts at an aperture the law gives to no datum below
  // (above a_max: the clamp does not apply to it either).
  constexpr std::size_t kUnbound = 4;
  constexpr double kKept = 3.3e-5;
  std::vector<double> start(num_pipes, kA0);
  start[kUnbound] = kKept;
  for (LatticePipes* s : {&by_contact, &by_pipe}) {
    s->pipe_contact[kUnbound] = -1;
    ASSERT_TRUE(s->flow.SetApertures(start, kMu).ok());
  }
  auto per_contact = ContactApertureUpdater::Create(law, kMu);
  auto per_pipe = ContactApertureUpdater::Create(law, kMu);
  ASSERT_TRUE(per_contact.ok() && per_pipe.ok());
  ASSERT_TRUE(per_contact->Bind(by_contact.flow, by_contact.pipe_contact).ok());
  ASSERT_TRUE(per_pipe->Bind(by_pipe.flow, by_pipe.pipe_contact).ok());

  const std::size_t num_contacts = by_pipe.d.contacts.size();
  std::vector<double> force(num_contacts), gap(num_contacts);
  std::vector<double> pipe_force(num_pipes), pipe_gap(num_pipes);
  for (std::size_t round = 0; round < 3; ++round) {
    SCOPED_TRACE("round " + std::to_string(round));
    FillContacts(round, &force, &gap);
    for (std::size_t p = 0; p < num_pipes; ++p) {
      const std::int32_t c = by_pipe.pipe_contact[p];
      pipe_force[p] = c < 0 ? std::nan("") : force[static_cast<std::size_t>(c)];
      pipe_gap[p] = c < 0 ? std::nan("") : gap[static_cast<std::size_t>(c)];
    }
    const auto a = per_contact->Update(by_contact.flow, force, gap);
    const auto b = per_pipe->UpdatePerPipe(by_pipe.flow, pipe_force, pipe_gap);
    ASSERT_TRUE(a.ok()) << a.status().ToString();
    ASSERT_TRUE(b.ok()) << b.status().ToString();
    EXPECT_GT(b->pipes_changed, 0);
    EXPECT_EQ(a->pipes_changed, b->pipes_changed);
    EXPECT_EQ(a->network_written, b->network_written);
    EXPECT_EQ(Copy(by_contact.flow.pipe_aperture()), Copy(by_pipe.flow.pipe_aperture()));
    EXPECT_EQ(Copy(by_contact.flow.pipe_conductance()), Copy(by_pipe.flow.pipe_conductance()));
    std::size_t capped = 0;
    for (std::size_t p = 0; p < num_pipes; ++p) {
      const double want = p == kUnbound ? kKept : Aperture(law, pipe_force[p], pipe_gap[p]);
      EXPECT_EQ(by_pipe.flow.pipe_aperture()[p], want) << "pipe " << p;
      capped += want == law.max_aperture;
    }
    EXPECT_GT(capped, 0u);
    EXPECT_EQ(by_pipe.flow.pipe_conductance()[kUnbound],
              PipeConductance(kKept, kMu, by_pipe.flow.pipe_length()[kUnbound]));
  }
}

// A non-finite force or gap on one bound pipe is refused naming its contact and pipe, before
// anything is written: apertures, conductances and the coefficient stamp stay as they were (so
// the solvers' caches stay valid). Arrays that are not one entry per pipe are refused too.
TEST(ContactApertures, PerPipeBadInputLeavesTheNetworkUntouched) {
  LatticePipes s = MakeLatticePipes();
  auto updater = ContactApertureUpdater::Create(Law(), kMu);
  ASSERT_TRUE(updater.ok());
  ASSERT_TRUE(updater->Bind(s.flow, s.pipe_contact).ok());
  const std::size_t num_pipes = s.flow.num_pipes();
  // Every pipe compressed: a valid update would change every aperture.
  std::vector<double> force(num_pipes, 1e3), gap(num_pipes, 0.0);
  const std::vector<double> apertures = Copy(s.flow.pipe_aperture());
  const std::vector<double> conductances = Copy(s.flow.pipe_conductance());
  const std::uint64_t stamp = s.flow.coefficient_version();
  auto expect_untouched = [&](const char* what) {
    EXPECT_EQ(Copy(s.flow.pipe_aperture()), apertures) << what;
    EXPECT_EQ(Copy(s.flow.pipe_conductance()), conductances) << what;
    EXPECT_EQ(s.flow.coefficient_version(), stamp) << what;
  };

  force[5] = std::nan("");
  auto nan_force = updater->UpdatePerPipe(s.flow, force, gap);
  EXPECT_EQ(nan_force.status().code(), StatusCode::kInvalidArgument);
  const std::string named5 =
      "coupling.contact_apertures: contact " + std::to_string(s.pipe_contact[5]) + " (pipe 5): ";
  EXPECT_EQ(nan_force.status().message().rfind(named5, 0), 0u) << nan_force.status().message();
  expect_untouched("NaN force");
  force[5] = 1e3;

  gap[9] = std::numeric_limits<double>::infinity();
  auto inf_gap = updater->UpdatePerPipe(s.flow, force, gap);
  EXPECT_EQ(inf_gap.status().code(), StatusCode::kInvalidArgument);
  const std::string named9 =
      "coupling.contact_apertures: contact " + std::to_string(s.pipe_contact[9]) + " (pipe 9): ";
  EXPECT_EQ(inf_gap.status().message().rfind(named9, 0), 0u) << inf_gap.status().message();
  expect_untouched("infinite gap");
  gap[9] = 0.0;

  const std::vector<double> short_force(num_pipes - 1, 1e3), long_gap(num_pipes + 1, 0.0);
  const auto short_status = updater->UpdatePerPipe(s.flow, short_force, gap).status();
  EXPECT_EQ(short_status.code(), StatusCode::kInvalidArgument);
  EXPECT_NE(
      short_status.message().find("pipe_force and pipe_gap have " + std::to_string(num_pipes - 1) +
                                  " and " + std::to_string(num_pipes) + " entries"),
      std::string::npos)
      << short_status.message();
  EXPECT_EQ(updater->UpdatePerPipe(s.flow, force, long_gap).status().code(),
            StatusCode::kInvalidArgument);
  expect_untouched("wrong sizes");

  // The same arrays, valid, do write: the refusals above were about the bad entries.
  const auto ok = updater->UpdatePerPipe(s.flow, force, gap);
  ASSERT_TRUE(ok.ok()) << ok.status().ToString();
  EXPECT_EQ(ok->pipes_changed, static_cast<std::int64_t>(num_pipes));
  EXPECT_NE(s.flow.coefficient_version(), stamp);
}

}  // namespace
}  // namespace seep::core
