#include <deal.II/base/mpi.h>
#include <deal.II/lac/trilinos_index_access.h>

#include <immersed_grains/fluid/cell_scatter.h>
#include <immersed_grains/linear_algebra/owned_vector_memory.h>

#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>

namespace ImmersedGrains
{
  namespace
  {
    // std::lower_bound without branches on the comparisons: the columns
    // sought in a row are scattered, so every branch of the bisection is a
    // coin toss for the predictor, and the positions' search for every
    // pair of every cell was a twentieth of the 3D cloud's first steps.
    const int *
    sorted_lower_bound(const int *first, const int *last, const int value)
    {
      std::size_t n = last - first;
      if (n == 0)
        return first;
      while (n > 1)
      {
        const std::size_t half = n / 2;
        first                  = first[half] < value ? first + half : first;
        n -= half;
      }
      return first + (*first < value ? 1 : 0);
    }

    // The kind of an entry of another rank's row: bit 0 set for the
    // right-hand side, bits 1 and 2 the blocks of its row and column.
    std::uint8_t
    remote_code(const bool         rhs,
                const unsigned int row_block,
                const unsigned int column_block)
    {
      return (rhs ? 1 : 0) | (row_block << 1) | (column_block << 2);
    }

    // What AffineConstraints puts on a constrained row's diagonal where the
    // cell matrix's own entry is zero: the mean absolute diagonal, else
    // the l1 norm over the rows, else 1.
    double
    mean_absolute_diagonal(const dealii::FullMatrix<double> &cell_matrix)
    {
      double mean = 0;
      for (unsigned int i = 0; i < cell_matrix.m(); ++i)
        mean += std::abs(cell_matrix(i, i));
      mean /= cell_matrix.m();
      if (mean == 0)
      {
        mean = cell_matrix.l1_norm() / cell_matrix.m();
        if (mean == 0)
          mean = 1;
      }
      return mean;
    }
  } // namespace


  template <int dim>
  void
  CellScatter<dim>::clear()
  {
    pairs.clear();
    pair_entries.clear();
    pair_row_pointers.clear();
    pair_diagonal_dof.clear();
    direct_index.clear();
    direct_remote_start.clear();
    condensed_index.clear();
    condensed_targets_start.clear();
    condensed_entries_start.clear();
    condensed_expansion_start.clear();
    condensed_diagonals_start.clear();
    condensed_targets.clear();
    condensed_expansion_offsets.clear();
    condensed_single_targets.clear();
    condensed_expansion.clear();
    condensed_diagonals.clear();
    condensed_row_lengths.clear();
    condensed_entries.clear();
    rows.clear();
    fixed.clear();
    positions.clear();
    dof_block.clear();
    for (auto &row : row_values)
      for (auto &values : row)
        values.clear();
    for (auto &row : row_indices)
      for (auto &indices : row)
        indices.clear();
    for (auto &row : row_lengths)
      for (auto &lengths : row)
        lengths.clear();
    vector_values = {{nullptr, nullptr}};
    condensed_remote_start.clear();
    remote_visits.clear();
    remote_slots.clear();
    exchange_remote         = false;
    remote_rows_by_exchange = false;
    send_ranks.clear();
    send_offsets.clear();
    send_values.clear();
    receive_ranks.clear();
    receive_targets.clear();
    receive_values.clear();
    system_matrix = nullptr;
    system_vector = nullptr;
  }


  template <int dim>
  bool
  CellScatter<dim>::is_direct(const unsigned int k) const
  {
    return k < direct_index.size() &&
           (direct_index[k] >= 0 || condensed_index[k] >= 0);
  }


  template <int dim>
  bool
  CellScatter<dim>::exchanges_remote_rows() const
  {
    return exchange_remote;
  }


  template <int dim>
  double
  CellScatter<dim>::direct_fraction() const
  {
    if (direct_index.empty())
      return 0;
    unsigned int direct = 0;
    for (unsigned int k = 0; k < direct_index.size(); ++k)
      direct += is_direct(k) ? 1 : 0;
    return static_cast<double>(direct) / direct_index.size();
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
    system_matrix = &matrix;
    system_vector = &vector;
    // On several ranks a cell next to another rank's cells writes rows that
    // rank owns: they go by the exchange (setup_remote_exchange()), which
    // needs every cell on every rank to take the direct or condensed path.
    // Cells with inhomogeneous constraints take the general path, so then
    // such cells are condensed instead (their other rows then go by global
    // index).
    const MPI_Comm comm = matrix.get_mpi_communicator();
    remote_rows_by_exchange =
      dealii::Utilities::MPI::n_mpi_processes(comm) > 1 &&
      dealii::Utilities::MPI::min(constraints.has_inhomogeneities() ? 0 : 1,
                                  comm) == 1;
    find_positions(dof_handler, coupling, constraints, matrix, vector);
    // Every rank, whatever find_positions() found: collective.
    setup_remote_exchange(dof_handler, matrix, vector);
  }


