#include <immersed_grains/fluid/cell_gather.h>

#include <Epetra_MultiVector.h>

namespace ImmersedGrains
{
  template <int dim>
  void
  CellGather<dim>::reinit(const dealii::DoFHandler<dim> &dof_handler,
                          const VectorType              &vector)
  {
    const auto &fe = dof_handler.get_fe();
    dofs_per_cell  = fe.n_dofs_per_cell();
    dof_block.resize(dofs_per_cell);
    for (unsigned int i = 0; i < dofs_per_cell; ++i)
      dof_block[i] = fe.system_to_component_index(i).first < dim ? 0 : 1;
    const dealii::types::global_dof_index offset = vector.block(0).size();

    for (unsigned int block = 0; block < 2; ++block)
      local_sizes[block] = vector.block(block).trilinos_vector().MyLength();
    positions.clear();
    owned_number.assign(dof_handler.get_triangulation().n_active_cells(), -1);
    int                                          owned = 0;
    std::vector<dealii::types::global_dof_index> indices(dofs_per_cell);
    for (const auto &cell : dof_handler.active_cell_iterators())
    {
      if (!cell->is_locally_owned())
        continue;
      owned_number[cell->active_cell_index()] = owned++;
      cell->get_dof_indices(indices);
      for (unsigned int i = 0; i < dofs_per_cell; ++i)
      {
        const unsigned int block = dof_block[i];
        const auto         index = indices[i] - (block == 0 ? 0 : offset);
        const int lid = vector.block(block).trilinos_vector().Map().LID(
          static_cast<dealii::TrilinosWrappers::types::int_type>(index));
        AssertThrow(lid >= 0,
                    dealii::ExcMessage("CellGather: a DoF of an owned cell "
                                       "is not in the ghosted vector."));
        positions.push_back(lid);
      }
    }
  }


  template <int dim>
  bool
  CellGather<dim>::matches(const VectorType &vector) const
  {
    return vector.n_blocks() == 2 &&
           vector.block(0).trilinos_vector().MyLength() == local_sizes[0] &&
           vector.block(1).trilinos_vector().MyLength() == local_sizes[1];
  }


  template <int dim>
  void
  CellGather<dim>::gather(const unsigned int   k,
                          const VectorType    &vector,
                          std::vector<double> &values) const
  {
    Assert((k + 1) * dofs_per_cell <= positions.size(),
           dealii::ExcIndexRange(k, 0, positions.size() / dofs_per_cell));
    const double *const data[2] = {vector.block(0).trilinos_vector()[0],
                                   vector.block(1).trilinos_vector()[0]};
    const int          *lid     = &positions[k * dofs_per_cell];
    values.resize(dofs_per_cell);
    for (unsigned int i = 0; i < dofs_per_cell; ++i)
      values[i] = data[dof_block[i]][lid[i]];
  }


  template <int dim>
  bool
  CellGather<dim>::gather(
    const typename dealii::DoFHandler<dim>::active_cell_iterator &cell,
    const VectorType                                             &vector,
    std::vector<double>                                          &values) const
  {
    const unsigned int index = cell->active_cell_index();
    if (index >= owned_number.size() || owned_number[index] < 0)
      return false;
    gather(owned_number[index], vector, values);
    return true;
  }


  template class CellGather<2>;
  template class CellGather<3>;
} // namespace ImmersedGrains
