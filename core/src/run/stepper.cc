#include "seep/core/run/stepper.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <string_view>

#include "../branch_free.h"
#include "../parallel_threshold.h"
#include "seep/core/dem/dem_integrator.h"
#include "seep/core/effects/flow_effect.h"
#include "seep/core/effects/fluid_stable_step.h"
#include "seep/core/effects/volume_change_effect.h"
#include "seep/core/log.h"
#include "seep/core/run/coupling_numbers.h"

namespace seep::core {
namespace {

using Clock = std::chrono::steady_clock;

// Progress reports (and time-series samples) per run when the scene does not choose an interval.
constexpr std::uint64_t kDefaultProgressReports = 200;

// Runs one hook of one effect and adds its wall time to *seconds.
template <typename Call>
Status Timed(double* seconds, Call call) {
  const Clock::time_point start = Clock::now();
  const Status status = call();
  *seconds += std::chrono::duration<double>(Clock::now() - start).count();
  return status;
}

// The pore fluid is a spring between the particles, which the step must resolve as well.
// Contacts and fluid act on the same particles in parallel: their stiffnesses add, so
// 1/dt^2 = 1/dt_contacts^2 + 1/dt_fluid^2 (taking the smaller alone let an undamped column
// diverge at dt_safety 0.5).
double CombinedStep(double contact_dt, double fluid_dt) {
  return 1.0 / std::sqrt(1.0 / (contact_dt * contact_dt) + 1.0 / (fluid_dt * fluid_dt));
}

// The most steps a run may take: past 2^53 steps a double time can no longer tell one step
// from the next (t + dt == t), and past 2^64 the count itself would overflow.
constexpr double kMaxSteps = 9007199254740992.0;  // 2^53

// Saturates at kMaxSteps (SetClock refuses a scene that needs more; a later, shorter step only
// gets this far).
std::uint64_t StepsToEnd(double end, double dt) {
  const double steps = std::ceil(end / dt * (1.0 - 1e-12));
  return std::max<std::uint64_t>(1,
                                 static_cast<std::uint64_t>(steps < kMaxSteps ? steps : kMaxSteps));
}

// The scene's end over its step, refused when it is no number of steps a run can count.
Status CheckStepCount(double end, double dt, std::string_view step_setting) {
  const double steps = end / dt;
  if (steps <= kMaxSteps) return Status::Ok();
  return InvalidArgument(fmt::format(
      "solver.end_time_s: {} s over a step of {} s is {:.3g} steps, more than a run can count "
      "(2^53); shorten solver.end_time_s or lengthen the step ({})",
      end, dt, steps, step_setting));
}

}  // namespace

Stepper::Stepper(const SceneSpec& scene) : scene_(scene) { state_.scene = &scene_; }

Result<std::unique_ptr<Stepper>> Stepper::Create(const SceneSpec& scene, SceneNetwork net,
                                                 bool has_network) {
  std::unique_ptr<Stepper> stepper(new Stepper(scene));
  LiveState& s = stepper->state_;
  s.net = std::move(net);
  s.has_network = has_network;
  s.detection_x = s.net.packing.x;
  s.detection_y = s.net.packing.y;
  s.storage = has_network ? RunStorage(scene, s.net.flow) : SceneStorage(scene);
  // An empty list is what every scene meant before effects existed: flow on a frozen packing.
  stepper->effects_ =
      MakeEffects(stepper->scene_.effects.empty() ? std::vector<EffectSpec>{FlowEffectSpec{}}
                                                  : stepper->scene_.effects);
  stepper->program_ = StageProgram(scene);
  const std::vector<std::unique_ptr<Effect>>& all = stepper->effects_.all;
  stepper->effect_seconds_.assign(all.size(), 0.0);
  for (std::size_t k = 0; k < all.size(); ++k) {
    Effect& effect = *all[k];
    SEEP_RETURN_IF_ERROR(effect.Bind(s, stepper->effects_));
    const std::uint32_t hooks = effect.Hooks();
    if (hooks & kFlowUpdateHook) stepper->flow_update_.push_back(k);
    if (hooks & kForceHook) stepper->force_.push_back(k);
    if (hooks & kPostForceHook) stepper->post_force_.push_back(k);
    if (hooks & kEndOfStepHook) stepper->end_of_step_.push_back(k);
  }
  if (s.moves() && all[stepper->force_.front()].get() != stepper->effects_.contacts) {
    return Internal("step loop: the contacts effect must lead the force list");
  }
  // The first stage's settings hold from the start (the servo's first targets included).
  if (stepper->program_.active()) SEEP_RETURN_IF_ERROR(stepper->ApplyStageControls(0.0, true));
  SEEP_RETURN_IF_ERROR(stepper->SetClock());
  // The network's columns lead, as they did before effects existed (a frozen packing has only
  // them); the others follow in canonical order.
  if (stepper->effects_.flow != nullptr) stepper->sample_order_.push_back(stepper->effects_.flow);
  for (const auto& effect : all) {
    if (effect.get() != stepper->effects_.flow) stepper->sample_order_.push_back(effect.get());
  }
  stepper->series_.columns = {"time_s"};
  for (const Effect* effect : stepper->sample_order_) {
    effect->AddSeriesColumns(s, &stepper->series_.columns);
  }
  // Which stage each row belongs to (from 1): where it changes, a stage ended.
  if (stepper->program_.active()) stepper->series_.columns.push_back("stage");
  if (s.moves()) {
    SEEP_RETURN_IF_ERROR(stepper->InitialForces());
    stepper->guard_.Start(s);
    stepper->reversals_.Start(s);
  }
  stepper->Sample();  // the initial state is the first row
  return stepper;
}

Status Stepper::SetClock() {
  const SolverSpec& solver = scene_.solver;
  FlowEffect* flow = effects_.flow;
  fluid_limited_dt_ = std::numeric_limits<double>::infinity();
  if (!state_.moves()) {
    // The validator refuses such a scene (effect_validation.cc); a stepper never trusts it to.
    if (flow == nullptr) {
      return InvalidArgument(
          "scene.effects: a frozen packing without the flow effect runs nothing");
    }
    if (flow->mode() == FlowMode::kSteady) return Status::Ok();
    if (!std::isfinite(flow->dt_crit_s())) {
      return FailedPrecondition("flow: no domain limits the time step (no pipes carry flow)");
    }
    dt_ = solver.dt_factor * flow->dt_crit_s();
  } else {
    const auto* contacts = FindEffect<ContactsEffectSpec>(scene_);
    const auto* bonds_effect = FindEffect<BondsEffectSpec>(scene_);
    const BondParams* bonds = bonds_effect != nullptr ? &bonds_effect->params : nullptr;
    SEEP_ASSIGN_OR_RETURN(
        contact_dt_, EstimateStableTimeStep(state_.particles, contacts->law.kn, contacts->law.kt,
                                            contacts->dt_safety, bonds));
    dt_ = contact_dt_;
    if (FluidIsASpring()) {
      fluid_limited_dt_ = FluidStableStep(state_, contacts->dt_safety);
      dt_ = CombinedStep(contact_dt_, fluid_limited_dt_);
    }
    if (flow != nullptr)
      flow_every_ = flow->SetEverySteps(dt_, fluid_limited_dt_, solver.dt_factor);
  }
  if (!program_.active()) {
    SEEP_RETURN_IF_ERROR(CheckStepCount(
        solver.end_time_s, dt_,
        state_.moves() ? "contacts.dt_safety, the contact stiffnesses" : "solver.dt_factor"));
  }
  total_steps_ = program_.active() ? std::max<std::uint64_t>(1, program_.EstimateSteps(dt_))
                                   : StepsToEnd(solver.end_time_s, dt_);
  sample_every_ = solver.progress_every > 0
                      ? solver.progress_every
                      : std::max<std::uint64_t>(1, total_steps_ / kDefaultProgressReports);
  series_stride_ = sample_every_;
  return Status::Ok();
}

std::string Stepper::Describe() const {
  const SolverSpec& solver = scene_.solver;
  if (!state_.moves()) {
    if (dt_ == 0.0) return "steady solve";
    return fmt::format(
        "{} solver: dt = {:.6g} s = {} x dt_crit (limiting domain {}), storage {} x {} (floor "
        "{:.6g} "
        "m^2), {} steps to t = {} s",
        solver.kind == SolverKind::kExplicit        ? "explicit"
        : solver.kind == SolverKind::kCrankNicolson ? "crank-nicolson"
                                                    : "implicit",
        dt_, solver.dt_factor, effects_.flow->limiting_domain(), StorageVolumeName(solver.storage),
        solver.storage_factor, state_.storage.floor_m2, total_steps_, solver.end_time_s);
  }
  std::string hooks;
  for (const Hook hook : {kFlowUpdateHook, kForceHook, kPostForceHook, kEndOfStepHook}) {
    hooks += hooks.empty() ? "[" : "] [";
    for (const std::string_view name : HookList(hook)) {
      hooks += fmt::format("{}{}", hooks.back() == '[' ? "" : " ", name);
    }
  }
  return fmt::format(
      "coupled run: {} particles, DEM dt = {:.6g} s, {} steps to t = {} s; flow every {} DEM "
      "step(s) (fluid dt_crit {:.6g} s); hooks flow-update/force/post-force/end-of-step: {}]",
      state_.particles.size(), dt_, total_steps_, solver.end_time_s, flow_every_,
      effects_.flow != nullptr ? effects_.flow->dt_crit_s() : 0.0, hooks);
}

std::vector<std::string_view> Stepper::HookList(Hook hook) const {
  const std::vector<std::size_t>& list = hook == kFlowUpdateHook  ? flow_update_
                                         : hook == kForceHook     ? force_
                                         : hook == kPostForceHook ? post_force_
                                                                  : end_of_step_;
  std::vector<std::string_view> names;
  for (const std::size_t k : list) names.push_back(effects_.all[k]->Name());
  return names;
}

std::vector<std::pair<std::string_view, double>> Stepper::EffectSeconds() const {
  std::vector<std::pair<std::string_view, double>> out;
  out.emplace_back("integration", integration_seconds_);
  for (std::size_t k = 0; k < effects_.all.size(); ++k) {
    out.emplace_back(effects_.all[k]->Name(), effect_seconds_[k]);
  }
  return out;
}

std::vector<double> Stepper::ReportedPoreVolumes() const {
  return core::ReportedPoreVolumes(state_, effects_.volume_change);
}

Status Stepper::InitialForces() {
  StepInfo info;
  info.dt = dt_;
  // With dt 0 the energy guard takes the fluid's forces at the start (its first step's work
  // averages with them) and no work.
  for (const std::size_t k : force_) SEEP_RETURN_IF_ERROR(AddForcesOf(k, info, 0.0));
  for (const std::size_t k : post_force_) {
    SEEP_RETURN_IF_ERROR(effects_.all[k]->PostForce(state_, info));
  }
  return Status::Ok();
}

Status Stepper::AddForcesOf(std::size_t k, const StepInfo& info, double guard_dt) {
  Effect& e = *effects_.all[k];
  if (&e != effects_.fluid_forces || !state_.moves()) return e.AddForces(state_, info);
  guard_.BeforeFluidForces(state_);
  SEEP_RETURN_IF_ERROR(e.AddForces(state_, info));
  guard_.AfterFluidForces(state_, guard_dt);
  return Status::Ok();
}

Result<std::uint64_t> Stepper::ClockTotalSteps(const MechanicsSnapshot& clock,
                                               std::uint64_t step) const {
  // The step is the contacts' or shorter (the fluid only ever shortens it).
  if (!(std::isfinite(clock.dt) && clock.dt > 0.0 && clock.dt <= contact_dt_)) {
    return DataLoss(fmt::format(
        "snapshot.mechanics.dt: {} s is not a step of this scene (its contacts allow {} s)",
        clock.dt, contact_dt_));
  }
  if (clock.clock_step > step ||
      !(std::isfinite(clock.clock_time_s) && clock.clock_time_s >= 0.0)) {
    return DataLoss(fmt::format(
        "snapshot.mechanics.clock_step/clock_time_s: ({}, {} s) is not a point before step {}",
        clock.clock_step, clock.clock_time_s, step));
  }
  if (clock.flow_every == 0 || !(clock.fluid_limited_dt > 0.0)) {
    return DataLoss(
        fmt::format("snapshot.mechanics.flow_every/fluid_limited_dt: ({}, {} s) must both be > 0",
                    clock.flow_every, clock.fluid_limited_dt));
  }
  // With stages the end is not known in advance (Restore estimates it from the stages).
  if (program_.active()) return step;
  return clock.clock_step + StepsToEnd(scene_.solver.end_time_s - clock.clock_time_s, clock.dt);
}

bool Stepper::FluidIsASpring() const {
  return effects_.fluid_forces != nullptr && effects_.volume_change != nullptr;
}

void Stepper::ShortenStepForTheFluid(const StepInfo& info) {
  if (!state_.moves() || !FluidIsASpring() || finished()) return;
  if (!program_.active() && info.step >= total_steps_) return;
  const auto* contacts = FindEffect<ContactsEffectSpec>(scene_);
  const double fluid_dt = FluidStableStep(state_, contacts->dt_safety);
  const double dt = CombinedStep(contact_dt_, fluid_dt);
  // Never longer: a softer fluid (domains merged) keeps the step it has.
  if (!(dt < dt_)) return;
  Logger()->info(
      "step {} (t = {} s): the re-detected pores are stiffer; DEM step {:.6g} s -> {:.6g} s "
      "(fluid alone allows {:.6g} s)",
      info.step, info.time_s, dt_, dt, fluid_dt);
  clock_step_ = info.step;
  clock_time_s_ = info.time_s;
  dt_ = dt;
  fluid_limited_dt_ = fluid_dt;
  if (effects_.flow != nullptr) {
    flow_every_ = effects_.flow->SetEverySteps(dt_, fluid_limited_dt_, scene_.solver.dt_factor);
  }
  total_steps_ = program_.active()
                     ? clock_step_ + program_.EstimateSteps(dt_)
                     : clock_step_ + StepsToEnd(scene_.solver.end_time_s - clock_time_s_, dt_);
}

Status Stepper::ReconfigureAll() {
  for (const auto& effect : effects_.all) SEEP_RETURN_IF_ERROR(effect->Reconfigure(state_));
  return Status::Ok();
}

Status Stepper::ApplyStageControls(double stage_time_s, bool force) {
  StageControls controls = program_.ControlsAt(stage_time_s);
  if (!force && controls == applied_) return Status::Ok();
  WriteControls(controls, &scene_);
  applied_ = std::move(controls);
  applied_stage_ = program_.state().index;
  return ReconfigureAll();
}

void Stepper::EndStage(int ended_by) {
  const std::uint32_t k = program_.state().index;
  const Metrics at_end = MeasureRun();
  const StageSpec& stage = scene_.stages[k];
  Logger()->info(
      "step {} (t = {} s): stage {}/{} '{}' ended ({})", step_, time_s_, k + 1, program_.count(),
      program_.Name(k),
      ended_by < 0 ? std::string("max_duration_s reached")
                   : std::string(EndConditionName(stage.end[static_cast<std::size_t>(ended_by)])));
  program_.Advance(at_end, ended_by, step_, time_s_);
  // Flow intervals and time count from the stage's start (time = clock time + steps x dt).
  clock_step_ = step_;
  clock_time_s_ = time_s_;
  if (!program_.done())
    total_steps_ = step_ + std::max<std::uint64_t>(1, program_.EstimateSteps(dt_));
}

double Stepper::FractionDone() const {
  if (program_.active()) return program_.FractionDone(step_, time_s_);
  return static_cast<double>(step_) / static_cast<double>(total_steps_);
}

Status Stepper::RebindAll() {
  for (const auto& effect : effects_.all) SEEP_RETURN_IF_ERROR(effect->Rebind(state_));
  return Status::Ok();
}

Status Stepper::CheckParticlesFinite(std::uint64_t step) const {
  const DemParticles& p = state_.particles;
  // Every step: a branch-free count on the threads, and the scan that names one only on failure.
  const double* x = p.x.data();
  const double* y = p.y.data();
  const auto n = static_cast<std::ptrdiff_t>(p.size());
  const double bad = internal::SumOverShares(n, [&](std::ptrdiff_t begin, std::ptrdiff_t end) {
    double count = 0.0;
#pragma omp simd reduction(+ : count)
    for (std::ptrdiff_t i = begin; i < end; ++i) {
      count += (internal::FiniteBranchFree(x[i]) & internal::FiniteBranchFree(y[i])) ? 0.0 : 1.0;
    }
    return count;
  });
  if (bad == 0.0) return Status::Ok();
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (!std::isfinite(p.x[i]) || !std::isfinite(p.y[i])) {
      return FailedPrecondition(
          fmt::format("mechanics: particle {} left the finite numbers at step {}; lower "
                      "contacts.dt_safety or check the stiffness and the loads",
                      i, step));
    }
  }
  return Status::Ok();
}

