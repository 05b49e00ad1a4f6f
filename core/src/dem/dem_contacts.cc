// Neighbour list, contact and bond forces of the DEM (see dem_contacts.h for the design).
#include "seep/core/dem/dem_contacts.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "../sizes.h"
#include "dem_parallel.h"

namespace seep::core {
namespace {

// Nearest periodic image of a pair vector component (valid while |dx| < 1.5 lx).
inline double NearestImage(double dx, bool periodic, double lx) {
  if (!periodic) return dx;
  const double half = 0.5 * lx;
  if (dx > half) return dx - lx;
  if (dx < -half) return dx + lx;
  return dx;
}

inline bool KeyLess(std::int32_t ai, std::int32_t aj, std::int32_t bi, std::int32_t bj) {
  return ai < bi || (ai == bi && aj < bj);
}

}  // namespace

Status ValidateDemContactSettings(const DemContactSettings& s) {
  SEEP_RETURN_IF_ERROR(ValidateContactLawParams(s.law));
  if (!std::isfinite(s.skin) || s.skin < 0.0) {
    return InvalidArgument("dem.contact.skin: must be finite and >= 0 (got " +
                           std::to_string(s.skin) + ")");
  }
  if (!std::isfinite(s.flow_gap) || s.flow_gap < 0.0) {
    return InvalidArgument("dem.contact.flow_gap: must be finite and >= 0 (got " +
                           std::to_string(s.flow_gap) + ")");
  }
  if (s.periodic_x) {
    if (!std::isfinite(s.x0)) return InvalidArgument("dem.contact.x0: must be finite");
    if (!std::isfinite(s.lx) || s.lx <= 0.0) {
      return InvalidArgument("dem.contact.lx: must be finite and > 0 when periodic_x (got " +
                             std::to_string(s.lx) + ")");
    }
  }
  return Status::Ok();
}

Result<DemContactForces> DemContactForces::Create(const DemContactSettings& settings) {
  SEEP_RETURN_IF_ERROR(ValidateDemContactSettings(settings));
  return DemContactForces(settings);
}

std::size_t DemContactForces::intact_bond_count() const {
  return static_cast<std::size_t>(
      std::count(bond_failure_.begin(), bond_failure_.end(), BondFailure::kNone));
}

bool DemContactForces::NeedsRebuild(const DemParticles& p,
                                    const std::vector<DemWall>& walls) const {
  if (needs_rebuild_ || ref_x_.size() != p.size() || ref_wall_x_.size() != walls.size() ||
      packed_.size() != p.size()) {
    return true;
  }
  const double half_skin = 0.5 * settings_.skin;
  for (std::size_t w = 0; w < walls.size(); ++w) {
    const double dx = walls[w].px - ref_wall_x_[w], dy = walls[w].py - ref_wall_y_[w];
    // A line moving along itself does not move; a segment does, so its whole displacement counts.
    const double d = IsSegment(w) ? std::hypot(dx, dy) : dx * walls[w].nx + dy * walls[w].ny;
    if (std::abs(d) > half_skin) return true;
  }
  return false;
}

namespace {

// Packs [begin, end) of the disks and returns the largest squared drift from the reference
// positions there (Disk: DemContactForces' packed disk).
template <class Disk>
double PackRange(std::ptrdiff_t begin, std::ptrdiff_t end, const double* __restrict x,
                 const double* __restrict y, const double* __restrict vx,
                 const double* __restrict vy, const double* __restrict w,
                 const double* __restrict rad, const double* __restrict rx,
                 const double* __restrict ry, Disk* __restrict packed) {
  double max_d2 = 0.0;
  for (std::ptrdiff_t i = begin; i < end; ++i) {
    packed[i] = Disk{x[i], y[i], vx[i], vy[i], w[i], rad[i]};
    const double dx = x[i] - rx[i];
    const double dy = y[i] - ry[i];
    max_d2 = std::max(max_d2, dx * dx + dy * dy);
  }
  return max_d2;
}

}  // namespace

double DemContactForces::PackDisks(const DemParticles& p) {
  const std::ptrdiff_t n = static_cast<std::ptrdiff_t>(p.size());
  // max is exact, so the result is thread-count independent.
  return dem_internal::MaxOverShares(n, [&](std::ptrdiff_t begin, std::ptrdiff_t end) {
    return PackRange(begin, end, p.x.data(), p.y.data(), p.vx.data(), p.vy.data(), p.omega.data(),
                     p.radius.data(), ref_x_.data(), ref_y_.data(), packed_.data());
  });
}

Status DemContactForces::FindCandidatePairs(const DemParticles& p, double cutoff,
                                            std::vector<std::int32_t>* cand_i,
                                            std::vector<std::int32_t>* cand_j) {
  cand_i->clear();
  cand_j->clear();
  const std::size_t n = p.size();
  if (n == 0) return Status::Ok();
  double rmax = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(p.x[i]) || !std::isfinite(p.y[i])) {
      return FailedPrecondition("dem.contact: particle " + std::to_string(i) +
                                " has a non-finite position (the run has diverged)");
    }
    rmax = std::max(rmax, p.radius[i]);
  }
  // Any pair closer than `cutoff` has centre distance < 2 rmax + cutoff.
  CellGridOptions grid_options;
  grid_options.reach = 2.0 * rmax + cutoff;
  grid_options.x = {settings_.periodic_x, settings_.x0, settings_.lx};
  if (Status s = grid_.Build(p.x, p.y, grid_options); !s.ok()) {
    return InvalidArgument("dem.contact.lx: " + s.message());
  }
  for (std::size_t i = 0; i < n; ++i) {
    row_candidates_.clear();
    const double ri = p.radius[i];
    grid_.ForEachNeighbour(static_cast<std::int32_t>(i), [&](std::int32_t j, double dx, double dy) {
      const double gap = std::sqrt(dx * dx + dy * dy) - ri - p.radius[static_cast<std::size_t>(j)];
      if (gap < cutoff) row_candidates_.push_back(j);
    });
    std::sort(row_candidates_.begin(), row_candidates_.end());
    for (std::int32_t j : row_candidates_) {
      cand_i->push_back(static_cast<std::int32_t>(i));
      cand_j->push_back(j);
    }
  }
  return Status::Ok();
}