  template <int dim>
  void
  CellScatter<dim>::find_positions(
    const dealii::DoFHandler<dim>                      &dof_handler,
    const dealii::Table<2, dealii::DoFTools::Coupling> &coupling,
    const dealii::AffineConstraints<double>            &constraints,
    MatrixType                                         &matrix,
    VectorType                                         &vector)
  {
    const auto &fe = dof_handler.get_fe();
    dofs_per_cell  = fe.n_dofs_per_cell();
    if (dofs_per_cell >= skip || matrix.n_block_rows() != 2 ||
        matrix.n_block_cols() != 2 || vector.n_blocks() != 2)
      return;

    // Epetra's rows: values, local column indices, lengths.
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
    component_of.resize(dofs_per_cell);
    for (unsigned int i = 0; i < dofs_per_cell; ++i)
    {
      component_of[i] = fe.system_to_component_index(i).first;
      dof_block[i]    = component_of[i] < dim ? 0 : 1;
    }
    for (unsigned int i = 0; i < dofs_per_cell; ++i)
      for (unsigned int j = 0; j < dofs_per_cell; ++j)
        if (coupling(fe.system_to_component_index(i).first,
                     fe.system_to_component_index(j).first) !=
            dealii::DoFTools::none)
        {
          pairs.push_back({static_cast<std::uint16_t>(i),
                           static_cast<std::uint16_t>(j),
                           dof_block[i],
                           dof_block[j]});
          pair_entries.push_back(i * dofs_per_cell + j);
          pair_row_pointers.push_back(2 * i + dof_block[j]);
          pair_diagonal_dof.push_back(i == j ? i : dofs_per_cell);
        }

    const auto &blocks = matrix.get_row_indices();
    std::vector<dealii::types::global_dof_index> dofs(dofs_per_cell);
    std::vector<int>                             cell_rows(dofs_per_cell);
    std::vector<bool>                            cell_fixed(dofs_per_cell);
    // Each DoF's column in the blocks of both rows (Epetra's local
    // numbering of the column map; -1 where absent).
    std::array<std::vector<int>, 2> cell_columns;
    for (auto &columns : cell_columns)
      columns.resize(dofs_per_cell);
    std::vector<std::uint16_t>                   cell_positions(pairs.size());
    std::vector<dealii::types::global_dof_index> cell_indices(dofs_per_cell);
    // The direct cells' arrays at their largest, instead of copies as they
    // grow (2 % of the 3D cloud's set-up).
    std::size_t n_owned = 0;
    for (const auto &cell : dof_handler.active_cell_iterators())
      n_owned += cell->is_locally_owned() ? 1 : 0;
    rows.reserve(n_owned * dofs_per_cell);
    fixed.reserve(n_owned * dofs_per_cell);
    positions.reserve(n_owned * pairs.size());
    direct_index.reserve(n_owned);
    direct_remote_start.reserve(n_owned);
    condensed_index.reserve(n_owned);
    for (const auto &cell : dof_handler.active_cell_iterators())
    {
      if (!cell->is_locally_owned())
        continue;
      cell->get_dof_indices(dofs);
      bool direct = true, remote = false;
      for (unsigned int i = 0; i < dofs_per_cell && direct; ++i)
      {
        const auto [block, index] = blocks.global_to_local(dofs[i]);
        cell_indices[i]           = index;
        const Epetra_CrsMatrix &m =
          matrix.block(block, block).trilinos_matrix();
        cell_rows[i] = m.RowMap().LID(
          static_cast<dealii::TrilinosWrappers::types::int_type>(index));
        remote = remote || cell_rows[i] < 0;
        for (unsigned int row_block = 0; row_block < 2; ++row_block)
          cell_columns[row_block][i] =
            matrix.block(row_block, block)
              .trilinos_matrix()
              .ColMap()
              .LID(
                static_cast<dealii::TrilinosWrappers::types::int_type>(index));
        cell_fixed[i] = constraints.is_constrained(dofs[i]);
        direct        = block == dof_block[i] &&
                 (cell_rows[i] >= 0 || remote_rows_by_exchange) &&
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
        // Another rank's row: a slot of the exchange, not a position.
        if (cell_rows[pair.i] < 0)
        {
          cell_positions[p] = 0;
          continue;
        }
        const int  column = cell_columns[pair.row_block][pair.j];
        const int  row    = cell_rows[pair.i];
        const int *begin  = row_indices[pair.row_block][pair.column_block][row];
        const int *end =
          begin + row_lengths[pair.row_block][pair.column_block][row];
        const int *found = sorted_lower_bound(begin, end, column);
        direct           = column >= 0 && found != end && *found == column &&
                 found - begin < skip;
        if (direct)
          cell_positions[p] = static_cast<std::uint16_t>(found - begin);
      }
      if (direct)
      {
        direct_index.push_back(rows.size() / dofs_per_cell);
        // The entries of other ranks' rows in the order add() visits them:
        // the pairs of such rows, then their right-hand sides.
        direct_remote_start.push_back(remote ? remote_visits.size() :
                                               no_remote);
        if (remote)
        {
          for (std::size_t p = 0; p < pairs.size(); ++p)
            if (cell_positions[p] != skip && cell_rows[pairs[p].i] < 0)
              remote_visits.push_back(
                {remote_code(false, pairs[p].row_block, pairs[p].column_block),
                 cell_indices[pairs[p].i],
                 cell_indices[pairs[p].j]});
          for (unsigned int i = 0; i < dofs_per_cell; ++i)
            if (!cell_fixed[i] && cell_rows[i] < 0)
              remote_visits.push_back(
                {remote_code(true, dof_block[i], 0), cell_indices[i], 0});
        }
        rows.insert(rows.end(), cell_rows.begin(), cell_rows.end());
        fixed.insert(fixed.end(), cell_fixed.begin(), cell_fixed.end());
        positions.insert(positions.end(),
                         cell_positions.begin(),
                         cell_positions.end());
        condensed_index.push_back(-1);
      }
      else
      {
        direct_index.push_back(-1);
        condensed_index.push_back(
          add_condensed_cell(dofs, constraints, coupling, matrix) ?
            static_cast<int>(condensed_targets_start.size()) - 1 :
            -1);
      }
    }
  }