StepInfo Stepper::NextStep() const {
  StepInfo info;
  info.step = step_ + 1;
  const bool staged = program_.active();
  const bool last = !staged && info.step == total_steps_;
  if (state_.moves()) {
    // Steps and flow intervals count from where the current step began (step 0 unless a
    // re-detection shortened it): a run that never retunes keeps time = step x dt exactly.
    const std::uint64_t since = info.step - clock_step_;
    info.dt = dt_;
    info.time_s = clock_time_s_ + static_cast<double>(since) * dt_;
    // A stage that ends on a known bound ends on a flow update, which closes its books.
    const bool bound = staged && program_.BoundReached(info.step, info.time_s, dt_);
    if (effects_.flow != nullptr && (since % flow_every_ == 0 || last || bound)) {
      const std::uint64_t interval_start = (since - 1) / flow_every_ * flow_every_;
      info.flow_update = true;
      info.flow_dt = static_cast<double>(since - interval_start) * dt_;
    }
    return info;
  }
  if (staged) {
    // A stage with a duration ends exactly on it: its last step is the time left.
    info.dt = dt_;
    info.time_s = time_s_ + dt_;
    const double end = program_.state().start_time_s + program_.TimeBound();
    if (std::isfinite(end) && info.time_s >= end - 1e-6 * dt_) {
      info.dt = std::min(end - time_s_, dt_);
      info.time_s = end;
    }
    info.flow_update = true;
    info.flow_dt = info.dt;
    return info;
  }
  // The last step lands on end_time_s: it is the time left, which the summed steps can make an
  // ulp longer than dt (that would exceed dt_crit at dt_factor 1), so never more than dt.
  const double end = scene_.solver.end_time_s;
  info.dt = last ? std::min(end - time_s_, dt_) : dt_;
  info.time_s = last ? end : time_s_ + info.dt;
  if (dt_ == 0.0) info.time_s = 0.0;  // steady
  info.flow_update = true;
  info.flow_dt = info.dt;
  return info;
}