Status DemContactForces::Rebuild(DemParticles* p, const std::vector<DemWall>& walls, double cutoff,
                                 DemCounters* counters) {
  const std::size_t n = p->size();
  if (settings_.periodic_x) {
    const double x0 = settings_.x0, lx = settings_.lx;
    for (std::size_t i = 0; i < n; ++i) {
      double xi = p->x[i] - lx * std::floor((p->x[i] - x0) / lx);
      if (xi >= x0 + lx) xi = x0;  // rounding of the line above
      p->x[i] = xi;
    }
  }
  // Pairs up to flow_gap farther than the skin, so that CollectFlowContacts stays complete up to
  // flow_gap until the next rebuild (walls need no such margin).
  // The candidates live only as long as the rebuild: between rebuilds the table is all there is.
  std::vector<std::int32_t> cand_i, cand_j;
  SEEP_RETURN_IF_ERROR(FindCandidatePairs(*p, cutoff + settings_.flow_gap, &cand_i, &cand_j));

  // Drop the bonds that broke (already reported) so that bond indices stay dense.
  {
    std::size_t out = 0;
    for (std::size_t b = 0; b < bond_i_.size(); ++b) {
      if (bond_failure_[b] != BondFailure::kNone) continue;
      bond_i_[out] = bond_i_[b];
      bond_j_[out] = bond_j_[b];
      bond_half_width_[out] = bond_half_width_[b];
      bond_state_[out] = bond_state_[b];
      ++out;
    }
    bond_i_.resize(out);
    bond_j_.resize(out);
    bond_half_width_.resize(out);
    bond_state_.resize(out);
    bond_failure_.assign(out, BondFailure::kNone);
    bond_reported_.assign(out, 0);
  }

  // New pair table = candidates merged with the bonds (a bonded pair stays listed however far it
  // moves), carrying the shear history of pairs that were already listed.
  const std::size_t nc = cand_i.size(), nb = bond_i_.size(), no = pairs_.size();
  // Most bonded pairs are candidates too: the table holds their union, counted first so that it
  // is allocated at its size (nc + nb would double a bonded packing's table).
  std::size_t union_size = 0;
  for (std::size_t c = 0, b = 0; c < nc || b < nb; ++union_size) {
    if (b >= nb || (c < nc && KeyLess(cand_i[c], cand_j[c], bond_i_[b], bond_j_[b]))) {
      ++c;
    } else {
      if (c < nc && cand_i[c] == bond_i_[b] && cand_j[c] == bond_j_[b]) ++c;
      ++b;
    }
  }
  std::vector<PairEntry> fresh;
  fresh.reserve(union_size);
  std::size_t c = 0, b = 0, o = 0;
  while (c < nc || b < nb) {
    PairEntry e{};
    e.bond = -1;
    if (b >= nb || (c < nc && KeyLess(cand_i[c], cand_j[c], bond_i_[b], bond_j_[b]))) {
      e.i = cand_i[c];
      e.j = cand_j[c];
      ++c;
    } else {
      e.i = bond_i_[b];
      e.j = bond_j_[b];
      e.bond = static_cast<std::int32_t>(b);
      if (c < nc && cand_i[c] == e.i && cand_j[c] == e.j) ++c;
      ++b;
    }
    while (o < no && KeyLess(pairs_[o].i, pairs_[o].j, e.i, e.j)) ++o;
    if (o < no && pairs_[o].i == e.i && pairs_[o].j == e.j) {
      e.shear = pairs_[o].shear;
      e.fn = pairs_[o].fn;
      e.gap = pairs_[o].gap;
    }
    const double m_eff = 1.0 / (p->inv_mass[e.i] + p->inv_mass[e.j]);
    e.damping = NormalDampingCoefficient(settings_.law, m_eff);
    fresh.push_back(e);
  }
  pairs_.swap(fresh);
  packed_.resize(n);
  gather_ready_ = false;  // the threaded pass makes its lists for this table

  // Wall candidates, keyed (particle, wall), with their history carried over.
  {
    std::vector<std::int32_t> wp, ww;
    std::vector<double> wshear, wfn, wgap;
    std::size_t old = 0;
    const std::size_t nold = wall_p_.size();
    for (std::size_t i = 0; i < n; ++i) {
      for (std::size_t w = 0; w < walls.size(); ++w) {
        const double gap = WallGapOf(*p, i, w, walls).gap;
        if (!(gap < cutoff)) continue;
        const auto ii = static_cast<std::int32_t>(i), wi = static_cast<std::int32_t>(w);
        while (old < nold && KeyLess(wall_p_[old], wall_w_[old], ii, wi)) ++old;
        const bool had = old < nold && wall_p_[old] == ii && wall_w_[old] == wi;
        wp.push_back(ii);
        ww.push_back(wi);
        wshear.push_back(had ? wall_shear_[old] : 0.0);
        wfn.push_back(had ? wall_fn_[old] : 0.0);
        wgap.push_back(gap);
      }
    }
    wall_p_.swap(wp);
    wall_w_.swap(ww);
    wall_shear_.swap(wshear);
    wall_fn_.swap(wfn);
    wall_gap_.swap(wgap);
  }

  ref_x_ = p->x;
  ref_y_ = p->y;
  ref_wall_x_.resize(walls.size());
  ref_wall_y_.resize(walls.size());
  for (std::size_t w = 0; w < walls.size(); ++w) {
    ref_wall_x_[w] = walls[w].px;
    ref_wall_y_[w] = walls[w].py;
  }
  needs_rebuild_ = false;
  ++pair_table_version_;
  if (counters != nullptr) ++counters->neighbour_rebuilds;
  return Status::Ok();
}