  template <int dim>
  bool
  CellScatter<dim>::add_condensed_cell(
    const std::vector<dealii::types::global_dof_index> &dofs,
    const dealii::AffineConstraints<double>            &constraints,
    const dealii::Table<2, dealii::DoFTools::Coupling> &coupling,
    const MatrixType                                   &matrix)
  {
    const auto &blocks = matrix.get_row_indices();
    // The position of column @p dof in the row @p row of block (b, c), or
    // skip where it is absent.
    const auto position = [&](const unsigned int                    b,
                              const int                             row,
                              const dealii::types::global_dof_index dof)
    {
      const auto [c, index] = blocks.global_to_local(dof);
      const int column      = matrix.block(b, c).trilinos_matrix().ColMap().LID(
        static_cast<dealii::TrilinosWrappers::types::int_type>(index));
      const int *begin = row_indices[b][c][row];
      const int *end   = begin + row_lengths[b][c][row];
      const int *found = sorted_lower_bound(begin, end, column);
      return column >= 0 && found != end && *found == column &&
                 found - begin < skip ?
               static_cast<std::uint16_t>(found - begin) :
               skip;
    };
    // The owned row of @p dof in its diagonal block, or -1.
    const auto owned_row = [&](const dealii::types::global_dof_index dof)
    {
      const auto [block, index] = blocks.global_to_local(dof);
      return matrix.block(block, block)
        .trilinos_matrix()
        .RowMap()
        .LID(static_cast<dealii::TrilinosWrappers::types::int_type>(index));
    };

    std::vector<dealii::types::global_dof_index> target_dofs;
    std::vector<Target>                          targets;
    // Each local DoF's targets, one after the other (offsets[i] on).
    std::vector<Expansion>    expansion;
    std::vector<unsigned int> offsets;
    std::vector<Diagonal>     diagonals;
    // The index of @p dof among the targets, added if new; -1 if it lies
    // in another block than @p block.
    const auto target_of = [&](const dealii::types::global_dof_index dof,
                               const unsigned int                    block,
                               const unsigned int component) -> int
    {
      const auto known = std::find(target_dofs.begin(), target_dofs.end(), dof);
      if (known != target_dofs.end())
        return known - target_dofs.begin();
      const auto [dof_block, index] = blocks.global_to_local(dof);
      if (dof_block != block || target_dofs.size() + 1 >= skip)
        return -1;
      target_dofs.push_back(dof);
      targets.push_back({owned_row(dof),
                         static_cast<std::uint8_t>(block),
                         static_cast<std::uint16_t>(component),
                         index});
      return targets.size() - 1;
    };

    for (unsigned int i = 0; i < dofs_per_cell; ++i)
    {
      offsets.push_back(expansion.size());
      const unsigned int block     = dof_block[i];
      const unsigned int component = component_of[i];
      if (!constraints.is_constrained(dofs[i]))
      {
        const int t = target_of(dofs[i], block, component);
        if (t < 0)
          return false;
        expansion.push_back({static_cast<std::uint16_t>(t), 1.0});
        continue;
      }
      if (constraints.is_inhomogeneously_constrained(dofs[i]))
        return false;
      for (const auto &[master, weight] :
           *constraints.get_constraint_entries(dofs[i]))
      {
        const int t = target_of(master, block, component);
        if (t < 0)
          return false;
        expansion.push_back({static_cast<std::uint16_t>(t), weight});
      }
      const auto [dof_block, index] = blocks.global_to_local(dofs[i]);
      if (dof_block != block)
        return false;
      const int           row = owned_row(dofs[i]);
      const std::uint16_t diagonal =
        row < 0 ? skip : position(block, row, dofs[i]);
      if (row >= 0 && diagonal == skip)
        return false;
      diagonals.push_back(
        {static_cast<std::uint16_t>(i), diagonal, row, index});
    }

    // Each target's column in the blocks of both row blocks, looked up
    // once (Epetra's column maps hash the global index).
    std::array<std::vector<int>, 2> columns;
    for (unsigned int row_block = 0; row_block < 2; ++row_block)
      for (unsigned int t = 0; t < targets.size(); ++t)
        columns[row_block].push_back(
          matrix.block(row_block, targets[t].block)
            .trilinos_matrix()
            .ColMap()
            .LID(static_cast<dealii::TrilinosWrappers::types::int_type>(
              blocks.global_to_local(target_dofs[t]).second)));
    std::vector<std::uint16_t> lengths(targets.size(), 0);
    std::vector<Entry>         entries;
    entries.reserve(pairs.size() + targets.size() * targets.size() / 2);
    for (unsigned int a = 0; a < targets.size(); ++a)
      for (unsigned int b = 0; b < targets.size(); ++b)
        if (coupling(targets[a].component, targets[b].component) !=
            dealii::DoFTools::none)
        {
          ++lengths[a];
          // Another rank's row is added by global index.
          if (targets[a].row < 0)
          {
            entries.push_back({static_cast<std::uint16_t>(b), skip});
            continue;
          }
          const unsigned int row_block = targets[a].block;
          const int          column    = columns[row_block][b];
          const int         *begin =
            row_indices[row_block][targets[b].block][targets[a].row];
          const int *end =
            begin + row_lengths[row_block][targets[b].block][targets[a].row];
          const int *found = sorted_lower_bound(begin, end, column);
          if (column < 0 || found == end || *found != column ||
              found - begin >= skip)
            return false;
          entries.push_back({static_cast<std::uint16_t>(b),
                             static_cast<std::uint16_t>(found - begin)});
        }

    // The entries of other ranks' rows in the order add_condensed() visits
    // them: each remote row's entries and its right-hand side, then the
    // remote constrained rows' diagonals.
    condensed_remote_start.push_back(remote_visits.size());
    for (std::size_t a = 0, e = 0; a < targets.size(); e += lengths[a], ++a)
    {
      if (targets[a].row >= 0)
        continue;
      for (unsigned int k = 0; k < lengths[a]; ++k)
      {
        const Target &column = targets[entries[e + k].column];
        remote_visits.push_back(
          {remote_code(false, targets[a].block, column.block),
           targets[a].index,
           column.index});
      }
      remote_visits.push_back(
        {remote_code(true, targets[a].block, 0), targets[a].index, 0});
    }
    for (const Diagonal &diagonal : diagonals)
      if (diagonal.row < 0)
      {
        const unsigned int block = dof_block[diagonal.local_dof];
        remote_visits.push_back(
          {remote_code(false, block, block), diagonal.index, diagonal.index});
      }

    condensed_targets_start.push_back(condensed_targets.size());
    condensed_targets.insert(condensed_targets.end(),
                             targets.begin(),
                             targets.end());
    condensed_row_lengths.insert(condensed_row_lengths.end(),
                                 lengths.begin(),
                                 lengths.end());
    condensed_entries_start.push_back(condensed_entries.size());
    condensed_entries.insert(condensed_entries.end(),
                             entries.begin(),
                             entries.end());
    condensed_expansion_start.push_back(condensed_expansion_offsets.size());
    for (const unsigned int offset : offsets)
      condensed_expansion_offsets.push_back(condensed_expansion.size() +
                                            offset);
    condensed_expansion_offsets.push_back(condensed_expansion.size() +
                                          expansion.size());
    condensed_expansion.insert(condensed_expansion.end(),
                               expansion.begin(),
                               expansion.end());
    // A free DoF's row or column is one target with weight 1: add_condensed()
    // adds its entries straight to it.
    for (unsigned int i = 0; i < dofs_per_cell; ++i)
    {
      const unsigned int end =
        i + 1 < dofs_per_cell ? offsets[i + 1] : expansion.size();
      condensed_single_targets.push_back(
        end == offsets[i] + 1 && expansion[offsets[i]].weight == 1.0 ?
          expansion[offsets[i]].target :
          -1);
    }
    condensed_diagonals_start.push_back(condensed_diagonals.size());
    condensed_diagonals.insert(condensed_diagonals.end(),
                               diagonals.begin(),
                               diagonals.end());
    return true;
  }