Status Stepper::Step() {
  LiveState& s = state_;
  // A stage's settings at the time this step starts from: new at a stage's start, and moved step
  // by step by a schedule (constant settings are not rebuilt on every step of a stage).
  if (program_.active() && (applied_stage_ != program_.state().index || program_.Scheduled())) {
    SEEP_RETURN_IF_ERROR(ApplyStageControls(time_s_ - program_.state().start_time_s, false));
  }
  const StepInfo info = NextStep();
  const bool moves = s.moves();
  Clock::time_point start = Clock::now();
  if (moves) {
    IntegrateFirstHalf(&s.particles, dt_, &s.counters.dem);
    if (!s.walls.empty()) MoveWalls(&s.walls, dt_);
    integration_seconds_ += std::chrono::duration<double>(Clock::now() - start).count();
  }
  // Particles and walls stand still from here to the end of the step: effects may share what they
  // compute from the positions until then (FluidVertices::CurrentInStep), and not beyond.
  s.step_stamp = ++s.last_step_stamp;
  const struct StepStampReset {
    LiveState& s;
    ~StepStampReset() { s.step_stamp = 0; }
  } reset_stamp{s};
  if (info.flow_update) {
    for (const std::size_t k : flow_update_) {
      Effect& e = *effects_.all[k];
      SEEP_RETURN_IF_ERROR(Timed(&effect_seconds_[k], [&] { return e.UpdateFlow(s, info); }));
    }
  }
  for (const std::size_t k : force_) {
    SEEP_RETURN_IF_ERROR(Timed(&effect_seconds_[k], [&] { return AddForcesOf(k, info, dt_); }));
  }
  // The walls moved with the velocities the servos set last step; the loads are this step's.
  if (moves) {
    guard_.AddStepWork(s, dt_);
    reversals_.AddStep(s);
  }
  for (const std::size_t k : post_force_) {
    Effect& e = *effects_.all[k];
    SEEP_RETURN_IF_ERROR(Timed(&effect_seconds_[k], [&] { return e.PostForce(s, info); }));
  }
  if (moves) {
    start = Clock::now();
    IntegrateSecondHalf(&s.particles, dt_, &s.counters.dem);
    integration_seconds_ += std::chrono::duration<double>(Clock::now() - start).count();
    // A blow-up is caught within a flow interval, or 64 steps without flow, not with a pass over
    // the particles every step; it cannot hide: non-finite positions stay non-finite.
    if (info.flow_update || info.step % 64 == 0 || info.step == total_steps_) {
      SEEP_RETURN_IF_ERROR(CheckParticlesFinite(info.step));
    }
  }
  bool retune = false;  // a re-detection replaced the network
  if (info.flow_update) {
    for (const std::size_t k : end_of_step_) {
      const std::uint64_t topology = s.topology_version;
      Effect& e = *effects_.all[k];
      SEEP_RETURN_IF_ERROR(Timed(&effect_seconds_[k], [&] { return e.EndOfStep(s, info); }));
      if (s.topology_version != topology) {
        SEEP_RETURN_IF_ERROR(Timed(&effect_seconds_[k], [&] { return RebindAll(); }));
        retune = true;
      }
    }
  }
  if (retune) ShortenStepForTheFluid(info);
  step_ = info.step;
  time_s_ = info.time_s;
  if (program_.active()) {
    step_stage_ = program_.state().index;
    // Scenes with flow end a stage by a condition on flow updates only (its books close there).
    const StageOutcome outcome =
        program_.AfterStep(s, info, effects_.flow == nullptr || info.flow_update);
    if (outcome.kind == StageOutcome::Kind::kFailed) return FailedPrecondition(outcome.message);
    if (outcome.kind == StageOutcome::Kind::kEnded) EndStage(outcome.ended_by);
  }
  if (moves && (step_ % EnergyGuard::kCheckEvery == 0 || finished())) {
    const double dt_safety = FindEffect<ContactsEffectSpec>(scene_)->dt_safety;
    SEEP_RETURN_IF_ERROR(guard_.Check(s, step_, dt_safety));
    SEEP_RETURN_IF_ERROR(reversals_.Check(s, step_, dt_, dt_safety));
  }
  if (step_ % sample_every_ == 0 || finished()) Sample();
  return Status::Ok();
}

