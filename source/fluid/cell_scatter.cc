#include <deal.II/lac/trilinos_index_access.h>

#include <immersed_grains/fluid/cell_scatter.h>

#include <algorithm>
#include <cmath>

namespace ImmersedGrains
{
  template <int dim>
  void
  CellScatter<dim>::clear()
  {
    pairs.clear();
    direct_index.clear();
    rows.clear();
    fixed.clear();
    positions.clear();
    dof_block.clear();
    for (auto &row : row_values)
      for (auto &values : row)
        values.clear();
    vector_values = {{nullptr, nullptr}};
  }


  template <int dim>
  bool
  CellScatter<dim>::is_direct(const unsigned int k) const
  {
    return k < direct_index.size() && direct_index[k] >= 0;
  }


  template <int dim>
  double
  CellScatter<dim>::direct_fraction() const
  {
    if (direct_index.empty())
      return 0;
    return static_cast<double>(std::count_if(direct_index.begin(),
                                             direct_index.end(),
                                             [](int d) { return d >= 0; })) /
           direct_index.size();
  }


  template <int dim>
  void
  CellScatter<dim>::reinit(
    const dealii::DoFHandler<dim>                      &dof_handler,
    const dealii::Table<2, dealii::DoFTools::Coupling> &coupling,
    const dealii::AffineConstraints<double>            &constraints,
    MatrixType                                         &matrix,
    VectorType                                         &vector)
  {
    clear();
    const auto &fe = dof_handler.get_fe();
    dofs_per_cell  = fe.n_dofs_per_cell();
    if (dofs_per_cell >= skip || matrix.n_block_rows() != 2 ||
        matrix.n_block_cols() != 2 || vector.n_blocks() != 2)
      return;

    // Epetra's rows: values, local column indices, lengths.
    std::array<std::array<std::vector<int *>, 2>, 2> row_indices;
    std::array<std::array<std::vector<int>, 2>, 2>   row_lengths;
    for (unsigned int b = 0; b < 2; ++b)
      for (unsigned int c = 0; c < 2; ++c)
      {
        const Epetra_CrsMatrix &m = matrix.block(b, c).trilinos_matrix();
        if (!m.Filled())
          return;
        const int n = m.NumMyRows();
        row_values[b][c].resize(n);
        row_indices[b][c].resize(n);
        row_lengths[b][c].resize(n);
        for (int r = 0; r < n; ++r)
        {
          m.ExtractMyRowView(r,
                             row_lengths[b][c][r],
                             row_values[b][c][r],
                             row_indices[b][c][r]);
          // The positions are found by bisection.
          if (!std::is_sorted(row_indices[b][c][r],
                              row_indices[b][c][r] + row_lengths[b][c][r]))
          {
            clear();
            return;
          }
        }
      }
    for (unsigned int b = 0; b < 2; ++b)
    {
      Epetra_FEVector &v = vector.block(b).trilinos_vector();
      vector_values[b]   = v[0];
      // add() indexes the vector by the matrix's row numbering.
      if (!v.Map().SameAs(matrix.block(b, b).trilinos_matrix().RowMap()))
      {
        clear();
        return;
      }
    }

    // The coupled pairs; the velocity block is 0, the pressure block 1.
    dof_block.resize(dofs_per_cell);
    for (unsigned int i = 0; i < dofs_per_cell; ++i)
      dof_block[i] = fe.system_to_component_index(i).first < dim ? 0 : 1;
    for (unsigned int i = 0; i < dofs_per_cell; ++i)
      for (unsigned int j = 0; j < dofs_per_cell; ++j)
        if (coupling(fe.system_to_component_index(i).first,
                     fe.system_to_component_index(j).first) !=
            dealii::DoFTools::none)
          pairs.push_back({static_cast<std::uint16_t>(i),
                           static_cast<std::uint16_t>(j),
                           dof_block[i],
                           dof_block[j]});

    const auto &blocks = matrix.get_row_indices();
    std::vector<dealii::types::global_dof_index> dofs(dofs_per_cell);
    std::vector<int>                             cell_rows(dofs_per_cell);
    std::vector<bool>                            cell_fixed(dofs_per_cell);
    // Each DoF's column in the blocks of both rows (Epetra's local
    // numbering of the column map; -1 where absent).
    std::array<std::vector<int>, 2> cell_columns;
    for (auto &columns : cell_columns)
      columns.resize(dofs_per_cell);
    std::vector<std::uint16_t> cell_positions(pairs.size());
    for (const auto &cell : dof_handler.active_cell_iterators())
    {
      if (!cell->is_locally_owned())
        continue;
      cell->get_dof_indices(dofs);
      bool direct = true;
      for (unsigned int i = 0; i < dofs_per_cell && direct; ++i)
      {
        const auto [block, index] = blocks.global_to_local(dofs[i]);
        const Epetra_CrsMatrix &m =
          matrix.block(block, block).trilinos_matrix();
        cell_rows[i] = m.RowMap().LID(
          static_cast<dealii::TrilinosWrappers::types::int_type>(index));
        for (unsigned int row_block = 0; row_block < 2; ++row_block)
          cell_columns[row_block][i] =
            matrix.block(row_block, block)
              .trilinos_matrix()
              .ColMap()
              .LID(
                static_cast<dealii::TrilinosWrappers::types::int_type>(index));
        cell_fixed[i] = constraints.is_constrained(dofs[i]);
        direct        = block == dof_block[i] && cell_rows[i] >= 0 &&
                 (!cell_fixed[i] ||
                  (constraints.get_constraint_entries(dofs[i])->empty() &&
                   !constraints.is_inhomogeneously_constrained(dofs[i])));
      }
      for (unsigned int p = 0; p < pairs.size() && direct; ++p)
      {
        const Pair &pair = pairs[p];
        if ((cell_fixed[pair.i] || cell_fixed[pair.j]) && pair.i != pair.j)
        {
          cell_positions[p] = skip;
          continue;
        }
        const int  column = cell_columns[pair.row_block][pair.j];
        const int  row    = cell_rows[pair.i];
        const int *begin  = row_indices[pair.row_block][pair.column_block][row];
        const int *end =
          begin + row_lengths[pair.row_block][pair.column_block][row];
        const int *found = std::lower_bound(begin, end, column);
        direct           = column >= 0 && found != end && *found == column &&
                 found - begin < skip;
        if (direct)
          cell_positions[p] = static_cast<std::uint16_t>(found - begin);
      }
      if (direct)
      {
        direct_index.push_back(rows.size() / dofs_per_cell);
        rows.insert(rows.end(), cell_rows.begin(), cell_rows.end());
        fixed.insert(fixed.end(), cell_fixed.begin(), cell_fixed.end());
        positions.insert(positions.end(),
                         cell_positions.begin(),
                         cell_positions.end());
      }
      else
        direct_index.push_back(-1);
    }
  }