  template <int dim>
  void
  CellScatter<dim>::add(const unsigned int                k,
                        const dealii::FullMatrix<double> &cell_matrix,
                        const dealii::Vector<double>     &cell_rhs) const
  {
    Assert(is_direct(k), dealii::ExcInternalError());
    if (direct_index[k] < 0)
    {
      add_condensed(condensed_index[k], cell_matrix, cell_rhs);
      return;
    }
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
    const double mean_diagonal =
      any_fixed ? mean_absolute_diagonal(cell_matrix) : 0.0;

    // Each local row's values in the two column blocks, looked up once
    // per cell rather than once per entry.
    row_pointers.resize(2 * dofs_per_cell);
    for (unsigned int i = 0; i < dofs_per_cell; ++i)
      for (unsigned int column_block = 0; column_block < 2; ++column_block)
        row_pointers[2 * i + column_block] =
          cell_rows[i] < 0 ?
            nullptr :
            row_values[dof_block[i]][column_block][cell_rows[i]];

    // Rows that another rank owns are summed in their slots of the
    // exchange.
    const std::uint32_t *slot = direct_remote_start[d] == no_remote ?
                                  nullptr :
                                  remote_slots.data() + direct_remote_start[d];
    if (slot == nullptr)
    {
      // Cells without another rank's rows: every entry goes to its
      // position, without the tests for remote rows and the bit look-ups
      // of fixed ones in the loop (which cost more than the writes).
      double *const *const       pointers = row_pointers.data();
      const double *const        values   = &cell_matrix(0, 0);
      const std::uint32_t *const entries  = pair_entries.data();
      const std::uint16_t *const row_of   = pair_row_pointers.data();
      if (!any_fixed)
        for (std::size_t p = 0; p < pairs.size(); ++p)
        {
          if (cell_slots[p] != skip)
            pointers[row_of[p]][cell_slots[p]] += values[entries[p]];
        }
      else
      {
        cell_fixed_dofs.resize(dofs_per_cell + 1);
        for (unsigned int i = 0; i < dofs_per_cell; ++i)
          cell_fixed_dofs[i] = fixed[first_dof + i];
        cell_fixed_dofs[dofs_per_cell]          = false;
        const std::uint16_t *const diagonal_dof = pair_diagonal_dof.data();
        for (std::size_t p = 0; p < pairs.size(); ++p)
        {
          if (cell_slots[p] == skip)
            continue;
          double value = values[entries[p]];
          if (cell_fixed_dofs[diagonal_dof[p]])
            value = value != 0 ? std::abs(value) : mean_diagonal;
          pointers[row_of[p]][cell_slots[p]] += value;
        }
      }
      for (unsigned int i = 0; i < dofs_per_cell; ++i)
        if (!any_fixed || !fixed[first_dof + i])
          vector_values[dof_block[i]][cell_rows[i]] += cell_rhs(i);
      return;
    }
    for (std::size_t p = 0; p < pairs.size(); ++p)
    {
      if (cell_slots[p] == skip)
        continue;
      const Pair &pair  = pairs[p];
      double      value = cell_matrix(pair.i, pair.j);
      if (pair.i == pair.j && fixed[first_dof + pair.i])
        value = value != 0 ? std::abs(value) : mean_diagonal;
      if (slot != nullptr && cell_rows[pair.i] < 0)
        send_values[*slot++] += value;
      else
        row_pointers[2 * pair.i + pair.column_block][cell_slots[p]] += value;
    }
    for (unsigned int i = 0; i < dofs_per_cell; ++i)
      if (!fixed[first_dof + i])
      {
        if (slot != nullptr && cell_rows[i] < 0)
          send_values[*slot++] += cell_rhs(i);
        else
          vector_values[dof_block[i]][cell_rows[i]] += cell_rhs(i);
      }
  }