void DemContactForces::BuildGatherLists(std::size_t n) {
  const std::size_t np = pairs_.size();
  gather_start_.assign(n + 1, 0);
  for (const PairEntry& e : pairs_) {
    ++gather_start_[e.i + 1];
    ++gather_start_[e.j + 1];
  }
  for (std::size_t i = 0; i < n; ++i) gather_start_[i + 1] += gather_start_[i];
  gather_items_.resize(2 * np);
  std::vector<std::int32_t>& fill = row_candidates_;  // scratch reused as the fill cursor
  fill.assign(gather_start_.begin(), gather_start_.end() - 1);
  for (std::size_t k = 0; k < np; ++k) {
    const auto kk = static_cast<std::int32_t>(k);
    gather_items_[fill[pairs_[k].i]++] = kk;
    gather_items_[fill[pairs_[k].j]++] = ~kk;
  }
}

template <bool kBonds>
void DemContactForces::PairForcesKernel(DemParticles* particles, double dt, bool overwrite,
                                        DemCounters* counters) {
  const DemParticles& p = *particles;
  const std::ptrdiff_t n = static_cast<std::ptrdiff_t>(p.size());
  const std::ptrdiff_t np = static_cast<std::ptrdiff_t>(pairs_.size());
  const bool periodic = settings_.periodic_x;
  const double lx = settings_.lx;
  const double kn = settings_.law.kn, kt = settings_.law.kt, mu = settings_.law.friction;
  PairEntry* __restrict pairs = pairs_.data();
  PackedDisk* __restrict packed = packed_.data();
  double* __restrict fx = particles->fx.data();
  double* __restrict fy = particles->fy.data();
  double* __restrict tq = particles->torque.data();
  BondState* bstate = bond_state_.data();
  BondFailure* bfail = bond_failure_.data();
  const double* bwidth = bond_half_width_.data();
  const BondParams bp = bond_params_;
  std::uint64_t touching = 0, bond_evals = 0, bond_fails = 0;
  // Pair k's contact law (and bond): updates its entry, returns its force on i. The counters are
  // the caller's (a thread's own copies on a team).
  const auto evaluate = [&](std::ptrdiff_t k, std::uint64_t& touched,
                            std::uint64_t& bonds_evaluated,
                            std::uint64_t& bonds_failed) -> PairSlot {
    PairEntry& e = pairs[k];
    const PackedDisk a = packed[e.i];
    const PackedDisk b = packed[e.j];
    const double dx = NearestImage(b.x - a.x, periodic, lx);
    const double dy = b.y - a.y;
    const double rs = a.r + b.r;
    // Coincident centres have no normal; the floor keeps the arithmetic finite.
    const double r2 = std::max(dx * dx + dy * dy, 1e-300);
    const double r = std::sqrt(r2);
    const double inv_r = 1.0 / r;
    const double nx = dx * inv_r, ny = dy * inv_r;
    const double gap = r - rs;
    const double dvx = b.vx - a.vx, dvy = b.vy - a.vy;
    const double vn = dvx * nx + dvy * ny;
    const double vt = dvy * nx - dvx * ny - (a.omega * a.r + b.omega * b.r);
    // Branch-free: every listed pair runs the law, open ones are multiplied by 0 (their history
    // is thereby reset). About a third of the pairs are open, at random: a branch mispredicts.
    const bool touch = gap < 0.0;
    touched += touch ? 1u : 0u;
    const double on = touch ? 1.0 : 0.0;
    const ContactForce f = EvaluateLinearContact(-gap, vn, vt, e.damping, kn, kt, mu, e.shear, dt);
    double fnc = on * f.fn, ftc = on * f.ft, moment = 0.0;
    e.shear = ftc;
    if constexpr (kBonds) {
      const std::int32_t bi = e.bond;
      if (bi >= 0 && bfail[bi] == BondFailure::kNone) {
        ++bonds_evaluated;
        BondState& st = bstate[bi];
        const BondFailure failure = UpdateBond(bp, bwidth[bi], vn, vt, a.omega, b.omega, dt, &st);
        if (failure != BondFailure::kNone) {
          bfail[bi] = failure;  // one bond per pair entry: no other thread writes it
          ++bonds_failed;
        } else {
          fnc += st.fn;
          ftc += st.fs;
          moment = st.moment;
        }
      }
    }
    e.fn = fnc;
    e.gap = gap;
    return PairSlot{-fnc * nx - ftc * ny, -fnc * ny + ftc * nx, ftc, moment};
  };
  // What particle i gets from its sums over its pairs: the same expressions on both paths.
  const auto write = [&](std::ptrdiff_t i, double ax, double ay, double ft, double m) {
    const double torque = packed[i].r * ft + m;
    if (overwrite) {  // loop-invariant: the compiler unswitches it
      fx[i] = ax;
      fy[i] = ay;
      tq[i] = torque;
    } else {
      fx[i] += ax;
      fy[i] += ay;
      tq[i] += torque;
    }
  };
  if (!(np >= dem_internal::MinParallelItems() && dem_internal::CoreThreads() > 1)) {
    // One thread: each pair adds to the sums of its two particles straight away, in ascending
    // pair order, which is the order of the gather below: the same additions, the same bits,
    // without a slot per pair (32 bytes) or the gather lists (8 bytes a pair).
    if (sums_.size() != static_cast<std::size_t>(n)) sums_.assign(static_cast<std::size_t>(n), {});
    PairSums* __restrict sums = sums_.data();
    for (std::ptrdiff_t k = 0; k < np; ++k) {
      const PairSlot sl = evaluate(k, touching, bond_evals, bond_fails);
      PairSums& si = sums[pairs[k].i];
      si.fx += sl.fx;
      si.fy += sl.fy;
      si.ft += sl.ft;
      if constexpr (kBonds) si.m += sl.m;
      PairSums& sj = sums[pairs[k].j];
      sj.fx += -1.0 * sl.fx;  // the gather's sign x slot: exact
      sj.fy += -1.0 * sl.fy;
      sj.ft += sl.ft;
      if constexpr (kBonds) sj.m += -1.0 * sl.m;
    }
    for (std::ptrdiff_t i = 0; i < n; ++i) {
      write(i, sums[i].fx, sums[i].fy, sums[i].ft, sums[i].m);
      sums[i] = PairSums{};  // zero for the next pass
    }
  } else {
    if (!gather_ready_) {
      slots_.resize(pairs_.size());
      BuildGatherLists(p.size());
      gather_ready_ = true;
    }
    PairSlot* __restrict slots = slots_.data();
    const std::int32_t* __restrict start = gather_start_.data();
    const std::int32_t* __restrict items = gather_items_.data();
    // One team run, two loops (pairs, then, after a barrier, the gather that needs all of them).
    std::atomic<std::uint64_t> team_touching{0}, team_bond_evals{0}, team_bond_fails{0};
    dem_internal::RunOnTeam(
        dem_internal::CoreThreads(), [&](const dem_internal::TeamMember& member) {
          std::uint64_t my_touching = 0, my_bond_evals = 0, my_bond_fails = 0;
          const auto [first_pair, last_pair] = member.Share(np);
          for (std::ptrdiff_t k = first_pair; k < last_pair; ++k) {
            slots[k] = evaluate(k, my_touching, my_bond_evals, my_bond_fails);
          }
          team_touching.fetch_add(my_touching, std::memory_order_relaxed);
          team_bond_evals.fetch_add(my_bond_evals, std::memory_order_relaxed);
          team_bond_fails.fetch_add(my_bond_fails, std::memory_order_relaxed);
          member.Barrier();
          const auto [first, last] = member.Share(n);
          for (std::ptrdiff_t i = first; i < last; ++i) {
            double ax = 0.0, ay = 0.0, ft = 0.0, m = 0.0;
            for (std::int32_t g = start[i]; g < start[i + 1]; ++g) {
              const std::int32_t it = items[g];
              const bool side_i = it >= 0;
              const PairSlot& sl = slots[side_i ? it : ~it];
              const double sign = side_i ? 1.0 : -1.0;  // exact: x (+-1) only flips the sign
              ax += sign * sl.fx;
              ay += sign * sl.fy;
              ft += sl.ft;
              if constexpr (kBonds) m += sign * sl.m;
            }
            write(i, ax, ay, ft, m);
          }
        });
    touching += team_touching.load(std::memory_order_relaxed);
    bond_evals += team_bond_evals.load(std::memory_order_relaxed);
    bond_fails += team_bond_fails.load(std::memory_order_relaxed);
  }
  if (bond_fails != 0) unreported_breaks_ = true;
  if (counters != nullptr) {
    counters->pair_checks += static_cast<std::uint64_t>(np);
    counters->pair_evaluations += touching;
    counters->bond_evaluations += bond_evals;
  }
}

