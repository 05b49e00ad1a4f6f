#include "spd_factorization.h"

#include <Eigen/CholmodSupport>
#include <Eigen/SparseCholesky>
#include <optional>
#include <string>

#include "supernodal_refactorization.h"

namespace seep::core {

LinearSolverKind ResolvedLinearSolverKind(LinearSolverKind kind, std::int64_t unknowns) {
  if (kind != LinearSolverKind::kAuto) return kind;
  return unknowns >= kSupernodalMinUnknowns ? LinearSolverKind::kCholmodSupernodal
                                            : LinearSolverKind::kEigenSimplicialLdlt;
}

std::string_view LinearSolverKindName(LinearSolverKind kind) {
  switch (kind) {
    case LinearSolverKind::kAuto:
      return "auto";
    case LinearSolverKind::kCholmodSupernodal:
      return "cholmod_supernodal";
    case LinearSolverKind::kEigenSimplicialLdlt:
      return "eigen_simplicial_ldlt";
  }
  return "unknown";
}

namespace flow_internal {

namespace {
std::string InfoName(Eigen::ComputationInfo info) {
  switch (info) {
    case Eigen::Success:
      return "success";
    case Eigen::NumericalIssue:
      return "numerical issue (matrix not positive definite)";
    case Eigen::NoConvergence:
      return "no convergence";
    case Eigen::InvalidInput:
      return "invalid input";
  }
  return "unknown";
}
}  // namespace

// Eigen's CHOLMOD wrapper with its factor in reach, for the replayed refactorization, and a solve
// that keeps its dense arrays: Eigen's calls cholmod_solve, which is cholmod_solve2 with arrays
// allocated and freed at every call (six allocations a solve, at every step of an implicit
// coupled scene); cholmod_solve2 with handles kept here reuses them, with the same arithmetic.
class CholmodSupernodal : public Eigen::CholmodSupernodalLLT<SparseMatrix, Eigen::Lower> {
 public:
  CholmodSupernodal() = default;
  CholmodSupernodal(const CholmodSupernodal&) = delete;
  CholmodSupernodal& operator=(const CholmodSupernodal&) = delete;
  ~CholmodSupernodal() {
    // Before the base class ends CHOLMOD's common block.
    for (cholmod_dense** dense : {&x_, &y_, &e_}) cholmod_free_dense(dense, &cholmod());
  }

  cholmod_factor* factor() { return m_cholmodFactor; }

  // x = A^-1 rhs with the current factor; false if CHOLMOD fails.
  bool SolveInto(const Eigen::VectorXd& rhs, Eigen::VectorXd& x) {
    cholmod_dense b{};
    b.nrow = b.nzmax = b.d = static_cast<std::size_t>(rhs.size());
    b.ncol = 1;
    b.x = const_cast<double*>(rhs.data());  // read only: B is an input of cholmod_solve2
    b.xtype = CHOLMOD_REAL;
    b.dtype = CHOLMOD_DOUBLE;
    if (!cholmod_solve2(CHOLMOD_A, m_cholmodFactor, &b, nullptr, &x_, nullptr, &y_, &e_,
                        &cholmod())) {
      return false;
    }
    x = Eigen::Map<const Eigen::VectorXd>(static_cast<const double*>(x_->x), rhs.size());
    return true;
  }

