#ifndef immersed_grains_linear_algebra_component_smoothed_amg_h
#define immersed_grains_linear_algebra_component_smoothed_amg_h

#include <deal.II/lac/trilinos_precondition.h>
#include <deal.II/lac/trilinos_sparse_matrix.h>

#include <immersed_grains/linear_algebra/restricted_schwarz_ilu.h>

#include <memory>

class Epetra_Vector;

namespace ImmersedGrains
{
  class ComponentBlock;

  /**
   * ML's smoothed-aggregation AMG of A = K (x) I_n (component_block.h),
   * whose finest level is smoothed by K's restricted-Schwarz ILU(0)
   * (restricted_schwarz_ilu.h) instead of ML's own ILU of A.
   *
   * The finest level's smoother is most of an AMG set-up: ML factorises A,
   * n times larger than K, and on several ranks first imports the
   * overlapping rows of A. K's ILU is A's where the components have the
   * same fixed unknowns (the components never meet in the factorisation),
   * and ML's overlapping ILU, like RestrictedSchwarzILU, keeps each rank's
   * own rows of its subdomain's solution: the V-cycle is the same to
   * round-off, on one rank and on several. Its residuals are K's products.
   * The coarser levels are ML's, built from A: an AMG of K
   * applied to each component took longer to apply (ML applies a
   * multi-vector one column at a time).
   *
   * Installed through ML's C interface: the finest level is set up without
   * a smoother ("do-nothing") and is then given this object's smoothing
   * step.
   */
  class ComponentSmoothedAMG : public dealii::TrilinosWrappers::PreconditionAMG
  {
  public:
    ComponentSmoothedAMG();
    ~ComponentSmoothedAMG() override;

    using dealii::TrilinosWrappers::PreconditionAMG::initialize;

    /**
     * The AMG of @p matrix with ML's @p parameters on every level but the
     * finest, which takes @p block's ILU with @p overlap layers of the
     * neighbouring ranks' rows. @p block stands for @p matrix and must
     * outlive this object. Where @p block's components do not share their
     * fixed unknowns (a slip wall), ML's own smoother stays.
     */
    void
    initialize(const dealii::TrilinosWrappers::SparseMatrix &matrix,
               const ComponentBlock                         &block,
               const Teuchos::ParameterList                 &parameters,
               unsigned int                                  overlap);

    /**
     * One smoothing step on the finest level, in A's local numbering:
     * x = ILU^{-1} rhs where x is zero on entry (@p zero_guess), else
     * x += ILU^{-1} (rhs - A x).
     */
    void
    smooth(double *x, const double *rhs, bool zero_guess) const;

    /** Whether the finest level is smoothed by K's ILU. */
    bool
    smooths_through_components() const;

  private:
    const ComponentBlock                  *block = nullptr;
    RestrictedSchwarzILU                   fine_ilu;
    mutable std::unique_ptr<Epetra_Vector> residual, correction;
  };
} // namespace ImmersedGrains

#endif