  template <int dim>
  void
  CellScatter<dim>::add_condensed(const unsigned int                c,
                                  const dealii::FullMatrix<double> &cell_matrix,
                                  const dealii::Vector<double> &cell_rhs) const
  {
    const Target     *targets = &condensed_targets[condensed_targets_start[c]];
    const std::size_t n_targets =
      (c + 1 < condensed_targets_start.size() ? condensed_targets_start[c + 1] :
                                                condensed_targets.size()) -
      condensed_targets_start[c];
    const unsigned int *offsets =
      &condensed_expansion_offsets[condensed_expansion_start[c]];

    // C^T K C and C^T f in the cell, over its target rows.
    condensed_matrix.assign(n_targets * n_targets, 0.0);
    condensed_rhs.assign(n_targets, 0.0);
    // Most of a cell's DoFs are free: their entries go straight to their
    // target (the same sum: 1 * 1 * value is value).
    const int *single_target =
      &condensed_single_targets[std::size_t(c) * dofs_per_cell];
    for (const Pair &pair : pairs)
    {
      const double value = cell_matrix(pair.i, pair.j);
      if (value == 0)
        continue;
      if (single_target[pair.i] >= 0 && single_target[pair.j] >= 0)
      {
        condensed_matrix[single_target[pair.i] * n_targets +
                         single_target[pair.j]] += value;
        continue;
      }
      for (unsigned int e = offsets[pair.i]; e < offsets[pair.i + 1]; ++e)
      {
        const Expansion &row    = condensed_expansion[e];
        double          *target = &condensed_matrix[row.target * n_targets];
        for (unsigned int f = offsets[pair.j]; f < offsets[pair.j + 1]; ++f)
        {
          const Expansion &column = condensed_expansion[f];
          target[column.target] += row.weight * column.weight * value;
        }
      }
    }
    for (unsigned int i = 0; i < dofs_per_cell; ++i)
      for (unsigned int e = offsets[i]; e < offsets[i + 1]; ++e)
        condensed_rhs[condensed_expansion[e].target] +=
          condensed_expansion[e].weight * cell_rhs(i);

    const Entry         *entry = &condensed_entries[condensed_entries_start[c]];
    const std::uint16_t *lengths =
      &condensed_row_lengths[condensed_targets_start[c]];
    // Where this cell's entries of other ranks' rows are summed.
    const std::uint32_t *slot =
      exchange_remote ? remote_slots.data() + condensed_remote_start[c] :
                        nullptr;
    for (std::size_t a = 0; a < n_targets; ++a)
    {
      const Target &row  = targets[a];
      const double *sums = &condensed_matrix[a * n_targets];
      if (row.row < 0)
      {
        if (exchange_remote)
        {
          for (unsigned int k = 0; k < lengths[a]; ++k, ++entry)
            send_values[*slot++] += sums[entry->column];
          send_values[*slot++] += condensed_rhs[a];
          continue;
        }
        add_to_remote_row(
          row, entry, lengths[a], sums, targets, condensed_rhs[a]);
        entry += lengths[a];
        continue;
      }
      double *const values[2] = {row_values[row.block][0][row.row],
                                 row_values[row.block][1][row.row]};
      for (unsigned int k = 0; k < lengths[a]; ++k, ++entry)
        values[targets[entry->column].block][entry->position] +=
          sums[entry->column];
      vector_values[row.block][row.row] += condensed_rhs[a];
    }

    // The constrained rows' diagonal, as AffineConstraints sets it.
    const std::size_t first = condensed_diagonals_start[c];
    const std::size_t last  = c + 1 < condensed_diagonals_start.size() ?
                                condensed_diagonals_start[c + 1] :
                                condensed_diagonals.size();
    if (first == last)
      return;
    const double mean = mean_absolute_diagonal(cell_matrix);
    for (std::size_t d = first; d < last; ++d)
    {
      const Diagonal    &diagonal = condensed_diagonals[d];
      const unsigned int block    = dof_block[diagonal.local_dof];
      double             value =
        std::abs(cell_matrix(diagonal.local_dof, diagonal.local_dof));
      value = value != 0 ? value : mean;
      if (diagonal.row < 0 && exchange_remote)
        send_values[*slot++] += value;
      else if (diagonal.row < 0)
        system_matrix->block(block, block)
          .add(diagonal.index, diagonal.index, value);
      else
        row_values[block][block][diagonal.row][diagonal.position] += value;
    }
  }


