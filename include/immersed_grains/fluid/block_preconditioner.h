#ifndef immersed_grains_fluid_block_preconditioner_h
#define immersed_grains_fluid_block_preconditioner_h

#include <deal.II/lac/trilinos_block_sparse_matrix.h>
#include <deal.II/lac/trilinos_parallel_block_vector.h>
#include <deal.II/lac/trilinos_precondition.h>

#include <immersed_grains/fluid/saddle_point_operator.h>
#include <immersed_grains/linear_algebra/component_smoothed_amg.h>
#include <immersed_grains/linear_algebra/restricted_schwarz_ilu.h>

#include <vector>

namespace ImmersedGrains
{
  /**
   * Upper block-triangular preconditioner for the saddle point system
   *
   *   [ A  B^T ] [u]   [f]        P = [ A  B^T ]
   *   [ B  0   ] [p] = [g],           [ 0  -S  ],
   *
   * applied as p = -S~^{-1} g, u = A~^{-1}(f - B^T p). A~^{-1} is one or
   * more AMG V-cycles on the velocity block, or one ILU where mass and drag
   * dominate A, or a few Krylov iterations preconditioned by either (a
   * variable preconditioner: FGMRES outside). S~^{-1}
   * is the Cahouet-Chabard sum M_w^{-1} + S_c^{-1} of a pressure mass matrix
   * weighted by phi/mu (the viscous limit of S) and S_c = B diag(c M)^{-1} B^T,
   * the limit where mass and drag c = phi rho a0/dt + beta dominate, the
   * first approximated by a few ILU-preconditioned CG iterations, the second
   * by one AMG V-cycle; either term may be left out. M_w's weight is
   * reduced where drag dominates (fluid_assembly.cc). doc/theory.md
   * motivates the choice.
   */
  class CoarseSchurCorrection;

  class BlockSchurPreconditioner
  {
  public:
    using VectorType = dealii::TrilinosWrappers::MPI::BlockVector;

    struct Settings
    {
      // ILU(0) of A instead of AMG: for a mass- or drag-dominated A.
      bool velocity_ilu = false;
      // V-cycles, or ILU sweeps, per application of A~^{-1}.
      unsigned int velocity_cycles = 2;

      // If positive: A~^{-1} is up to this many GMRES iterations
      // preconditioned by one V-cycle, stopped early at a relative residual
      // of inner_tolerance; 0: velocity_cycles V-cycles.
      unsigned int inner_iterations = 0;
      double       inner_tolerance  = 1e-6;

      // 1: M_w^{-1} is one ILU application; N > 1: CG preconditioned by
      // the ILU until the relative residual is below
      // pressure_mass_tolerance, at most N iterations.
      unsigned int pressure_mass_iterations = 3;
      double       pressure_mass_tolerance  = 3e-4;

      // The AMG's aggregation threshold for A: the strength below which a
      // coupling is dropped when the aggregates are formed. 0.05 suits the
      // 2D Q2 blocks; in 3D it doubled the set-up at 10^5 DoFs
      // (doc/performance.md).
      double velocity_aggregation_threshold = 0.02;
      // Symmetric Gauss-Seidel instead of ILU on the AMG's coarser levels:
      // in 3D their operators hold about 200 entries per row, whose ILU
      // cost more to set up than the finest level's (doc/performance.md,
      // preconditioner benchmarks).
      bool velocity_coarse_gauss_seidel = false;

      // Constant modes of the velocity components (near null space of A).
      std::vector<std::vector<bool>> velocity_constant_modes;
    };

    /**
     * @p pressure_mass or @p pressure_laplace may be null to leave that
     * term out of S~^{-1}.
     */
    BlockSchurPreconditioner(
      const dealii::TrilinosWrappers::BlockSparseMatrix &system_matrix,
      const dealii::TrilinosWrappers::SparseMatrix      *pressure_mass,
      const dealii::TrilinosWrappers::SparseMatrix      *pressure_laplace,
      const Settings                                    &settings,
      const CoarseSchurCorrection                       *coarse = nullptr,
      const ComponentBlock *velocity_block                      = nullptr);
    // @p coarse, if given, is applied first (CoarseSchurCorrection).
    // @p velocity_block, if given, is system_matrix's velocity block
    // stored once for all components: products and the ILU use it.

    void
    vmult(VectorType &dst, const VectorType &src) const;


  private:
    void
    apply_block(VectorType &dst, const VectorType &src) const;

    // The two-level correction's solution and the residual it leaves.
    mutable VectorType coarse_correction, coarse_residual;

    void
    solve_velocity(dealii::TrilinosWrappers::MPI::Vector       &dst,
                   const dealii::TrilinosWrappers::MPI::Vector &src) const;

    void
    solve_pressure_mass(dealii::TrilinosWrappers::MPI::Vector       &dst,
                        const dealii::TrilinosWrappers::MPI::Vector &src) const;

    const dealii::TrilinosWrappers::BlockSparseMatrix &system_matrix;
    const SaddlePointOperator                          system;
    const Settings                                     settings;
    const dealii::TrilinosWrappers::SparseMatrix      *pressure_mass;
    const CoarseSchurCorrection                       *coarse;

    // The one of these that A~^{-1} applies.
    const dealii::TrilinosWrappers::PreconditionBase &
    velocity_preconditioner() const;

    ComponentSmoothedAMG                      velocity_amg;
    RestrictedSchwarzILU                      velocity_ilu;
    dealii::TrilinosWrappers::PreconditionILU pressure_mass_ilu;
    dealii::TrilinosWrappers::PreconditionAMG pressure_laplace_amg;
    bool                                      use_mass    = false;
    bool                                      use_laplace = false;

    mutable dealii::TrilinosWrappers::MPI::Vector velocity_tmp;
    mutable dealii::TrilinosWrappers::MPI::Vector velocity_residual;
    mutable dealii::TrilinosWrappers::MPI::Vector velocity_correction;
    mutable dealii::TrilinosWrappers::MPI::Vector pressure_tmp;
    // The conjugate-gradient iteration of solve_pressure_mass().
    mutable dealii::TrilinosWrappers::MPI::Vector cg_residual;
    mutable dealii::TrilinosWrappers::MPI::Vector cg_preconditioned;
    mutable dealii::TrilinosWrappers::MPI::Vector cg_direction;
    mutable dealii::TrilinosWrappers::MPI::Vector cg_product;
  };
} // namespace ImmersedGrains

#endif