void DemContactForces::ComputePairForces(DemParticles* p, double dt, bool overwrite,
                                         DemCounters* counters) {
  if (bond_i_.empty()) {
    PairForcesKernel<false>(p, dt, overwrite, counters);
  } else {
    PairForcesKernel<true>(p, dt, overwrite, counters);
  }
}

void DemContactForces::ComputeWallForces(DemParticles* p, const std::vector<DemWall>& walls,
                                         double dt, DemCounters* counters) {
  wall_loads_.assign(walls.size(), DemWallLoad{});
  const ContactLawParams& law = settings_.law;
  std::uint64_t touching = 0;
  for (std::size_t c = 0; c < wall_p_.size(); ++c) {
    const std::int32_t i = wall_p_[c];
    const DemWall& wall = walls[wall_w_[c]];
    const double ri = p->radius[i];
    const WallGap where = WallGapOf(*p, static_cast<std::size_t>(i), wall_w_[c], walls);
    const double gap = where.gap;
    wall_gap_[c] = gap;
    if (!(gap < 0.0)) {
      wall_shear_[c] = 0.0;
      wall_fn_[c] = 0.0;
      // A disk about to touch counts for the servo's gain in part (dem_wall.h's DemWallLoad):
      // in full at contact, nothing from kServoApproachGap x its radius away.
      const double weight = 1.0 - gap / (kServoApproachGap * ri);
      if (weight > 0.0) {
        DemWallLoad& load = wall_loads_[wall_w_[c]];
        load.stiffness_sum += weight * law.kn;
        load.damping_sum += weight * NormalDampingCoefficient(law, p->mass[i]);
      }
      continue;
    }
    ++touching;
    // Normal from the disk to the wall, tangent t = z x n.
    const double nx = -where.ux, ny = -where.uy;
    const double dvx = wall.vx - p->vx[i], dvy = wall.vy - p->vy[i];
    const double vn = dvx * nx + dvy * ny;
    const double vt = dvy * nx - dvx * ny - p->omega[i] * ri;
    const double damping = NormalDampingCoefficient(law, p->mass[i]);
    const ContactForce f = EvaluateLinearContact(-gap, vn, vt, damping, law.kn, law.kt,
                                                 law.friction, wall_shear_[c], dt);
    wall_shear_[c] = f.ft;
    wall_fn_[c] = f.fn;
    p->fx[i] += -f.fn * nx - f.ft * ny;
    p->fy[i] += -f.fn * ny + f.ft * nx;
    p->torque[i] += ri * f.ft;
    DemWallLoad& load = wall_loads_[wall_w_[c]];
    // The load along the wall's normal: the whole force for a line (u = n), its normal part at a
    // segment's end or on its back face.
    load.normal_force += IsSegment(static_cast<std::size_t>(wall_w_[c]))
                             ? f.fn * (where.ux * wall.nx + where.uy * wall.ny)
                             : f.fn;
    load.stiffness_sum += law.kn;
    load.damping_sum += damping;
    ++load.contact_count;
  }
  if (counters != nullptr) {
    counters->wall_checks += wall_p_.size();
    counters->wall_evaluations += touching;
  }
}