void Stepper::Sample() {
  latest_sample_.clear();
  latest_sample_.push_back(time_s_);
  for (const Effect* effect : sample_order_) effect->AddSample(state_, &latest_sample_);
  if (program_.active()) latest_sample_.push_back(static_cast<double>(step_stage_ + 1));
  if (step_ % series_stride_ != 0 && !finished()) return;
  series_.values.insert(series_.values.end(), latest_sample_.begin(), latest_sample_.end());
  if (series_.rows() > kMaxSeriesRows) HalveSeries();
}

void Stepper::HalveSeries() {
  const std::size_t width = series_.columns.size();
  const std::size_t rows = series_.rows();
  std::size_t kept = 0;
  for (std::size_t row = 0; row < rows; row += 2, ++kept) {
    std::copy_n(series_.values.begin() + static_cast<std::ptrdiff_t>(row * width), width,
                series_.values.begin() + static_cast<std::ptrdiff_t>(kept * width));
  }
  series_.values.resize(kept * width);
  series_stride_ *= 2;
}

std::uint64_t Stepper::SeriesStrideAt(std::uint64_t step) const {
  // Rows 0, stride, 2 stride, ... up to step: a halving happened once they would exceed the cap.
  std::uint64_t stride = sample_every_;
  while (step / stride + 1 > kMaxSeriesRows) stride *= 2;
  return stride;
}