  template <int dim>
  void
  CellScatter<dim>::add_to_remote_row(const Target      &row,
                                      const Entry       *entries,
                                      const unsigned int n_entries,
                                      const double      *sums,
                                      const Target      *targets,
                                      const double       rhs) const
  {
    for (unsigned int c = 0; c < 2; ++c)
    {
      remote_columns[c].clear();
      remote_values[c].clear();
    }
    for (unsigned int k = 0; k < n_entries; ++k)
    {
      const Target &column = targets[entries[k].column];
      remote_columns[column.block].push_back(column.index);
      remote_values[column.block].push_back(sums[entries[k].column]);
    }
    for (unsigned int c = 0; c < 2; ++c)
      if (!remote_columns[c].empty())
        system_matrix->block(row.block, c)
          .add(row.index,
               remote_columns[c].size(),
               remote_columns[c].data(),
               remote_values[c].data(),
               true,
               false);
    system_vector->block(row.block).add(1, &row.index, &rhs);
  }


  template <int dim>
  void
  CellScatter<dim>::setup_remote_exchange(
    const dealii::DoFHandler<dim> &dof_handler,
    MatrixType                    &matrix,
    VectorType                    &vector)
  {
    const MPI_Comm comm = matrix.get_mpi_communicator();
    if (dealii::Utilities::MPI::n_mpi_processes(comm) == 1)
    {
      remote_visits.clear();
      return;
    }

    // Only where no cell on any rank writes through deal.II: its matrix
    // and vector then receive nothing non-local and need no compress().
    bool ready = !row_values[0][0].empty();
    {
      unsigned int owned = 0;
      for (const auto &cell : dof_handler.active_cell_iterators())
        if (cell->is_locally_owned())
          ready = ready && is_direct(owned++);
      ready = ready || owned == 0;
    }

    // The owner of each remote row, from the ranks' owned ranges of each
    // block (deal.II's compute_index_owner() took 2 s per mesh of the 3D
    // cloud on two ranks, most of it in a reduction over the whole index
    // space).
    std::array<std::vector<std::tuple<dealii::types::global_dof_index,
                                      dealii::types::global_dof_index,
                                      unsigned int>>,
               2>
      owned_ranges;
    for (unsigned int b = 0; b < 2; ++b)
    {
      const dealii::IndexSet owned =
        matrix.block(b, b).locally_owned_range_indices();
      std::vector<std::pair<dealii::types::global_dof_index,
                            dealii::types::global_dof_index>>
        mine;
      for (auto i = owned.begin_intervals(); i != owned.end_intervals(); ++i)
        mine.emplace_back(*i->begin(), i->last() + 1);
      const auto all = dealii::Utilities::MPI::all_gather(comm, mine);
      for (unsigned int q = 0; q < all.size(); ++q)
        for (const auto &[first, end] : all[q])
          owned_ranges[b].emplace_back(first, end, q);
      std::sort(owned_ranges[b].begin(), owned_ranges[b].end());
    }
    const auto owner_of =
      [&](const unsigned int b, const dealii::types::global_dof_index row)
    {
      const auto &ranges = owned_ranges[b];
      auto        range =
        std::upper_bound(ranges.begin(),
                         ranges.end(),
                         row,
                         [](const dealii::types::global_dof_index i,
                            const auto &r) { return i < std::get<0>(r); });
      Assert(range != ranges.begin(), dealii::ExcInternalError());
      --range;
      Assert(row < std::get<1>(*range), dealii::ExcInternalError());
      return std::get<2>(*range);
    };

    // One slot per distinct entry, grouped by owner.
    using Key = std::tuple<unsigned int,
                           std::uint8_t,
                           dealii::types::global_dof_index,
                           dealii::types::global_dof_index>;
    // The visits sorted by key with their numbers: each run of equal keys
    // is one slot.
    std::vector<std::pair<Key, std::uint32_t>> keyed;
    keyed.reserve(remote_visits.size());
    for (std::size_t v = 0; v < remote_visits.size(); ++v)
    {
      const RemoteVisit &visit = remote_visits[v];
      keyed.emplace_back(Key(owner_of((visit.code >> 1) & 1, visit.row),
                             visit.code,
                             visit.row,
                             visit.column),
                         static_cast<std::uint32_t>(v));
    }
    std::sort(keyed.begin(), keyed.end());
    std::vector<Key> slots_by_key;
    remote_slots.resize(keyed.size());
    for (const auto &[key, v] : keyed)
    {
      if (slots_by_key.empty() || slots_by_key.back() != key)
        slots_by_key.push_back(key);
      remote_slots[v] = slots_by_key.size() - 1;
    }
    keyed.clear();
    keyed.shrink_to_fit();
    remote_visits.clear();
    remote_visits.shrink_to_fit();

    // Each owner learns once which entries it will receive, in slot order.
    std::map<unsigned int, std::vector<std::uint64_t>> requests;
    for (std::size_t k = 0; k < slots_by_key.size(); ++k)
    {
      const auto &[owner, code, row, column] = slots_by_key[k];
      if (send_ranks.empty() || send_ranks.back() != owner)
      {
        send_ranks.push_back(owner);
        send_offsets.push_back(k);
      }
      auto &list = requests[owner];
      list.push_back(code);
      list.push_back(row);
      list.push_back(column);
    }
    send_offsets.push_back(slots_by_key.size());
    send_values.assign(slots_by_key.size(), 0.0);

    const auto asked = dealii::Utilities::MPI::some_to_some(comm, requests);
    for (const auto &[rank, list] : asked)
    {
      receive_ranks.push_back(rank);
      auto &targets = receive_targets.emplace_back();
      for (std::size_t k = 0; k + 2 < list.size(); k += 3)
      {
        const unsigned int b       = (list[k] >> 1) & 1;
        const unsigned int c       = (list[k] >> 2) & 1;
        const bool         for_rhs = list[k] & 1;
        const auto         gid     = [](const std::uint64_t i)
        { return static_cast<dealii::TrilinosWrappers::types::int_type>(i); };
        const Epetra_CrsMatrix &m   = matrix.block(b, c).trilinos_matrix();
        const int               row = m.RowMap().LID(gid(list[k + 1]));
        if (!ready || row < 0)
        {
          ready = false;
          break;
        }
        if (for_rhs)
        {
          targets.push_back(vector_values[b] + row);
          continue;
        }
        const int  column = m.ColMap().LID(gid(list[k + 2]));
        const int *begin  = row_indices[b][c][row];
        const int *end    = begin + row_lengths[b][c][row];
        const int *found  = sorted_lower_bound(begin, end, column);
        if (column < 0 || found == end || *found != column)
        {
          ready = false;
          break;
        }
        targets.push_back(row_values[b][c][row] + (found - begin));
      }
      receive_values.emplace_back(targets.size());
    }

    exchange_remote = dealii::Utilities::MPI::min(int(ready), comm) == 1;
    if (!exchange_remote)
    {
      // Not reached where no constraint is inhomogeneous, unless a cell or
      // an owner's look-up of a slot failed to qualify; the direct cells
      // that write other ranks' rows then take the general path.
      for (int &d : direct_index)
        if (d >= 0 && direct_remote_start[d] != no_remote)
          d = -1;
      remote_slots.clear();
      send_ranks.clear();
      send_offsets.clear();
      send_values.clear();
      receive_ranks.clear();
      receive_targets.clear();
      receive_values.clear();
      return;
    }
    ignore_non_local_entries(vector);
  }