WallGap DemContactForces::WallGapOf(const DemParticles& p, std::size_t i, std::size_t w,
                                    const std::vector<DemWall>& walls) const {
  if (IsSegment(w)) {
    return SegmentWallGap(walls[w], wall_extents_[w], p.x[i], p.y[i], p.radius[i]);
  }
  return LineWallGap(walls[w], p.x[i], p.y[i], p.radius[i]);
}

Status DemContactForces::SetWallExtents(std::vector<DemWallExtent> extents) {
  SEEP_RETURN_IF_ERROR(ValidateWallExtents(extents));
  wall_extents_ = std::move(extents);
  needs_rebuild_ = true;
  return Status::Ok();
}

void DemContactForces::CollectBondBreaks(DemCounters* counters) {
  // A scan of every bond only after a pass that broke one (it was 1.6 % of a coupled step on the
  // 43k-disk fracturing bed, and serial).
  if (!unreported_breaks_) return;
  unreported_breaks_ = false;
  for (std::size_t b = 0; b < bond_i_.size(); ++b) {
    if (bond_failure_[b] == BondFailure::kNone || bond_reported_[b]) continue;
    bond_reported_[b] = 1;
    broken_.push_back(BondBreak{bond_i_[b], bond_j_[b], bond_failure_[b]});
    if (counters != nullptr) ++counters->bonds_broken;
  }
}

