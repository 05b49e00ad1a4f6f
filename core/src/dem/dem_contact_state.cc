// Checkpoint state of DemContactForces (see dem_contact_state.h): validation of a
// DemContactState, and DemContactForces::SaveState / RestoreState. A checkpoint read back from
// disk is untrusted input and the force kernel indexes particles, bonds and walls by the ids it
// holds, so every id and length is checked before anything is adopted.
#include "seep/core/dem/dem_contact_state.h"

#include <cmath>
#include <string>

#include "seep/core/dem/dem_contacts.h"
#include "seep/core/dem/parallel_bond.h"

namespace seep::core {
namespace {

std::string Field(const char* name) { return std::string("dem_state.") + name; }

std::string Element(const char* name, std::size_t k) {
  return Field(name) + "[" + std::to_string(k) + "]";
}

template <typename T>
Status CheckLength(const char* name, const std::vector<T>& v, std::size_t expected,
                   const char* what) {
  if (v.size() == expected) return Status::Ok();
  return DataLoss(Field(name) + ": length " + std::to_string(v.size()) + ", expected " +
                  std::to_string(expected) + " (" + what + ")");
}

Status CheckFinite(const char* name, const std::vector<double>& v) {
  for (std::size_t k = 0; k < v.size(); ++k) {
    if (!std::isfinite(v[k])) return DataLoss(Element(name, k) + ": not finite");
  }
  return Status::Ok();
}

Status CheckFiniteScalar(const char* name, double value) {
  if (std::isfinite(value)) return Status::Ok();
  return DataLoss(Field(name) + ": not finite");
}

// finite and >= 0 (strictly > 0 when `positive`).
Status CheckNonNegative(const char* name, const std::vector<double>& v, bool positive) {
  SEEP_RETURN_IF_ERROR(CheckFinite(name, v));
  for (std::size_t k = 0; k < v.size(); ++k) {
    if (positive ? !(v[k] > 0.0) : !(v[k] >= 0.0)) {
      return DataLoss(Element(name, k) + ": must be " + (positive ? "> 0" : ">= 0") + ", got " +
                      std::to_string(v[k]));
    }
  }
  return Status::Ok();
}

Status CheckIds(const char* name, const std::vector<std::int32_t>& ids, std::size_t limit,
                const char* what) {
  for (std::size_t k = 0; k < ids.size(); ++k) {
    if (ids[k] < 0 || static_cast<std::size_t>(ids[k]) >= limit) {
      return DataLoss(Element(name, k) + ": " + std::to_string(ids[k]) + " out of range [0, " +
                      std::to_string(limit) + ") of " + what);
    }
  }
  return Status::Ok();
}

// Keys (a[k], b[k]) strictly increasing; with `ordered_pair`, also a[k] < b[k].
Status CheckSortedKeys(const char* name_a, const char* name_b, const std::vector<std::int32_t>& a,
                       const std::vector<std::int32_t>& b, bool ordered_pair) {
  for (std::size_t k = 0; k < a.size(); ++k) {
    if (ordered_pair && !(a[k] < b[k])) {
      return DataLoss(Element(name_a, k) + ": " + std::to_string(a[k]) + " must be < " + name_b +
                      " " + std::to_string(b[k]));
    }
    if (k > 0 && !(a[k - 1] < a[k] || (a[k - 1] == a[k] && b[k - 1] < b[k]))) {
      return DataLoss(Element(name_a, k) + ": keys not sorted strictly by (" + name_a + ", " +
                      name_b + ")");
    }
  }
  return Status::Ok();
}

Status ValidateBonds(const DemContactState& s, std::size_t particle_count) {
  const std::size_t nb = s.bond_i.size();
  SEEP_RETURN_IF_ERROR(CheckLength("bond_j", s.bond_j, nb, "as bond_i"));
  SEEP_RETURN_IF_ERROR(CheckLength("bond_half_width", s.bond_half_width, nb, "as bond_i"));
  SEEP_RETURN_IF_ERROR(CheckLength("bond_fn", s.bond_fn, nb, "as bond_i"));
  SEEP_RETURN_IF_ERROR(CheckLength("bond_fs", s.bond_fs, nb, "as bond_i"));
  SEEP_RETURN_IF_ERROR(CheckLength("bond_moment", s.bond_moment, nb, "as bond_i"));
  SEEP_RETURN_IF_ERROR(CheckLength("bond_failure", s.bond_failure, nb, "as bond_i"));
  SEEP_RETURN_IF_ERROR(CheckLength("bond_reported", s.bond_reported, nb, "as bond_i"));
  SEEP_RETURN_IF_ERROR(CheckIds("bond_i", s.bond_i, particle_count, "the particles"));
  SEEP_RETURN_IF_ERROR(CheckIds("bond_j", s.bond_j, particle_count, "the particles"));
  SEEP_RETURN_IF_ERROR(CheckSortedKeys("bond_i", "bond_j", s.bond_i, s.bond_j, true));
  SEEP_RETURN_IF_ERROR(CheckNonNegative("bond_half_width", s.bond_half_width, true));
  SEEP_RETURN_IF_ERROR(CheckFinite("bond_fn", s.bond_fn));
  SEEP_RETURN_IF_ERROR(CheckFinite("bond_fs", s.bond_fs));
  SEEP_RETURN_IF_ERROR(CheckFinite("bond_moment", s.bond_moment));
  for (std::size_t b = 0; b < nb; ++b) {
    if (s.bond_failure[b] > static_cast<std::uint8_t>(BondFailure::kShear)) {
      return DataLoss(Element("bond_failure", b) + ": unknown failure " +
                      std::to_string(s.bond_failure[b]));
    }
    if (s.bond_reported[b] > 1 || (s.bond_reported[b] == 1 && s.bond_failure[b] == 0)) {
      return DataLoss(Element("bond_reported", b) + ": must be 0, or 1 for a broken bond");
    }
  }
  SEEP_RETURN_IF_ERROR(CheckFiniteScalar("bond_normal_stiffness", s.bond_normal_stiffness));
  SEEP_RETURN_IF_ERROR(CheckFiniteScalar("bond_shear_stiffness", s.bond_shear_stiffness));
  SEEP_RETURN_IF_ERROR(CheckFiniteScalar("bond_radius_multiplier", s.bond_radius_multiplier));
  SEEP_RETURN_IF_ERROR(CheckFiniteScalar("bond_tensile_strength", s.bond_tensile_strength));
  SEEP_RETURN_IF_ERROR(CheckFiniteScalar("bond_shear_strength", s.bond_shear_strength));
  if (nb > 0) {
    // The parameters were validated when the bonds were made; bad ones mean a corrupt state.
    const BondParams params{s.bond_normal_stiffness, s.bond_shear_stiffness,
                            s.bond_radius_multiplier, s.bond_tensile_strength,
                            s.bond_shear_strength};
    const Status st = ValidateBondParams(params);
    if (!st.ok()) return DataLoss(Field("bond_params") + ": " + st.message());
  }
  return Status::Ok();
}

Status ValidatePairs(const DemContactState& s, std::size_t particle_count) {
  const std::size_t np = s.pair_i.size();
  SEEP_RETURN_IF_ERROR(CheckLength("pair_j", s.pair_j, np, "as pair_i"));
  SEEP_RETURN_IF_ERROR(CheckLength("pair_bond", s.pair_bond, np, "as pair_i"));
  SEEP_RETURN_IF_ERROR(CheckLength("pair_damping", s.pair_damping, np, "as pair_i"));
  SEEP_RETURN_IF_ERROR(CheckLength("pair_shear", s.pair_shear, np, "as pair_i"));
  SEEP_RETURN_IF_ERROR(CheckLength("pair_fn", s.pair_fn, np, "as pair_i"));
  SEEP_RETURN_IF_ERROR(CheckLength("pair_gap", s.pair_gap, np, "as pair_i"));
  SEEP_RETURN_IF_ERROR(CheckIds("pair_i", s.pair_i, particle_count, "the particles"));
  SEEP_RETURN_IF_ERROR(CheckIds("pair_j", s.pair_j, particle_count, "the particles"));
  SEEP_RETURN_IF_ERROR(CheckSortedKeys("pair_i", "pair_j", s.pair_i, s.pair_j, true));
  SEEP_RETURN_IF_ERROR(CheckNonNegative("pair_damping", s.pair_damping, false));
  SEEP_RETURN_IF_ERROR(CheckFinite("pair_shear", s.pair_shear));
  SEEP_RETURN_IF_ERROR(CheckFinite("pair_fn", s.pair_fn));
  SEEP_RETURN_IF_ERROR(CheckFinite("pair_gap", s.pair_gap));
  // A pair's bond joins the same two disks; with both tables sorted strictly this also means no
  // two pairs share a bond (the parallel kernel writes a bond from its one pair only).
  const std::size_t nb = s.bond_i.size();
  for (std::size_t k = 0; k < np; ++k) {
    const std::int32_t b = s.pair_bond[k];
    if (b == -1) continue;
    if (b < 0 || static_cast<std::size_t>(b) >= nb) {
      return DataLoss(Element("pair_bond", k) + ": " + std::to_string(b) +
                      " is neither -1 nor a bond index in [0, " + std::to_string(nb) + ")");
    }
    if (s.bond_i[b] != s.pair_i[k] || s.bond_j[b] != s.pair_j[k]) {
      return DataLoss(Element("pair_bond", k) + ": bond " + std::to_string(b) +
                      " joins other particles than the pair");
    }
  }
  return Status::Ok();
}

Status ValidateWallContacts(const DemContactState& s, std::size_t particle_count,
                            std::size_t wall_count) {
  const std::size_t nc = s.wall_contact_particle.size();
  SEEP_RETURN_IF_ERROR(
      CheckLength("wall_contact_wall", s.wall_contact_wall, nc, "as wall_contact_particle"));
  SEEP_RETURN_IF_ERROR(
      CheckLength("wall_contact_shear", s.wall_contact_shear, nc, "as wall_contact_particle"));
  SEEP_RETURN_IF_ERROR(
      CheckLength("wall_contact_fn", s.wall_contact_fn, nc, "as wall_contact_particle"));
  SEEP_RETURN_IF_ERROR(
      CheckLength("wall_contact_gap", s.wall_contact_gap, nc, "as wall_contact_particle"));
  SEEP_RETURN_IF_ERROR(
      CheckIds("wall_contact_particle", s.wall_contact_particle, particle_count, "the particles"));
  SEEP_RETURN_IF_ERROR(CheckIds("wall_contact_wall", s.wall_contact_wall, wall_count, "the walls"));
  SEEP_RETURN_IF_ERROR(CheckSortedKeys("wall_contact_particle", "wall_contact_wall",
                                       s.wall_contact_particle, s.wall_contact_wall, false));
  SEEP_RETURN_IF_ERROR(CheckFinite("wall_contact_shear", s.wall_contact_shear));
  SEEP_RETURN_IF_ERROR(CheckFinite("wall_contact_fn", s.wall_contact_fn));
  SEEP_RETURN_IF_ERROR(CheckFinite("wall_contact_gap", s.wall_contact_gap));

  // The loads are read by index = wall index (servos) before the next pass, so they cover every
  // wall, or none before the first pass.
  const std::size_t nl = s.wall_load_normal_force.size();
  if (nl != wall_count && !(nl == 0 && s.needs_rebuild)) {
    return DataLoss(Field("wall_load_normal_force") + ": length " + std::to_string(nl) +
                    ", expected " + std::to_string(wall_count) + " (one per wall)");
  }
  SEEP_RETURN_IF_ERROR(CheckLength("wall_load_stiffness_sum", s.wall_load_stiffness_sum, nl,
                                   "as wall_load_normal_force"));
  SEEP_RETURN_IF_ERROR(CheckLength("wall_load_damping_sum", s.wall_load_damping_sum, nl,
                                   "as wall_load_normal_force"));
  SEEP_RETURN_IF_ERROR(CheckLength("wall_load_contact_count", s.wall_load_contact_count, nl,
                                   "as wall_load_normal_force"));
  SEEP_RETURN_IF_ERROR(CheckFinite("wall_load_normal_force", s.wall_load_normal_force));
  SEEP_RETURN_IF_ERROR(
      CheckNonNegative("wall_load_stiffness_sum", s.wall_load_stiffness_sum, false));
  SEEP_RETURN_IF_ERROR(CheckNonNegative("wall_load_damping_sum", s.wall_load_damping_sum, false));
  for (std::size_t w = 0; w < nl; ++w) {
    if (s.wall_load_contact_count[w] < 0) {
      return DataLoss(Element("wall_load_contact_count", w) + ": must be >= 0, got " +
                      std::to_string(s.wall_load_contact_count[w]));
    }
  }
  return Status::Ok();
}

// Reference positions: one per body, or none while a rebuild is pending (never rebuilt yet).
Status ValidateReferences(const DemContactState& s, std::size_t particle_count,
                          std::size_t wall_count) {
  const std::size_t n = s.ref_x.size();
  if (n != particle_count && !(n == 0 && s.needs_rebuild)) {
    return DataLoss(Field("ref_x") + ": length " + std::to_string(n) + ", expected " +
                    std::to_string(particle_count) + " (one per particle)");
  }
  SEEP_RETURN_IF_ERROR(CheckLength("ref_y", s.ref_y, n, "as ref_x"));
  const std::size_t nw = s.ref_wall_x.size();
  if (nw != wall_count && !(nw == 0 && s.needs_rebuild)) {
    return DataLoss(Field("ref_wall_x") + ": length " + std::to_string(nw) + ", expected " +
                    std::to_string(wall_count) + " (one per wall)");
  }
  SEEP_RETURN_IF_ERROR(CheckLength("ref_wall_y", s.ref_wall_y, nw, "as ref_wall_x"));
  SEEP_RETURN_IF_ERROR(CheckFinite("ref_x", s.ref_x));
  SEEP_RETURN_IF_ERROR(CheckFinite("ref_y", s.ref_y));
  SEEP_RETURN_IF_ERROR(CheckFinite("ref_wall_x", s.ref_wall_x));
  SEEP_RETURN_IF_ERROR(CheckFinite("ref_wall_y", s.ref_wall_y));
  return Status::Ok();
}

}  // namespace

Status ValidateDemContactState(const DemContactState& state, std::size_t particle_count,
                               std::size_t wall_count) {
  SEEP_RETURN_IF_ERROR(ValidateReferences(state, particle_count, wall_count));
  SEEP_RETURN_IF_ERROR(ValidateBonds(state, particle_count));
  SEEP_RETURN_IF_ERROR(ValidatePairs(state, particle_count));
  SEEP_RETURN_IF_ERROR(ValidateWallContacts(state, particle_count, wall_count));
  return Status::Ok();
}

DemContactState DemContactForces::SaveState() const {
  DemContactState s;
  s.needs_rebuild = needs_rebuild_;
  s.bond_normal_stiffness = bond_params_.normal_stiffness;
  s.bond_shear_stiffness = bond_params_.shear_stiffness;
  s.bond_radius_multiplier = bond_params_.radius_multiplier;
  s.bond_tensile_strength = bond_params_.tensile_strength;
  s.bond_shear_strength = bond_params_.shear_strength;

  const std::size_t np = pairs_.size();
  s.pair_i.resize(np);
  s.pair_j.resize(np);
  s.pair_bond.resize(np);
  s.pair_damping.resize(np);
  s.pair_shear.resize(np);
  s.pair_fn.resize(np);
  s.pair_gap.resize(np);
  for (std::size_t k = 0; k < np; ++k) {
    const PairEntry& e = pairs_[k];
    s.pair_i[k] = e.i;
    s.pair_j[k] = e.j;
    s.pair_bond[k] = e.bond;
    s.pair_damping[k] = e.damping;
    s.pair_shear[k] = e.shear;
    s.pair_fn[k] = e.fn;
    s.pair_gap[k] = e.gap;
  }

  const std::size_t nb = bond_i_.size();
  s.bond_i = bond_i_;
  s.bond_j = bond_j_;
  s.bond_half_width = bond_half_width_;
  s.bond_fn.resize(nb);
  s.bond_fs.resize(nb);
  s.bond_moment.resize(nb);
  s.bond_failure.resize(nb);
  for (std::size_t b = 0; b < nb; ++b) {
    s.bond_fn[b] = bond_state_[b].fn;
    s.bond_fs[b] = bond_state_[b].fs;
    s.bond_moment[b] = bond_state_[b].moment;
    s.bond_failure[b] = static_cast<std::uint8_t>(bond_failure_[b]);
  }
  s.bond_reported = bond_reported_;

  s.wall_contact_particle = wall_p_;
  s.wall_contact_wall = wall_w_;
  s.wall_contact_shear = wall_shear_;
  s.wall_contact_fn = wall_fn_;
  s.wall_contact_gap = wall_gap_;

  const std::size_t nl = wall_loads_.size();
  s.wall_load_normal_force.resize(nl);
  s.wall_load_stiffness_sum.resize(nl);
  s.wall_load_damping_sum.resize(nl);
  s.wall_load_contact_count.resize(nl);
  for (std::size_t w = 0; w < nl; ++w) {
    s.wall_load_normal_force[w] = wall_loads_[w].normal_force;
    s.wall_load_stiffness_sum[w] = wall_loads_[w].stiffness_sum;
    s.wall_load_damping_sum[w] = wall_loads_[w].damping_sum;
    s.wall_load_contact_count[w] = wall_loads_[w].contact_count;
  }

  s.ref_x = ref_x_;
  s.ref_y = ref_y_;
  s.ref_wall_x = ref_wall_x_;
  s.ref_wall_y = ref_wall_y_;
  return s;
}

Status DemContactForces::RestoreState(const DemContactState& s, std::size_t particle_count,
                                      std::size_t wall_count) {
  // Everything is checked before the first member changes: on error the object is untouched.
  SEEP_RETURN_IF_ERROR(ValidateDemContactState(s, particle_count, wall_count));

  needs_rebuild_ = s.needs_rebuild;
  ++pair_table_version_;
  bond_params_ =
      BondParams{s.bond_normal_stiffness, s.bond_shear_stiffness, s.bond_radius_multiplier,
                 s.bond_tensile_strength, s.bond_shear_strength};

  const std::size_t np = s.pair_i.size();
  pairs_.resize(np);
  for (std::size_t k = 0; k < np; ++k) {
    pairs_[k] = PairEntry{s.pair_i[k],       s.pair_j[k],     s.pair_bond[k], 0,
                          s.pair_damping[k], s.pair_shear[k], s.pair_fn[k],   s.pair_gap[k]};
  }

  const std::size_t nb = s.bond_i.size();
  bond_i_ = s.bond_i;
  bond_j_ = s.bond_j;
  bond_half_width_ = s.bond_half_width;
  bond_state_.resize(nb);
  bond_failure_.resize(nb);
  for (std::size_t b = 0; b < nb; ++b) {
    bond_state_[b] = BondState{s.bond_fn[b], s.bond_fs[b], s.bond_moment[b]};
    bond_failure_[b] = static_cast<BondFailure>(s.bond_failure[b]);
  }
  bond_reported_ = s.bond_reported;
  unreported_breaks_ = true;
  broken_.clear();

  wall_p_ = s.wall_contact_particle;
  wall_w_ = s.wall_contact_wall;
  wall_shear_ = s.wall_contact_shear;
  wall_fn_ = s.wall_contact_fn;
  wall_gap_ = s.wall_contact_gap;

  const std::size_t nl = s.wall_load_normal_force.size();
  wall_loads_.resize(nl);
  for (std::size_t w = 0; w < nl; ++w) {
    wall_loads_[w] = DemWallLoad{s.wall_load_normal_force[w], s.wall_load_stiffness_sum[w],
                                 s.wall_load_damping_sum[w], s.wall_load_contact_count[w]};
  }

  ref_x_ = s.ref_x;
  ref_y_ = s.ref_y;
  ref_wall_x_ = s.ref_wall_x;
  ref_wall_y_ = s.ref_wall_y;

  // Derived and scratch, sized as the last rebuild of the saved object left them: packed_ must
  // have one entry per particle or the next pass would rebuild early (NeedsRebuild), which would
  // change the results; the threaded pass makes its gather lists from the pair table.
  packed_.assign(particle_count, PackedDisk{});
  gather_ready_ = false;
  return Status::Ok();
}

}  // namespace seep::core