Status CheckMetricsFinite(const Metrics& metrics) {
  for (const auto& [name, value] : metrics) {
    if (!std::isfinite(value)) {
      return FailedPrecondition(
          fmt::format("report: metric '{}' is not a finite number (got {})", name, value));
    }
  }
  return Status::Ok();
}

Metrics Stepper::Measure() const {
  Metrics m = MeasureRun();
  program_.AddMetrics(&m);
  return m;
}

Metrics Stepper::MeasureRun() const {
  Metrics m;
  for (const auto& effect : effects_.all) effect->AddMetrics(state_, &m);
  if (state_.moves()) {
    m["dem_dt_s"] = dt_;
    if (std::isfinite(fluid_limited_dt_)) m["fluid_limited_dt_s"] = fluid_limited_dt_;
    m["flow_every_steps"] = static_cast<double>(flow_every_);
    // The run's count, which a checkpoint keeps (the redetection effect's own part); the work
    // counter state_.counters.redetections counts this process's calls only.
    m.try_emplace("redetections", 0.0);
    // Whether the fluid's stiffness was scaled safely (docs/accuracy.md, coupled runs): the
    // number, and beside it the bound under which the accuracy bench measured more than 5 %
    // error, so that a reader of the result (seep show) can warn without the physics.
    if (const auto numbers = MeasureCouplingNumbers(state_)) {
      m["coupling_storage_porosity"] = numbers->storage_porosity;
      m["coupling_skeleton_bulk_modulus_pa"] = numbers->skeleton_bulk_modulus_pa;
      m["coupling_fluid_to_skeleton_stiffness"] = numbers->fluid_to_skeleton_stiffness;
      m["coupling_fluid_to_skeleton_stiffness_safe_above"] = kSafeFluidToSkeletonStiffness;
      if (std::isfinite(fluid_limited_dt_) && flow_every_ > 0) {
        m["coupling_fluid_step_over_flow_interval"] =
            fluid_limited_dt_ / (static_cast<double>(flow_every_) * dt_);
        m["coupling_fluid_step_over_flow_interval_safe_above"] = kSafeFluidStepOverFlowInterval;
      }
      if (HasEffect<BondsEffectSpec>(scene_)) {
        m["coupling_bonded_dem_step_safety"] = FindEffect<ContactsEffectSpec>(scene_)->dt_safety;
        m["coupling_bonded_dem_step_safety_safe_below"] = kSafeBondedDemStepSafety;
      }
    }
  } else if (dt_ > 0.0) {
    m["dt_s"] = dt_;
  }
  m["steps"] = static_cast<double>(step_);
  m["simulated_time_s"] = time_s_;
  return m;
}

}  // namespace seep::core