  template <int dim>
  void
  CellScatter<dim>::zero_system(MatrixType &matrix, VectorType &vector) const
  {
    vector = 0;
    if (!exchange_remote)
    {
      // deal.II's zeroing compresses each block (an export on several
      // ranks).
      matrix = 0;
      return;
    }
    for (unsigned int b = 0; b < 2; ++b)
      for (unsigned int c = 0; c < 2; ++c)
        for (std::size_t r = 0; r < row_values[b][c].size(); ++r)
          std::fill(row_values[b][c][r],
                    row_values[b][c][r] + row_lengths[b][c][r],
                    0.0);
    std::fill(send_values.begin(), send_values.end(), 0.0);
  }


  template <int dim>
  void
  CellScatter<dim>::compress_system(MatrixType &matrix,
                                    VectorType &vector) const
  {
    if (!exchange_remote)
    {
      matrix.compress(dealii::VectorOperation::add);
      vector.compress(dealii::VectorOperation::add);
      return;
    }
    // Tag: this exchange's own, apart from the grains' messages.
    constexpr int            tag  = 7431;
    const MPI_Comm           comm = matrix.get_mpi_communicator();
    std::vector<MPI_Request> requests;
    requests.reserve(receive_ranks.size() + send_ranks.size());
    for (std::size_t i = 0; i < receive_ranks.size(); ++i)
    {
      const int error = MPI_Irecv(receive_values[i].data(),
                                  receive_values[i].size(),
                                  MPI_DOUBLE,
                                  receive_ranks[i],
                                  tag,
                                  comm,
                                  &requests.emplace_back());
      AssertThrowMPI(error);
    }
    for (std::size_t i = 0; i < send_ranks.size(); ++i)
    {
      const int error = MPI_Isend(send_values.data() + send_offsets[i],
                                  send_offsets[i + 1] - send_offsets[i],
                                  MPI_DOUBLE,
                                  send_ranks[i],
                                  tag,
                                  comm,
                                  &requests.emplace_back());
      AssertThrowMPI(error);
    }
    const int error =
      MPI_Waitall(requests.size(), requests.data(), MPI_STATUSES_IGNORE);
    AssertThrowMPI(error);
    for (std::size_t i = 0; i < receive_ranks.size(); ++i)
      for (std::size_t k = 0; k < receive_targets[i].size(); ++k)
        *receive_targets[i][k] += receive_values[i][k];
  }


  template class CellScatter<2>;
  template class CellScatter<3>;
} // namespace ImmersedGrains