Status DemContactForces::AddForces(DemParticles* particles, const std::vector<DemWall>& walls,
                                   double dt, DemCounters* counters) {
  return Evaluate(particles, walls, dt, /*overwrite=*/false, counters);
}

Status DemContactForces::SetForces(DemParticles* particles, const std::vector<DemWall>& walls,
                                   double dt, DemCounters* counters) {
  return Evaluate(particles, walls, dt, /*overwrite=*/true, counters);
}

Status DemContactForces::Evaluate(DemParticles* particles, const std::vector<DemWall>& walls,
                                  double dt, bool overwrite, DemCounters* counters) {
  if (!(dt > 0.0) || !std::isfinite(dt)) {
    return InvalidArgument("dem.contact.dt: must be finite and > 0 (got " + std::to_string(dt) +
                           ")");
  }
  broken_.clear();
  // The displacement check rides on the packing pass (one team run instead of two).
  bool rebuild = NeedsRebuild(*particles, walls);
  if (!rebuild) {
    const double half_skin = 0.5 * settings_.skin;
    rebuild = PackDisks(*particles) > half_skin * half_skin;
  }
  if (rebuild) {
    SEEP_RETURN_IF_ERROR(Rebuild(particles, walls, settings_.skin, counters));
    PackDisks(*particles);  // positions may have been wrapped
  }
  ComputePairForces(particles, dt, overwrite, counters);
  ComputeWallForces(particles, walls, dt, counters);
  if (!bond_i_.empty()) CollectBondBreaks(counters);
  return Status::Ok();
}

