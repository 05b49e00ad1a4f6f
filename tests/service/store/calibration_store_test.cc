// The calibration records in the store: a real 5-target sweep stored and read back field by
// field, filters (k range AND porosity range, tags, dates), paging, epoch fencing, and the
// nearest-neighbour look-up with its log-log interpolation.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <map>
#include <set>

#include "seep/core/calibration/calibration.h"
#include "store/calibration_lookup.h"
#include "store/job_store.h"

namespace seep::service {
namespace {

constexpr double kTargets[] = {1e-14, 3e-14, 1e-13, 3e-13, 1e-12};

class CalibrationStoreTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("seep-calibration-store-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
    auto store = JobStore::Open((dir_ / "seep.db").string());
    ASSERT_TRUE(store.ok()) << store.status().ToString();
    store_ = std::move(*store);
  }
  void TearDown() override {
    store_.reset();
    std::filesystem::remove_all(dir_);
  }

  // Inserts a calibration job and claims it; returns the lease epoch to record with.
  std::int64_t InsertAndClaim(const std::string& id) {
    JobRecord job;
    job.id = id;
    job.name = id;
    job.kind = JobKind::kCalibration;
    job.scene = "x";
    job.build_id = "test";
    job.created_at_ms = 1;
    EXPECT_TRUE(store_->Insert(job).ok());
    auto claimed = store_->ClaimNextQueued("w", 10, 100000);
    EXPECT_TRUE(claimed.ok() && claimed->has_value());
    EXPECT_EQ((*claimed)->id, id);
    EXPECT_EQ((*claimed)->kind, JobKind::kCalibration);
    return (*claimed)->lease_epoch;
  }

  // A synthetic sweep of kTargets on one packing: a0 = c k^(1/3), as when every pipe's aperture
  // is proportional to a0, so log-log interpolation between two of them is exact.
  static std::vector<StoredCalibration> Sweep(const std::string& job, double porosity, double c,
                                              std::int64_t created_at_ms,
                                              const std::vector<std::string>& tags) {
    std::vector<StoredCalibration> out;
    for (std::size_t i = 0; i < std::size(kTargets); ++i) {
      StoredCalibration s;
      s.job_id = job;
      s.record.target_index = i;
      s.record.target_permeability_m2 = kTargets[i];
      s.record.residual_aperture_m = c * std::cbrt(kTargets[i]);
      s.record.permeability_m2 = kTargets[i] * (1 + 1e-9);
      s.record.relative_error = 1e-9;
      s.record.converged = true;
      s.record.iterations = 2;
      s.record.corrections = 1;
      s.record.packing.particle_count = 300;
      s.record.packing.porosity_2d = porosity;
      s.record.packing.mean_radius_m = 1e-3;
      s.record.packing.coordination_number = 4.0;
      s.tolerance = 1e-6;
      s.scene_sha256 = "setup-" + job;
      s.build_id = "test";
      s.created_at_ms = created_at_ms;
      s.tags = tags;
      out.push_back(s);
    }
    return out;
  }

  void StoreSweep(const std::string& job, double porosity, double c, std::int64_t created_at_ms,
                  const std::vector<std::string>& tags = {}) {
    const std::int64_t epoch = InsertAndClaim(job);
    ASSERT_TRUE(
        store_->RecordCalibrations(job, epoch, Sweep(job, porosity, c, created_at_ms, tags), tags)
            .ok());
  }

  // (job, target index) of each record, for set comparisons.
  static std::set<std::pair<std::string, std::size_t>> Keys(const CalibrationPage& page) {
    std::set<std::pair<std::string, std::size_t>> keys;
    for (const auto& r : page.records) keys.insert({r.job_id, r.record.target_index});
    return keys;
  }

