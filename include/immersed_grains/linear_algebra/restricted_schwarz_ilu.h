#ifndef immersed_grains_linear_algebra_restricted_schwarz_ilu_h
#define immersed_grains_linear_algebra_restricted_schwarz_ilu_h

#include <deal.II/lac/trilinos_precondition.h>
#include <deal.II/lac/trilinos_sparse_matrix.h>

namespace ImmersedGrains
{
  class ComponentBlock;

  /**
   * ILU(0) of a distributed matrix, each rank factorising its rows and
   * `overlap` layers of its neighbours' rows, combined as a restricted
   * additive Schwarz method: a rank keeps only its own rows of its
   * subdomain's solution.
   *
   * deal.II's PreconditionILU adds the overlapping subdomains' solutions
   * instead, which counts the overlap's corrections twice. As an outer
   * Krylov method's preconditioner that took 10 FGMRES iterations per step
   * on two ranks where one rank takes 6 (the two 2D clouds), and two ILU
   * sweeps as a stationary iteration diverged (doc/performance.md, "Two
   * ranks"). The restricted form is Cai & Sarkis's (SIAM J. Sci. Comput.
   * 21, 1999). On one rank both are the plain ILU(0).
   */
  class RestrictedSchwarzILU : public dealii::TrilinosWrappers::PreconditionBase
  {
  public:
    void
    initialize(const dealii::TrilinosWrappers::SparseMatrix &matrix,
               unsigned int                                  overlap);

    /**
     * The same for A = K (x) I_n (component_block.h): K's ILU(0), applied
     * to each of the n components of a vector numbered like A's rows, set
     * up from a matrix n times smaller and applied reading K's factors once
     * for all components. Where the components have the same fixed
     * unknowns that is A's ILU(0) (the components never meet in the
     * factorisation); where a node is fixed in some components only, K
     * holds it as free. @p block must outlive this object.
     */
    void
    initialize(const ComponentBlock &block, unsigned int overlap);
  };
} // namespace ImmersedGrains

#endif