Result<std::size_t> DemContactForces::BondTouchingPairs(DemParticles* particles,
                                                        const BondParams& params, double tolerance,
                                                        DemCounters* counters) {
  SEEP_RETURN_IF_ERROR(ValidateBondParams(params));
  if (!std::isfinite(tolerance) || tolerance < 0.0) {
    return InvalidArgument("dem.bond.tolerance: must be finite and >= 0 (got " +
                           std::to_string(tolerance) + ")");
  }
  // gap < nextafter(tol) is gap <= tol.
  std::vector<std::int32_t> cand_i, cand_j;
  SEEP_RETURN_IF_ERROR(FindCandidatePairs(
      *particles, std::nextafter(tolerance, std::numeric_limits<double>::infinity()), &cand_i,
      &cand_j));
  bond_params_ = params;
  bond_i_ = std::move(cand_i);
  bond_j_ = std::move(cand_j);
  const std::size_t nb = bond_i_.size();
  bond_half_width_.resize(nb);
  for (std::size_t b = 0; b < nb; ++b) {
    bond_half_width_[b] =
        BondHalfWidth(params, particles->radius[bond_i_[b]], particles->radius[bond_j_[b]]);
  }
  bond_state_.assign(nb, BondState{});
  bond_failure_.assign(nb, BondFailure::kNone);
  bond_reported_.assign(nb, 0);
  needs_rebuild_ = true;
  (void)counters;
  return nb;
}

void DemContactForces::CollectContacts(std::vector<DemContactRecord>* out) const {
  out->clear();
  for (const PairEntry& e : pairs_) {
    const bool bonded = e.bond >= 0 && bond_failure_[e.bond] == BondFailure::kNone;
    if (!(e.gap < 0.0) && !bonded) continue;
    out->push_back(DemContactRecord{e.i, e.j, e.fn, e.gap, e.shear, bonded});
  }
}

void DemContactForces::CollectFlowContacts(double max_gap, ContactList* out) const {
  out->Clear();
  for (const PairEntry& e : pairs_) {
    if (!IsFlowContact(e, max_gap)) continue;
    out->i.push_back(e.i);
    out->j.push_back(e.j);
    out->gap.push_back(e.gap);
  }
}

namespace {

// The first entry m of the list (i, j) with (i[m], j[m]) not before (ki, kj); a bisection, so it
// ends on any list (on an unsorted one the entries found there simply will not match).
std::size_t FirstNotBefore(std::span<const std::int32_t> i, std::span<const std::int32_t> j,
                           std::int32_t ki, std::int32_t kj) {
  std::size_t lo = 0, hi = i.size();
  while (lo < hi) {
    const std::size_t mid = lo + (hi - lo) / 2;
    if (KeyLess(i[mid], j[mid], ki, kj)) {
      lo = mid + 1;
    } else {
      hi = mid;
    }
  }
  return lo;
}

// Thread shares FlowContactsAre compares on (a team this large or larger checks on one thread).
constexpr int kMaxFlowCheckShares = 64;

}  // namespace

DemContactForces::FlowRun DemContactForces::MatchFlowRun(double max_gap, std::size_t begin,
                                                         std::size_t end,
                                                         std::span<const std::int32_t> i,
                                                         std::span<const std::int32_t> j) const {
  FlowRun run;
  std::size_t m = 0;
  for (std::size_t k = begin; k < end; ++k) {
    const PairEntry& e = pairs_[k];
    if (!IsFlowContact(e, max_gap)) continue;
    if (run.count == 0) run.start = m = FirstNotBefore(i, j, e.i, e.j);
    if (m == i.size() || e.i != i[m] || e.j != j[m]) {
      run.ok = false;
      return run;
    }
    ++m;
    ++run.count;
  }
  return run;
}

