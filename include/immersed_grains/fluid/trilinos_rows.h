#ifndef immersed_grains_fluid_trilinos_rows_h
#define immersed_grains_fluid_trilinos_rows_h

#include <deal.II/base/exceptions.h>
#include <deal.II/base/types.h>

#include <deal.II/lac/trilinos_index_access.h>

#include <Epetra_CrsMatrix.h>

#include <vector>

namespace ImmersedGrains
{
  /**
   * Calls f(row, columns, values) for every locally owned row of @p matrix,
   * with global indices, through Epetra's views of its rows. deal.II's row
   * iterators copy the whole row into a cache at begin() and again at
   * end(): the loops that used them spent 15 % of a three-step 3D run
   * there (perf, Lethe's scene). A row Epetra cannot show, or shows with a
   * negative length, is an error rather than an empty row.
   */
  template <typename RowFunction>
  void
  for_each_owned_row(const Epetra_CrsMatrix &matrix, const RowFunction &f)
  {
    std::vector<dealii::types::global_dof_index> columns;
    for (int row = 0; row < matrix.NumMyRows(); ++row)
    {
      int     n       = 0;
      double *values  = nullptr;
      int    *indices = nullptr;
      AssertThrow(matrix.ExtractMyRowView(row, n, values, indices) == 0 &&
                    n >= 0,
                  dealii::ExcMessage("a row of a Trilinos matrix could not "
                                     "be read"));
      columns.resize(n);
      for (int k = 0; k < n; ++k)
        columns[k] =
          dealii::TrilinosWrappers::global_column_index(matrix, indices[k]);
      f(static_cast<dealii::types::global_dof_index>(
          dealii::TrilinosWrappers::global_row_index(matrix, row)),
        columns,
        values);
    }
  }
} // namespace ImmersedGrains

#endif
