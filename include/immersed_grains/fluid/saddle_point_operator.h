#ifndef immersed_grains_fluid_saddle_point_operator_h
#define immersed_grains_fluid_saddle_point_operator_h

#include <deal.II/lac/trilinos_block_sparse_matrix.h>
#include <deal.II/lac/trilinos_parallel_block_vector.h>

#include <immersed_grains/linear_algebra/component_block.h>

namespace ImmersedGrains
{
  /**
   * The fluid's system [A B^T; B -C] as an operator, its velocity block A
   * applied through the scalar block K where A = K (x) I_dim
   * (component_block.h), else through the block matrix itself.
   */
  class SaddlePointOperator
  {
  public:
    using VectorType = dealii::TrilinosWrappers::MPI::BlockVector;

    SaddlePointOperator(
      const dealii::TrilinosWrappers::BlockSparseMatrix &matrix,
      const ComponentBlock                              *velocity_block)
        : matrix(matrix)
        , velocity_block(velocity_block)
    {
    }

    void
    vmult(VectorType &dst, const VectorType &src) const
    {
      if (velocity_block == nullptr)
      {
        matrix.vmult(dst, src);
        return;
      }
      velocity_block->vmult(dst.block(0), src.block(0));
      matrix.block(0, 1).vmult_add(dst.block(0), src.block(1));
      matrix.block(1, 0).vmult(dst.block(1), src.block(0));
      matrix.block(1, 1).vmult_add(dst.block(1), src.block(1));
    }

    /** A alone. */
    void
    vmult_velocity(dealii::TrilinosWrappers::MPI::Vector       &dst,
                   const dealii::TrilinosWrappers::MPI::Vector &src) const
    {
      if (velocity_block == nullptr)
        matrix.block(0, 0).vmult(dst, src);
      else
        velocity_block->vmult(dst, src);
    }

    const ComponentBlock *
    component_block() const
    {
      return velocity_block;
    }

  private:
    const dealii::TrilinosWrappers::BlockSparseMatrix &matrix;
    const ComponentBlock                              *velocity_block;
  };
} // namespace ImmersedGrains

#endif