  std::filesystem::path dir_;
  std::unique_ptr<JobStore> store_;
};

TEST_F(CalibrationStoreTest, ASweepOfFiveTargetsStoresFiveRecords) {
  // A real calibration: a 10 x 6 square lattice of 1 mm disks, a = a0 on every pipe (unloaded,
  // no gaps), where k = a0^3 / (24 R) exactly (docs/physics.md §1.3).
  core::CalibrationSpec spec;
  spec.scene.packing.source = core::LatticePackingSpec{core::LatticeKind::kSquare, 10, 6, 1e-3};
  spec.scene.fluid = {1e-3, 2.2e9};
  spec.scene.aperture = {0.0, 10.0, 0.0, 0.0};
  spec.scene.boundary.axis = core::FlowAxis::kX;
  spec.scene.boundary.inlet_pressure_pa = 1e5;
  spec.target_permeabilities_m2.assign(std::begin(kTargets), std::end(kTargets));
  auto records = core::CalibrateResidualAperture(spec);
  ASSERT_TRUE(records.ok()) << records.status().ToString();

  const std::int64_t epoch = InsertAndClaim("sweep");
  std::vector<StoredCalibration> rows;
  for (const auto& r : *records) {
    rows.push_back({0, "sweep", r, 1e-6, "abc", "build-1", 1700000000000, {"lattice", "v4"}});
  }
  ASSERT_TRUE(store_->RecordCalibrations("sweep", epoch, rows, {"v4", "lattice"}).ok());

  CalibrationFilter filter;
  filter.job_id = "sweep";
  auto page = store_->ListCalibrations(100, std::nullopt, filter);
  ASSERT_TRUE(page.ok()) << page.status().ToString();
  ASSERT_EQ(page->records.size(), 5u);
  for (const StoredCalibration& s : page->records) {
    const core::CalibrationRecord& got = s.record;
    const core::CalibrationRecord& want = (*records)[got.target_index];
    // Every field comes back bit for bit (SQLite REAL is an IEEE double).
    EXPECT_EQ(got.target_permeability_m2, want.target_permeability_m2);
    EXPECT_EQ(got.residual_aperture_m, want.residual_aperture_m);
    EXPECT_EQ(got.permeability_m2, want.permeability_m2);
    EXPECT_EQ(got.relative_error, want.relative_error);
    EXPECT_EQ(got.iterations, want.iterations);
    EXPECT_EQ(got.first_guess_residual_aperture_m, want.first_guess_residual_aperture_m);
    EXPECT_EQ(got.first_guess_relative_error, want.first_guess_relative_error);
    EXPECT_EQ(got.packing.particle_count, 60u);
    EXPECT_EQ(got.packing.porosity_2d, want.packing.porosity_2d);
    EXPECT_EQ(got.packing.coordination_number, want.packing.coordination_number);
    EXPECT_EQ(got.stress.pipes_closed_unloaded, want.stress.pipes_closed_unloaded);
    EXPECT_EQ(got.stress.aperture_proportional_to_a0, want.stress.aperture_proportional_to_a0);
    EXPECT_EQ(got.sample_length_m, want.sample_length_m);
    EXPECT_EQ(got.flow_axis, core::FlowAxis::kX);
    EXPECT_EQ(s.scene_sha256, "abc");
    EXPECT_EQ(s.build_id, "build-1");
    EXPECT_EQ(s.tags, (std::vector<std::string>{"lattice", "v4"}));
    // The answer: on the lattice a0 = (24 R k)^(1/3). k is matched to 1e-6 (the tolerance), so
    // a0 to 1e-6 / 3 plus round-off; 1e-6 leaves room.
    const double exact = std::cbrt(24.0 * 1e-3 * got.target_permeability_m2);
    EXPECT_NEAR(got.residual_aperture_m / exact, 1.0, 1e-6);
    EXPECT_TRUE(got.converged);
    EXPECT_LT(got.relative_error, 1e-6);
  }
  // Newest first: the records were inserted in target order.
  EXPECT_EQ(page->records.front().record.target_index, 4u);
  EXPECT_EQ(page->records.back().record.target_index, 0u);

  // A re-run (after a restart) replaces the records instead of adding to them.
  ASSERT_TRUE(store_->RecordCalibrations("sweep", epoch, rows, {"v4"}).ok());
  page = store_->ListCalibrations(100, std::nullopt, filter);
  ASSERT_TRUE(page.ok());
  EXPECT_EQ(page->records.size(), 5u);
  EXPECT_EQ(page->records.front().tags, (std::vector<std::string>{"v4"}));
}

TEST_F(CalibrationStoreTest, RecordingIsFencedByTheLeaseEpoch) {
  const std::int64_t epoch = InsertAndClaim("a");
  const auto rows = Sweep("a", 0.2, 1.0, 5, {});
  EXPECT_EQ(store_->RecordCalibrations("a", epoch + 1, rows, {}).code(),
            core::StatusCode::kAborted);
  EXPECT_EQ(store_->RecordCalibrations("a", epoch, Sweep("b", 0.2, 1.0, 5, {}), {}).code(),
            core::StatusCode::kInvalidArgument);
  auto page = store_->ListCalibrations(100, std::nullopt);
  ASSERT_TRUE(page.ok());
  EXPECT_TRUE(page->records.empty());
}

TEST_F(CalibrationStoreTest, JobsListByKind) {
  InsertAndClaim("calibration");
  JobRecord simulation;
  simulation.id = "simulation";
  simulation.name = "simulation";
  simulation.scene = "s";
  ASSERT_TRUE(store_->Insert(simulation).ok());
  JobFilter filter;
  filter.kinds = {JobKind::kCalibration};
  auto page = store_->List(10, std::nullopt, filter);
  ASSERT_TRUE(page.ok()) << page.status().ToString();
  ASSERT_EQ(page->jobs.size(), 1u);
  EXPECT_EQ(page->jobs[0].id, "calibration");
  filter.kinds = {JobKind::kSimulation};
  page = store_->List(10, std::nullopt, filter);
  ASSERT_EQ(page->jobs.size(), 1u);
  EXPECT_EQ(page->jobs[0].kind, JobKind::kSimulation);
  filter.kinds = {JobKind::kSimulation, JobKind::kCalibration};
  EXPECT_EQ(store_->List(10, std::nullopt, filter)->jobs.size(), 2u);
}

TEST_F(CalibrationStoreTest, KRangeAndPorosityRangeReturnExactlyTheRecordsInBoth) {
  StoreSweep("low", 0.15, 1.0, 100);
  StoreSweep("mid", 0.20, 1.1, 200);
  StoreSweep("high", 0.25, 1.2, 300);
  CalibrationFilter filter;
  filter.min_permeability_m2 = 2e-14;
  filter.max_permeability_m2 = 2e-13;
  filter.min_porosity = 0.18;
  filter.max_porosity = 0.27;
  auto page = store_->ListCalibrations(100, std::nullopt, filter);
  ASSERT_TRUE(page.ok()) << page.status().ToString();
  // k in [2e-14, 2e-13]: targets 1 (3e-14) and 2 (1e-13); porosity in [0.18, 0.27]: mid, high.
  EXPECT_EQ(Keys(*page), (std::set<std::pair<std::string, std::size_t>>{
                             {"mid", 1}, {"mid", 2}, {"high", 1}, {"high", 2}}));
  // Bounds are inclusive: k exactly 1e-13 alone.
  filter = {};
  filter.min_permeability_m2 = 1e-13;
  filter.max_permeability_m2 = 1e-13;
  filter.max_porosity = 0.15;
  page = store_->ListCalibrations(100, std::nullopt, filter);
  ASSERT_TRUE(page.ok());
  EXPECT_EQ(Keys(*page), (std::set<std::pair<std::string, std::size_t>>{{"low", 2}}));
  // Mean radius and creation time: [200, 300) is "mid" only.
  filter = {};
  filter.min_mean_radius_m = 0.9e-3;
  filter.max_mean_radius_m = 1.1e-3;
  filter.created_after_ms = 200;
  filter.created_before_ms = 300;
  page = store_->ListCalibrations(100, std::nullopt, filter);
  ASSERT_TRUE(page.ok());
  EXPECT_EQ(page->records.size(), 5u);
  for (const auto& r : page->records) EXPECT_EQ(r.job_id, "mid");
  filter.min_mean_radius_m = 1.2e-3;
  page = store_->ListCalibrations(100, std::nullopt, filter);
  ASSERT_TRUE(page.ok());
  EXPECT_TRUE(page->records.empty());
}

TEST_F(CalibrationStoreTest, TagsFilterNeedsEveryTag) {
  StoreSweep("a", 0.2, 1.0, 1, {"shared", "only-a"});
  StoreSweep("b", 0.2, 1.0, 2, {"shared", "only-b"});
  StoreSweep("c", 0.2, 1.0, 3, {});
  auto jobs_with = [&](std::vector<std::string> tags) {
    CalibrationFilter filter;
    filter.tags = std::move(tags);
    auto page = store_->ListCalibrations(100, std::nullopt, filter);
    EXPECT_TRUE(page.ok());
    std::map<std::string, int> count;
    for (const auto& r : page->records) ++count[r.job_id];
    return count;
  };
  EXPECT_EQ(jobs_with({"shared"}), (std::map<std::string, int>{{"a", 5}, {"b", 5}}));
  EXPECT_EQ(jobs_with({"shared", "only-a"}), (std::map<std::string, int>{{"a", 5}}));
  // A repeated tag is one condition, not two.
  EXPECT_EQ(jobs_with({"only-b", "only-b"}), (std::map<std::string, int>{{"b", 5}}));
  EXPECT_TRUE(jobs_with({"only-a", "only-b"}).empty());
  EXPECT_TRUE(jobs_with({"nope"}).empty());
  EXPECT_EQ(jobs_with({}).size(), 3u);
}

TEST_F(CalibrationStoreTest, PagesAreNewestFirstWithoutGapsOrRepeats) {
  StoreSweep("a", 0.2, 1.0, 1);
  StoreSweep("b", 0.2, 1.0, 2);
  StoreSweep("c", 0.2, 1.0, 3);
  std::vector<std::int64_t> ids;
  std::vector<std::size_t> sizes;
  std::optional<std::int64_t> cursor;
  do {
    auto page = store_->ListCalibrations(4, cursor);
    ASSERT_TRUE(page.ok());
    sizes.push_back(page->records.size());
    for (const auto& r : page->records) ids.push_back(r.row_id);
    cursor = page->next_cursor;
  } while (cursor);
  EXPECT_EQ(sizes, (std::vector<std::size_t>{4, 4, 4, 3}));
  ASSERT_EQ(ids.size(), 15u);
  for (std::size_t i = 1; i < ids.size(); ++i) EXPECT_GT(ids[i - 1], ids[i]);
}

TEST_F(CalibrationStoreTest, NearestRanksByNormalizedLogDistanceAndInterpolatesLogLog) {
  StoreSweep("p15", 0.15, 1.0e-1, 1);
  StoreSweep("p20", 0.20, 1.1e-1, 2);
  StoreSweep("p30", 0.30, 1.3e-1, 3);
  CalibrationProbe probe;
  probe.porosity_2d = 0.21;
  probe.mean_radius_m = 1e-3;
  probe.permeability_m2 = 5e-14;
  auto nearest = store_->NearestCalibrations(probe, 3);
  ASSERT_TRUE(nearest.ok()) << nearest.status().ToString();
  ASSERT_EQ(nearest->size(), 3u);
  // Closest: porosity 0.20 and k = 3e-14: d = sqrt(ln(0.20/0.21)^2 + (ln(3e-14/5e-14)/3)^2).
  const auto& best = nearest->front();
  EXPECT_EQ(best.calibration.job_id, "p20");
  EXPECT_EQ(best.calibration.record.target_permeability_m2, 3e-14);
  const double expected = std::hypot(std::log(0.20 / 0.21), std::log(3.0 / 5.0) / 3.0);
  EXPECT_NEAR(best.distance, expected, 1e-15);
  EXPECT_EQ((*nearest)[1].calibration.job_id, "p20");  // k = 1e-13: ln(2)/3 away in k
  EXPECT_EQ((*nearest)[1].calibration.record.target_permeability_m2, 1e-13);
  for (std::size_t i = 1; i < nearest->size(); ++i) {
    EXPECT_LE((*nearest)[i - 1].distance, (*nearest)[i].distance);
  }

  // Interpolation within the nearest record's setup: a0 = c k^(1/3) is a line in log-log, so
  // the interpolated a0 at 5e-14 is c (5e-14)^(1/3) to round-off (1e-14 relative).
  auto same = store_->CalibrationsOfSetup(best.calibration.scene_sha256);
  ASSERT_TRUE(same.ok());
  EXPECT_EQ(same->size(), 5u);
  auto interpolated = InterpolateApertureLogLog(*same, 5e-14);
  ASSERT_TRUE(interpolated.has_value());
  EXPECT_NEAR(interpolated->residual_aperture_m / (1.1e-1 * std::cbrt(5e-14)), 1.0, 1e-14);
  EXPECT_EQ(interpolated->lower.record.target_permeability_m2, 3e-14);
  EXPECT_EQ(interpolated->upper.record.target_permeability_m2, 1e-13);
  // At a stored k, that record's a0; outside the stored range, nothing.
  interpolated = InterpolateApertureLogLog(*same, 1e-13);
  ASSERT_TRUE(interpolated.has_value());
  EXPECT_EQ(interpolated->residual_aperture_m, same->at(2).record.residual_aperture_m);
  EXPECT_EQ(same->at(2).record.target_permeability_m2, 1e-13);
  EXPECT_FALSE(InterpolateApertureLogLog(*same, 2e-12).has_value());
  EXPECT_FALSE(InterpolateApertureLogLog(*same, 5e-15).has_value());

  // The optional particle count joins the distance: 3000 particles is ln(10) away from all.
  probe.particle_count = 3000;
  nearest = store_->NearestCalibrations(probe, 1);
  ASSERT_TRUE(nearest.ok());
  EXPECT_NEAR(nearest->front().distance, std::hypot(expected, std::log(10.0)), 1e-14);
}

}  // namespace
}  // namespace seep::service