 private:
  cholmod_dense* x_ = nullptr;
  cholmod_dense* y_ = nullptr;
  cholmod_dense* e_ = nullptr;
};

// Both Eigen wrappers are neither copyable nor movable (CHOLMOD keeps a pointer into its
// common block), hence the heap indirection.
struct SpdFactorization::Impl {
  std::unique_ptr<Eigen::SimplicialLDLT<SparseMatrix, Eigen::Lower>> ldlt;
  std::unique_ptr<CholmodSupernodal> cholmod;
  // CHOLMOD's numeric factorization replayed for this pattern (supernodal_refactorization.h):
  // planned after the pattern's first factorization by CHOLMOD, dropped by Analyze.
  std::optional<SupernodalRefactorization> replay;
  bool analyzed = false;
  bool factorized = false;
};

SpdFactorization::SpdFactorization(LinearSolverKind kind)
    : kind_(kind), active_kind_(kind), impl_(std::make_unique<Impl>()) {}

SpdFactorization::~SpdFactorization() = default;
SpdFactorization::SpdFactorization(SpdFactorization&&) noexcept = default;
SpdFactorization& SpdFactorization::operator=(SpdFactorization&&) noexcept = default;

Status SpdFactorization::Analyze(const SparseMatrix& lower) {
  impl_->analyzed = impl_->factorized = false;
  impl_->replay.reset();
  // The factorization for this pattern's size (kAuto), made anew only when the kind changes.
  active_kind_ = ResolvedLinearSolverKind(kind_, lower.rows());
  if (active_kind_ == LinearSolverKind::kCholmodSupernodal) {
    impl_->ldlt.reset();
    if (!impl_->cholmod) {
      impl_->cholmod = std::make_unique<CholmodSupernodal>();
    }
  } else {
    impl_->cholmod.reset();
    if (!impl_->ldlt)
      impl_->ldlt = std::make_unique<Eigen::SimplicialLDLT<SparseMatrix, Eigen::Lower>>();
  }
  Eigen::ComputationInfo info;
  if (impl_->cholmod) {
    impl_->cholmod->analyzePattern(lower);
    info = impl_->cholmod->info();
  } else {
    impl_->ldlt->analyzePattern(lower);
    info = impl_->ldlt->info();
  }
  if (info != Eigen::Success) {
    return Internal("flow.linear_solver(" + std::string(LinearSolverKindName(active_kind_)) +
                    "): symbolic analysis failed: " + InfoName(info));
  }
  impl_->analyzed = true;
  return Status::Ok();
}

Status SpdFactorization::Factorize(const SparseMatrix& lower) {
  if (!impl_->analyzed) return Internal("flow.linear_solver: Factorize before Analyze");
  impl_->factorized = false;
  Eigen::ComputationInfo info;
  if (impl_->cholmod) {
    // The replay gives CHOLMOD's bits (or, with its own kernels, its own: see
    // supernodal_refactorization.h). A matrix it finds not positive definite goes to CHOLMOD
    // itself, which reports the failure; the plan is then made again after CHOLMOD's next
    // success, so that Eigen's wrapper holds the state of a good factorization again.
    if (impl_->replay && impl_->replay->Refactorize(lower, *impl_->cholmod->factor())) {
      impl_->factorized = true;
      ++replayed_factorizations_;
      return Status::Ok();
    }
    impl_->replay.reset();
    impl_->cholmod->factorize(lower);
    info = impl_->cholmod->info();
    if (info == Eigen::Success) {
      impl_->replay = SupernodalRefactorization::Plan(*impl_->cholmod->factor(), lower);
      // A plan with kernels of its own writes this first factor again with them, so that every
      // factor of the run has bits that do not depend on the machine's BLAS.
      if (impl_->replay && impl_->replay->OwnKernels() &&
          !impl_->replay->Refactorize(lower, *impl_->cholmod->factor())) {
        impl_->replay.reset();
        info = Eigen::NumericalIssue;
      }
    }
  } else {
    impl_->ldlt->factorize(lower);
    info = impl_->ldlt->info();
  }
  if (info != Eigen::Success) {
    return FailedPrecondition("flow.linear_solver(" +
                              std::string(LinearSolverKindName(active_kind_)) +
                              "): factorization failed: " + InfoName(info) +
                              "; check for a component without a fixed-pressure node");
  }
  impl_->factorized = true;
  return Status::Ok();
}

bool SpdFactorization::own_kernels() const {
  return impl_->factorized && impl_->cholmod && impl_->replay && impl_->replay->OwnKernels();
}

Status SpdFactorization::Solve(const Eigen::VectorXd& rhs, Eigen::VectorXd& x) const {
  if (!impl_->factorized) return Internal("flow.linear_solver: Solve before Factorize");
  Eigen::ComputationInfo info;
  if (own_kernels()) {
    info = impl_->replay->Solve(*impl_->cholmod->factor(), rhs, x) ? Eigen::Success
                                                                   : Eigen::NumericalIssue;
  } else if (impl_->cholmod) {
    info = impl_->cholmod->SolveInto(rhs, x) ? Eigen::Success : Eigen::NumericalIssue;
  } else {
    x = impl_->ldlt->solve(rhs);
    info = impl_->ldlt->info();
  }
  if (info != Eigen::Success) {
    return Internal("flow.linear_solver(" + std::string(LinearSolverKindName(active_kind_)) +
                    "): solve failed: " + InfoName(info));
  }
  return Status::Ok();
}

}  // namespace flow_internal
}  // namespace seep::core