  template <int dim>
  void
  CellScatter<dim>::add(const unsigned int                k,
                        const dealii::FullMatrix<double> &cell_matrix,
                        const dealii::Vector<double>     &cell_rhs) const
  {
    Assert(is_direct(k), dealii::ExcInternalError());
    const std::size_t    d          = direct_index[k];
    const int           *cell_rows  = &rows[d * dofs_per_cell];
    const std::size_t    first_dof  = d * dofs_per_cell;
    const std::uint16_t *cell_slots = &positions[d * pairs.size()];

    // A fixed row gets its absolute diagonal entry, or where that is zero
    // the cell matrix's mean absolute diagonal (then its l1 norm over the
    // rows, then 1), as AffineConstraints does.
    bool any_fixed = false;
    for (unsigned int i = 0; i < dofs_per_cell; ++i)
      any_fixed = any_fixed || fixed[first_dof + i];
    double mean_diagonal = 0;
    if (any_fixed)
    {
      for (unsigned int i = 0; i < dofs_per_cell; ++i)
        mean_diagonal += std::abs(cell_matrix(i, i));
      mean_diagonal /= dofs_per_cell;
      if (mean_diagonal == 0)
      {
        mean_diagonal = cell_matrix.l1_norm() / dofs_per_cell;
        if (mean_diagonal == 0)
          mean_diagonal = 1;
      }
    }

    // Each local row's values in the two column blocks, looked up once
    // per cell rather than once per entry.
    row_pointers.resize(2 * dofs_per_cell);
    for (unsigned int i = 0; i < dofs_per_cell; ++i)
      for (unsigned int column_block = 0; column_block < 2; ++column_block)
        row_pointers[2 * i + column_block] =
          row_values[dof_block[i]][column_block][cell_rows[i]];

    for (std::size_t p = 0; p < pairs.size(); ++p)
    {
      if (cell_slots[p] == skip)
        continue;
      const Pair &pair  = pairs[p];
      double      value = cell_matrix(pair.i, pair.j);
      if (pair.i == pair.j && fixed[first_dof + pair.i])
        value = value != 0 ? std::abs(value) : mean_diagonal;
      row_pointers[2 * pair.i + pair.column_block][cell_slots[p]] += value;
    }
    for (unsigned int i = 0; i < dofs_per_cell; ++i)
      if (!fixed[first_dof + i])
        vector_values[dof_block[i]][cell_rows[i]] += cell_rhs(i);
  }


  template class CellScatter<2>;
  template class CellScatter<3>;
} // namespace ImmersedGrains
