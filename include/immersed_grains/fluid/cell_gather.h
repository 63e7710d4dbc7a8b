#ifndef immersed_grains_fluid_cell_gather_h
#define immersed_grains_fluid_cell_gather_h

#include <deal.II/dofs/dof_handler.h>
#include <deal.II/lac/trilinos_parallel_block_vector.h>

#include <array>
#include <vector>

namespace ImmersedGrains
{
  /**
   * Reads a locally owned cell's DoF values from the fluid's ghosted
   * Trilinos block vectors through their positions in Epetra's local
   * storage, found once per mesh. Reading through the global index
   * (vector(i), or cell->get_dof_values) looks every DoF up in Epetra's
   * map, which took a tenth of the 3D assembly (doc/performance.md).
   * Every ghosted vector of the same partitioning shares the positions.
   */
  template <int dim>
  class CellGather
  {
  public:
    using VectorType = dealii::TrilinosWrappers::MPI::BlockVector;

    /** Finds the positions of every locally owned cell's DoFs in the
     * ghosted @p vector (blocks by component: velocity, then pressure). */
    void
    reinit(const dealii::DoFHandler<dim> &dof_handler,
           const VectorType              &vector);

    /** The values of the @p k-th locally owned cell (in the order of
     * DoFHandler::active_cell_iterators()) in @p vector, which must have
     * the partitioning given to reinit(). */
    void
    gather(unsigned int         k,
           const VectorType    &vector,
           std::vector<double> &values) const;

    /** The same for @p cell; false (and @p values untouched) where the
     * cell is not locally owned. */
    bool
    gather(const typename dealii::DoFHandler<dim>::active_cell_iterator &cell,
           const VectorType                                             &vector,
           std::vector<double> &values) const;

    /** Whether @p vector has the local layout given to reinit(). */
    bool
    matches(const VectorType &vector) const;

  private:
    unsigned int              dofs_per_cell = 0;
    std::array<int, 2>        local_sizes{{-1, -1}};
    std::vector<unsigned int> dof_block;    // local DoF -> block
    std::vector<int>          positions;    // per owned cell, per local DoF
    std::vector<int>          owned_number; // per active cell index: k, or -1
  };
} // namespace ImmersedGrains

#endif
