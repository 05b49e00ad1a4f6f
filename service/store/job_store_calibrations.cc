// JobStore: calibration records and their tags (schema v4). One row per calibrated target; the
// job's tags live in calibration_tags so that "has every one of these tags" is a COUNT.
#include <fmt/format.h>

#include <algorithm>

#include "calibration_lookup.h"
#include "job_store.h"
#include "job_store_internal.h"
#include "sqlite_handle.h"

namespace seep::service {
namespace {

// Every column of a record after id, in the order Bind and Read use.
constexpr const char* kCalibrationColumns =
    "job_id, target_index, target_permeability_m2, residual_aperture_m, permeability_m2, "
    "relative_error, converged, tolerance, iterations, corrections, "
    "first_guess_residual_aperture_m, first_guess_permeability_m2, first_guess_relative_error, "
    "particle_count, contact_count, domain_count, pipe_count, porosity_2d, mean_radius_m, "
    "radius_std_dev_m, min_radius_m, max_radius_m, coordination_number, viscosity_pa_s, "
    "bulk_modulus_pa, reference_force_n, gap_multiplier, max_aperture_m, uniform_normal_force_n, "
    "listed_contact_forces, pipes_in_compression, pipes_closed_unloaded, pipes_open, pipes_capped, "
    "min_normal_force_n, mean_normal_force_n, max_normal_force_n, aperture_proportional_to_a0, "
    "flow_axis, pressure_drop_pa, sample_length_m, sample_width_m, scene_sha256, build_id, "
    "created_at_ms";
constexpr int kCalibrationColumnCount = 45;

std::int64_t Count(std::size_t n) { return static_cast<std::int64_t>(n); }

// One statement per column: chained Bind(i++, ...) calls would leave the order of the
// increments to the compiler.
void BindCalibration(Stmt& s, const StoredCalibration& c) {
  const core::CalibrationRecord& r = c.record;
  int i = 1;
  s.Bind(i++, std::string_view(c.job_id));
  s.Bind(i++, Count(r.target_index));
  s.Bind(i++, r.target_permeability_m2);
  s.Bind(i++, r.residual_aperture_m);
  s.Bind(i++, r.permeability_m2);
  s.Bind(i++, r.relative_error);
  s.Bind(i++, std::int64_t{r.converged ? 1 : 0});
  s.Bind(i++, c.tolerance);
  s.Bind(i++, std::int64_t{r.iterations});
  s.Bind(i++, std::int64_t{r.corrections});
  s.Bind(i++, r.first_guess_residual_aperture_m);
  s.Bind(i++, r.first_guess_permeability_m2);
  s.Bind(i++, r.first_guess_relative_error);
  s.Bind(i++, Count(r.packing.particle_count));
  s.Bind(i++, Count(r.packing.contact_count));
  s.Bind(i++, Count(r.packing.domain_count));
  s.Bind(i++, Count(r.packing.pipe_count));
  s.Bind(i++, r.packing.porosity_2d);
  s.Bind(i++, r.packing.mean_radius_m);
  s.Bind(i++, r.packing.radius_std_dev_m);
  s.Bind(i++, r.packing.min_radius_m);
  s.Bind(i++, r.packing.max_radius_m);
  s.Bind(i++, r.packing.coordination_number);
  s.Bind(i++, r.fluid.viscosity_pa_s);
  s.Bind(i++, r.fluid.bulk_modulus_pa);
  s.Bind(i++, r.aperture.reference_force_n);
  s.Bind(i++, r.aperture.gap_multiplier);
  s.Bind(i++, r.aperture.max_aperture_m);
  s.Bind(i++, r.stress.uniform_normal_force_n);
  s.Bind(i++, Count(r.stress.listed_contact_forces));
  s.Bind(i++, Count(r.stress.pipes_in_compression));
  s.Bind(i++, Count(r.stress.pipes_closed_unloaded));
  s.Bind(i++, Count(r.stress.pipes_open));
  s.Bind(i++, Count(r.stress.pipes_capped));
  s.Bind(i++, r.stress.min_normal_force_n);
  s.Bind(i++, r.stress.mean_normal_force_n);
  s.Bind(i++, r.stress.max_normal_force_n);
  s.Bind(i++, std::int64_t{r.stress.aperture_proportional_to_a0 ? 1 : 0});
  s.Bind(i++, std::string_view(r.flow_axis == core::FlowAxis::kX ? "X" : "Y"));
  s.Bind(i++, r.pressure_drop_pa);
  s.Bind(i++, r.sample_length_m);
  s.Bind(i++, r.sample_width_m);
  s.Bind(i++, std::string_view(c.scene_sha256));
  s.Bind(i++, std::string_view(c.build_id));
  s.Bind(i++, c.created_at_ms);
}

// Reads a row of "SELECT id, <kCalibrationColumns>".
StoredCalibration ReadCalibration(const Stmt& s) {
  auto size = [&s](int col) { return static_cast<std::size_t>(s.ColumnInt(col)); };
  StoredCalibration c;
  core::CalibrationRecord& r = c.record;
  int i = 0;
  c.row_id = s.ColumnInt(i++);
  c.job_id = s.ColumnText(i++);
  r.target_index = size(i++);
  r.target_permeability_m2 = s.ColumnDouble(i++);
  r.residual_aperture_m = s.ColumnDouble(i++);
  r.permeability_m2 = s.ColumnDouble(i++);
  r.relative_error = s.ColumnDouble(i++);
  r.converged = s.ColumnInt(i++) != 0;
  c.tolerance = s.ColumnDouble(i++);
  r.iterations = static_cast<int>(s.ColumnInt(i++));
  r.corrections = static_cast<int>(s.ColumnInt(i++));
  r.first_guess_residual_aperture_m = s.ColumnDouble(i++);
  r.first_guess_permeability_m2 = s.ColumnDouble(i++);
  r.first_guess_relative_error = s.ColumnDouble(i++);
  r.packing.particle_count = size(i++);
  r.packing.contact_count = size(i++);
  r.packing.domain_count = size(i++);
  r.packing.pipe_count = size(i++);
  r.packing.porosity_2d = s.ColumnDouble(i++);
  r.packing.mean_radius_m = s.ColumnDouble(i++);
  r.packing.radius_std_dev_m = s.ColumnDouble(i++);
  r.packing.min_radius_m = s.ColumnDouble(i++);
  r.packing.max_radius_m = s.ColumnDouble(i++);
  r.packing.coordination_number = s.ColumnDouble(i++);
  r.fluid.viscosity_pa_s = s.ColumnDouble(i++);
  r.fluid.bulk_modulus_pa = s.ColumnDouble(i++);
  r.aperture.reference_force_n = s.ColumnDouble(i++);
  r.aperture.gap_multiplier = s.ColumnDouble(i++);
  r.aperture.max_aperture_m = s.ColumnDouble(i++);
  r.aperture.residual_aperture_m = r.residual_aperture_m;
  r.stress.uniform_normal_force_n = s.ColumnDouble(i++);
  r.stress.listed_contact_forces = size(i++);
  r.stress.pipes_in_compression = size(i++);
  r.stress.pipes_closed_unloaded = size(i++);
  r.stress.pipes_open = size(i++);
  r.stress.pipes_capped = size(i++);
  r.stress.min_normal_force_n = s.ColumnDouble(i++);
  r.stress.mean_normal_force_n = s.ColumnDouble(i++);
  r.stress.max_normal_force_n = s.ColumnDouble(i++);
  r.stress.aperture_proportional_to_a0 = s.ColumnInt(i++) != 0;
  r.flow_axis = s.ColumnText(i++) == "Y" ? core::FlowAxis::kY : core::FlowAxis::kX;
  r.pressure_drop_pa = s.ColumnDouble(i++);
  r.sample_length_m = s.ColumnDouble(i++);
  r.sample_width_m = s.ColumnDouble(i++);
  c.scene_sha256 = s.ColumnText(i++);
  c.build_id = s.ColumnText(i++);
  c.created_at_ms = s.ColumnInt(i++);
  return c;
}

}  // namespace

Status JobStore::RecordCalibrations(const std::string& id, std::int64_t epoch,
                                    const std::vector<StoredCalibration>& records,
                                    const std::vector<std::string>& tags) {
  for (const StoredCalibration& c : records) {
    if (c.job_id != id) {
      return core::InvalidArgument(fmt::format(
          "store: a calibration record of job {} names job '{}'; they must match", id, c.job_id));
    }
  }
  const StoreOperation operation("record calibrations");
  std::lock_guard lock(mutex_);
  SEEP_ASSIGN_OR_RETURN(WriteTx tx, WriteTx::Begin(*db_));
  {
    SEEP_ASSIGN_OR_RETURN(
        Stmt lease, db_->Prepare("SELECT 1 FROM jobs WHERE id = ? AND lease_epoch = ? AND state = "
                                 "'RUNNING'"));
    lease.Bind(1, std::string_view(id)).Bind(2, epoch);
    SEEP_ASSIGN_OR_RETURN(const bool row, lease.Step());
    if (!row) return LeaseLost(id, epoch);
  }
  for (const char* table : {"calibrations", "calibration_tags"}) {
    SEEP_ASSIGN_OR_RETURN(Stmt clear,
                          db_->Prepare(fmt::format("DELETE FROM {} WHERE job_id = ?", table)));
    clear.Bind(1, std::string_view(id));
    SEEP_RETURN_IF_ERROR(clear.Run());
  }
  std::string placeholders = "?";
  for (int i = 1; i < kCalibrationColumnCount; ++i) placeholders += ", ?";
  SEEP_ASSIGN_OR_RETURN(Stmt insert,
                        db_->Prepare(fmt::format("INSERT INTO calibrations ({}) VALUES ({})",
                                                 kCalibrationColumns, placeholders)));
  for (const StoredCalibration& c : records) {
    insert.Reset();
    BindCalibration(insert, c);
    SEEP_RETURN_IF_ERROR(insert.Run());
  }
  SEEP_ASSIGN_OR_RETURN(
      Stmt tag, db_->Prepare("INSERT OR IGNORE INTO calibration_tags (job_id, tag) VALUES (?, ?)"));
  for (const std::string& t : tags) {
    tag.Reset();
    tag.Bind(1, std::string_view(id)).Bind(2, std::string_view(t));
    SEEP_RETURN_IF_ERROR(tag.Run());
  }
  return tx.Commit();
}

Status JobStore::ReadCalibrationTagsLocked(std::vector<StoredCalibration>& records) {
  SEEP_ASSIGN_OR_RETURN(
      Stmt s, db_->Prepare("SELECT tag FROM calibration_tags WHERE job_id = ? ORDER BY tag"));
  std::string last_job;
  std::vector<std::string> last_tags;
  for (StoredCalibration& c : records) {
    if (c.job_id != last_job) {
      last_job = c.job_id;
      last_tags.clear();
      s.Reset();
      s.Bind(1, std::string_view(c.job_id));
      for (;;) {
        SEEP_ASSIGN_OR_RETURN(const bool row, s.Step());
        if (!row) break;
        last_tags.push_back(s.ColumnText(0));
      }
    }
    c.tags = last_tags;
  }
  return Status::Ok();
}

Result<CalibrationPage> JobStore::ListCalibrations(std::uint32_t limit,
                                                   std::optional<std::int64_t> cursor,
                                                   const CalibrationFilter& filter) {
  // Tags to match, once each (a repeated tag must not be counted twice).
  std::vector<std::string> tags = filter.tags;
  std::sort(tags.begin(), tags.end());
  tags.erase(std::unique(tags.begin(), tags.end()), tags.end());

  std::string where = "c.id < ?";
  auto range = [&where](const std::optional<double>& bound, const char* clause) {
    if (bound) where += clause;
  };
  range(filter.min_permeability_m2, " AND c.target_permeability_m2 >= ?");
  range(filter.max_permeability_m2, " AND c.target_permeability_m2 <= ?");
  range(filter.min_porosity, " AND c.porosity_2d >= ?");
  range(filter.max_porosity, " AND c.porosity_2d <= ?");
  range(filter.min_mean_radius_m, " AND c.mean_radius_m >= ?");
  range(filter.max_mean_radius_m, " AND c.mean_radius_m <= ?");
  if (filter.created_after_ms) where += " AND c.created_at_ms >= ?";
  if (filter.created_before_ms) where += " AND c.created_at_ms < ?";
  if (!filter.job_id.empty()) where += " AND c.job_id = ?";
  if (!tags.empty()) {
    where +=
        " AND (SELECT COUNT(*) FROM calibration_tags t WHERE t.job_id = c.job_id AND t.tag IN (";
    for (std::size_t i = 0; i < tags.size(); ++i) where += i == 0 ? "?" : ", ?";
    where += ")) = ?";
  }

  const StoreOperation operation("list calibrations");
  std::lock_guard lock(mutex_);
  SEEP_ASSIGN_OR_RETURN(Stmt s, db_->Prepare(fmt::format("SELECT c.id, {} FROM calibrations c "
                                                         "WHERE {} ORDER BY c.id DESC LIMIT ?",
                                                         kCalibrationColumns, where)));
  int index = 1;
  s.Bind(index++, cursor.value_or(INT64_MAX));
  for (const auto* bound :
       {&filter.min_permeability_m2, &filter.max_permeability_m2, &filter.min_porosity,
        &filter.max_porosity, &filter.min_mean_radius_m, &filter.max_mean_radius_m}) {
    if (*bound) s.Bind(index++, **bound);
  }
  if (filter.created_after_ms) s.Bind(index++, *filter.created_after_ms);
  if (filter.created_before_ms) s.Bind(index++, *filter.created_before_ms);
  if (!filter.job_id.empty()) s.Bind(index++, std::string_view(filter.job_id));
  if (!tags.empty()) {
    for (const std::string& t : tags) s.Bind(index++, std::string_view(t));
    s.Bind(index++, Count(tags.size()));
  }
  s.Bind(index, static_cast<std::int64_t>(limit) + 1);
  CalibrationPage page;
  for (;;) {
    SEEP_ASSIGN_OR_RETURN(const bool row, s.Step());
    if (!row) break;
    if (page.records.size() == limit) {
      page.next_cursor = page.records.back().row_id;
      break;
    }
    page.records.push_back(ReadCalibration(s));
  }
  SEEP_RETURN_IF_ERROR(ReadCalibrationTagsLocked(page.records));
  return page;
}

Result<std::vector<CalibrationNeighbour>> JobStore::NearestCalibrations(
    const CalibrationProbe& probe, std::uint32_t limit) {
  std::vector<CalibrationNeighbour> all;
  {
    const StoreOperation operation("look up calibrations");
    std::lock_guard lock(mutex_);
    SEEP_ASSIGN_OR_RETURN(
        Stmt s, db_->Prepare(fmt::format(
                    "SELECT id, {} FROM calibrations WHERE converged = 1 ORDER BY id DESC",
                    kCalibrationColumns)));
    for (;;) {
      SEEP_ASSIGN_OR_RETURN(const bool row, s.Step());
      if (!row) break;
      StoredCalibration c = ReadCalibration(s);
      const double d = CalibrationDistance(probe, c);
      all.push_back({std::move(c), d});
    }
  }
  // Stable: among equal distances the newer record (read first) stays first.
  std::stable_sort(all.begin(), all.end(),
                   [](const CalibrationNeighbour& a, const CalibrationNeighbour& b) {
                     return a.distance < b.distance;
                   });
  if (all.size() > limit) all.resize(limit);
  std::vector<StoredCalibration> kept;
  kept.reserve(all.size());
  for (auto& n : all) kept.push_back(std::move(n.calibration));
  {
    const StoreOperation operation("look up calibrations");
    std::lock_guard lock(mutex_);
    SEEP_RETURN_IF_ERROR(ReadCalibrationTagsLocked(kept));
  }
  for (std::size_t i = 0; i < all.size(); ++i) all[i].calibration = std::move(kept[i]);
  return all;
}

Result<std::vector<StoredCalibration>> JobStore::CalibrationsOfSetup(
    const std::string& scene_sha256) {
  const StoreOperation operation("read calibrations of a setup");
  std::lock_guard lock(mutex_);
  SEEP_ASSIGN_OR_RETURN(
      Stmt s, db_->Prepare(fmt::format("SELECT id, {} FROM calibrations WHERE scene_sha256 = ? "
                                       "AND converged = 1 ORDER BY target_permeability_m2, id",
                                       kCalibrationColumns)));
  s.Bind(1, std::string_view(scene_sha256));
  std::vector<StoredCalibration> out;
  for (;;) {
    SEEP_ASSIGN_OR_RETURN(const bool row, s.Step());
    if (!row) break;
    out.push_back(ReadCalibration(s));
  }
  SEEP_RETURN_IF_ERROR(ReadCalibrationTagsLocked(out));
  return out;
}

}  // namespace seep::service