bool DemContactForces::FlowContactsAre(double max_gap, std::span<const std::int32_t> i,
                                       std::span<const std::int32_t> j) const {
  if (i.size() != j.size()) return false;
  // Each share (one without a team) finds its flow contacts where its first one sits in the list
  // (a pass over the pairs checked every flow update, 2-3 % of a coupled step on one thread). The
  // lists are equal exactly when every share matched a run and the runs, in share order, tile the
  // list.
  const auto n = static_cast<std::ptrdiff_t>(pairs_.size());
  FlowRun runs[kMaxFlowCheckShares];
  int shares = 1;
  if (!dem_internal::OnTeam(n) || dem_internal::CoreThreads() > kMaxFlowCheckShares) {
    runs[0] = MatchFlowRun(max_gap, 0, pairs_.size(), i, j);
  } else {
    dem_internal::RunOnTeam(
        dem_internal::CoreThreads(), [&](const dem_internal::TeamMember& member) {
          const auto [begin, end] = member.Share(n);
          runs[member.index()] = MatchFlowRun(max_gap, static_cast<std::size_t>(begin),
                                              static_cast<std::size_t>(end), i, j);
          if (member.index() == 0) shares = member.size();
        });
  }
  std::size_t tiled = 0;
  for (int t = 0; t < shares; ++t) {
    if (!runs[t].ok) return false;
    if (runs[t].count == 0) continue;
    if (runs[t].start != tiled) return false;
    tiled += runs[t].count;
  }
  return tiled == i.size();
}

Status DemContactForces::FindPairs(std::span<const std::int32_t> i, std::span<const std::int32_t> j,
                                   std::vector<std::int32_t>* index) const {
  if (i.size() != j.size()) {
    return InvalidArgument("dem.contact.find_pairs: " + std::to_string(i.size()) + " i and " +
                           std::to_string(j.size()) + " j");
  }
  for (std::size_t m = 0; m < i.size(); ++m) {
    if (i[m] >= j[m] || (m > 0 && !KeyLess(i[m - 1], j[m - 1], i[m], j[m]))) {
      return InvalidArgument("dem.contact.find_pairs: pair " + std::to_string(m) + " (" +
                             std::to_string(i[m]) + ", " + std::to_string(j[m]) +
                             ") is not sorted with i < j");
    }
  }
  index->assign(i.size(), -1);
  std::size_t k = 0;
  for (std::size_t m = 0; m < i.size(); ++m) {
    while (k < pairs_.size() && KeyLess(pairs_[k].i, pairs_[k].j, i[m], j[m])) ++k;
    if (k < pairs_.size() && pairs_[k].i == i[m] && pairs_[k].j == j[m]) {
      (*index)[m] = static_cast<std::int32_t>(k);
    }
  }
  return Status::Ok();
}

void DemContactForces::CollectFlowWallContacts(double max_gap, const DemParticles& particles,
                                               WallContactList* out,
                                               std::vector<double>* normal_force) const {
  out->Clear();
  if (normal_force != nullptr) normal_force->clear();
  for (std::size_t c = 0; c < wall_p_.size(); ++c) {
    const double gap = wall_gap_[c];
    if (!(gap <= max_gap) || !(gap > -particles.radius[static_cast<std::size_t>(wall_p_[c])])) {
      continue;
    }
    out->particle.push_back(wall_p_[c]);
    out->wall.push_back(wall_w_[c]);
    out->gap.push_back(gap);
    if (normal_force != nullptr) normal_force->push_back(wall_fn_[c]);
  }
}

void DemContactForces::CollectWallContacts(std::vector<DemWallContactRecord>* out) const {
  out->clear();
  for (std::size_t c = 0; c < wall_p_.size(); ++c) {
    if (!(wall_gap_[c] < 0.0)) continue;
    out->push_back(
        DemWallContactRecord{wall_p_[c], wall_w_[c], wall_fn_[c], wall_gap_[c], wall_shear_[c]});
  }
}

std::size_t DemContactForces::MemoryBytes() const {
  return internal::VectorBytes(pairs_, slots_, sums_, packed_, gather_start_, gather_items_,
                               bond_i_, bond_j_, bond_half_width_, bond_state_, bond_failure_,
                               bond_reported_, broken_, wall_p_, wall_w_, wall_shear_, wall_fn_,
                               wall_gap_, wall_loads_, wall_extents_, ref_x_, ref_y_, ref_wall_x_,
                               ref_wall_y_, row_candidates_) +
         grid_.MemoryBytes();
}

}  // namespace seep::core
