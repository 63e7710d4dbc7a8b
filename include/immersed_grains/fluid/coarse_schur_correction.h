#ifndef immersed_grains_fluid_coarse_schur_correction_h
#define immersed_grains_fluid_coarse_schur_correction_h

#include <deal.II/base/index_set.h>
#include <deal.II/lac/solver_control.h>
#include <deal.II/lac/trilinos_block_sparse_matrix.h>
#include <deal.II/lac/trilinos_parallel_block_vector.h>
#include <deal.II/lac/trilinos_solver.h>
#include <deal.II/lac/trilinos_sparse_matrix.h>
#include <deal.II/lac/trilinos_vector.h>

#include <map>
#include <memory>
#include <vector>

namespace dealii
{
  template <int dim, int spacedim>
  class DoFHandler;
  template <typename number>
  class AffineConstraints;
} // namespace dealii

namespace ImmersedGrains
{
  template <int dim>
  class Geometry;

  /**
   * The second level of the fluid's preconditioner: the saddle point system
   * on a coarse Taylor-Hood space. It carries the pressure modes that vary
   * over many cells (Poiseuille flow along a long channel, flow around and
   * through a region of drag), which the pressure mass matrix and the Darcy
   * operator of BlockSchurPreconditioner approximate only within the
   * domain's inf-sup constant.
   *
   * The coarse space is the Q2-Q1 space of the box's coarse mesh refined
   * @p coarse_refinement times, interpolated at the fine DoFs' support
   * points (P_u, P_p; rows of constrained fine DoFs left empty, so every
   * coarse function is an admissible fine one). Its velocities come in two
   * parts: W P_u on the fine velocities where viscosity dominates A, and
   * (I - W) P_u on those where mass or drag do (the second only where
   * there are such). A coarse function reaching into a region of drag
   * would otherwise carry the region's drag into the flow around it; cut
   * at the region's edge instead, the coarse space could not carry a flow
   * through it (a packed bed across a channel). Its pressures are those
   * away from regions where drag exceeds viscosity a thousandfold (W_p).
   * The coarse operators are the Galerkin products of the assembled
   * blocks, A_H = Pi_u^T A Pi_u and so on, so that drag, fluid fraction and
   * viscosity enter as the fine matrix has them; the coarse system is
   * factorised once per build (Amesos KLU, all coarse rows on rank 0).
   * Applied, it gives Pi K_H^{-1} Pi^T r with
   * Pi = diag([W P_u, (I - W) P_u], W_p P_p).
   */
  class CoarseSchurCorrection
  {
  public:
    /**
     * The interpolation from the coarse space to the fine DoFs of
     * @p dof_handler (velocity components first, then the pressure, as
     * FluidSolver numbers them; @p owned_partitioning gives each block's
     * owned DoFs, block-local).
     */
    template <int dim>
    CoarseSchurCorrection(
      const dealii::DoFHandler<dim, dim>      &dof_handler,
      const dealii::AffineConstraints<double> &constraints,
      const Geometry<dim>                     &geometry,
      unsigned int                             coarse_refinement,
      const std::vector<dealii::IndexSet>     &owned_partitioning,
      MPI_Comm                                 mpi_communicator);

    ~CoarseSchurCorrection();

    /**
     * The coarse operators of @p system_matrix, factorised. @p drag_share
     * is, for each owned fine velocity, the share of mass and drag in A's
     * diagonal; it sorts the fine velocities between the two parts of the
     * coarse space (below 1/2: viscous) and drops the pressure nodes where
     * it exceeds 0.999. With @p pin_pressure (no open face: the pressure
     * is fixed up to a constant) the first coarse pressure is held at zero.
     */
    void
    build(const dealii::TrilinosWrappers::BlockSparseMatrix &system_matrix,
          const dealii::TrilinosWrappers::MPI::Vector       &drag_share,
          bool                                               pin_pressure);

    /**
     * dst = Pi K_H^{-1} Pi^T src: the coarse saddle point system's solution
     * interpolated, Pi = diag(W P_u, W_p P_p).
     */
    void
    vmult(dealii::TrilinosWrappers::MPI::BlockVector       &dst,
          const dealii::TrilinosWrappers::MPI::BlockVector &src) const;

    /** Velocity and pressure DoFs of the coarse space. */
    dealii::types::global_dof_index
    n_dofs() const
    {
      return n_coarse_velocities + n_coarse_pressures;
    }

  private:
    MPI_Comm                               mpi_communicator;
    dealii::types::global_dof_index        n_coarse_velocities = 0;
    dealii::types::global_dof_index        n_coarse_pressures  = 0;
    dealii::TrilinosWrappers::SparseMatrix velocity_interpolation;
    dealii::TrilinosWrappers::SparseMatrix pressure_interpolation;
    // The interpolations restricted by the weights of the last build()
    // (the velocities' viscous and drag parts, the pressure), and each
    // part's interpolation: the restricted one, or the whole one where
    // the weights keep every row.
    dealii::TrilinosWrappers::SparseMatrix        restricted_velocity[2];
    dealii::TrilinosWrappers::SparseMatrix        restricted_pressure;
    const dealii::TrilinosWrappers::SparseMatrix *velocity_part[2] = {nullptr,
                                                                      nullptr};
    const dealii::TrilinosWrappers::SparseMatrix *pressure_part    = nullptr;
    bool                                          pinned           = false;
    // Whether the coarse velocities have a drag part, and their number.
    bool                            split_velocities = false;
    dealii::types::global_dof_index n_velocity_rows  = 0;
    // Coarse DoFs the last build() left without an operator (no fine DoF
    // sees them, or the weights removed them): identity rows.
    std::vector<bool> empty;

    dealii::TrilinosWrappers::SparseMatrix                  coarse_matrix;
    dealii::SolverControl                                   solver_control;
    std::unique_ptr<dealii::TrilinosWrappers::SolverDirect> coarse_solver;

    mutable dealii::TrilinosWrappers::MPI::Vector coarse_pressure;
    mutable dealii::TrilinosWrappers::MPI::Vector coarse_velocity;
    mutable dealii::TrilinosWrappers::MPI::Vector coarse_rhs;
    mutable dealii::TrilinosWrappers::MPI::Vector coarse_solution;
    mutable dealii::TrilinosWrappers::MPI::Vector fine_velocity;
    dealii::TrilinosWrappers::MPI::Vector         viscous_weight;
    dealii::TrilinosWrappers::MPI::Vector         drag_weight;
    dealii::TrilinosWrappers::MPI::Vector         pressure_weight;
    dealii::TrilinosWrappers::MPI::Vector         drag_share_ghosted;
    // Each owned fine pressure's vertex: the velocity DoF there.
    std::map<dealii::types::global_dof_index, dealii::types::global_dof_index>
      pressure_vertex_velocity;
  };
} // namespace ImmersedGrains

#endif
