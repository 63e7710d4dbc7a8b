#include <deal.II/base/exceptions.h>

#include <immersed_grains/linear_algebra/component_block.h>

#include <Epetra_CrsMatrix.h>
#include <Epetra_Map.h>
#include <Epetra_MultiVector.h>

#include <algorithm>

namespace ImmersedGrains
{
  namespace
  {
    // Whether every rank says yes.
    bool
    all_ranks(const bool yes, const Epetra_Comm &comm)
    {
      int local = yes ? 1 : 0, global = 0;
      comm.MinAll(&local, &global, 1);
      return global == 1;
    }


    // A's values in one array (Epetra's optimised storage), and a row's
    // offset in it.
    const double *
    values_of(const Epetra_CrsMatrix &a)
    {
      int     length  = 0;
      double *values  = nullptr;
      int    *indices = nullptr;
      a.ExtractMyRowView(0, length, values, indices);
      return values;
    }
  } // namespace


  ComponentBlock::ComponentBlock() = default;


  ComponentBlock::~ComponentBlock() = default;


  bool
  ComponentBlock::reinit(const dealii::TrilinosWrappers::SparseMatrix &A,
                         const unsigned int       n_components,
                         const std::vector<bool> &fixed)
  {
    matrix.reset();
    node_map.reset();
    node_column_map.reset();
    row_map.reset();
    split_source.reset();
    split_destination.reset();
    source.clear();
    fixed_rows.clear();
    fixed_diagonal.clear();
    fixed_values.clear();
    values_checked = false;
    fixed_alike    = false;
    components     = 0;

    const Epetra_CrsMatrix &a      = A.trilinos_matrix();
    const Epetra_Map       &rows   = a.RowMap();
    const Epetra_Map       &cols   = a.ColMap();
    const int               n      = static_cast<int>(n_components);
    const int               n_rows = a.NumMyRows();

    // Whole nodes on this rank, numbered n i + c, A filled and stored in
    // one array.
    bool alike = n > 0 && a.Filled() && a.StorageOptimized() &&
                 n_rows % std::max(n, 1) == 0 &&
                 static_cast<int>(fixed.size()) == n_rows &&
                 rows.SameAs(a.RangeMap()) && rows.SameAs(a.DomainMap());
    std::vector<int> node_gids;
    for (int l = 0; alike && l < n_rows; ++l)
    {
      const int first = rows.GID(l - l % n);
      alike           = first % n == 0 && rows.GID(l) == first + l % n;
      if (alike && l % n == 0)
        node_gids.push_back(first / n);
    }

    // Each node row of K as (node column, offset in A's values) pairs: the
    // entry is read from the first free component that has it.
    const double *base = n_rows > 0 ? values_of(a) : nullptr;
    std::vector<std::vector<std::pair<int, int>>> node_rows(alike ? n_rows / n :
                                                                    0);
    for (int l = 0; alike && l < n_rows; ++l)
    {
      int     length  = 0;
      double *values  = nullptr;
      int    *indices = nullptr;
      a.ExtractMyRowView(l, length, values, indices);
      const int c = l % n;
      if (fixed[l])
      {
        alike = length == 1 && cols.GID(indices[0]) == rows.GID(l);
        fixed_rows.push_back(l);
        fixed_diagonal.push_back(values - base);
        continue;
      }
      auto &row = node_rows[l / n];
      for (int k = 0; alike && k < length; ++k)
      {
        const int column = cols.GID(indices[k]);
        alike            = column % n == c;
        row.emplace_back(column / n, (values + k) - base);
      }
    }
    // One entry per column: the first component's that has it.
    for (auto &row : node_rows)
    {
      std::stable_sort(row.begin(),
                       row.end(),
                       [](const auto &x, const auto &y)
                       { return x.first < y.first; });
      row.erase(std::unique(row.begin(),
                            row.end(),
                            [](const auto &x, const auto &y)
                            { return x.first == y.first; }),
                row.end());
    }
    // A node fixed in every component keeps its diagonal (of the first).
    for (std::size_t f = 0; alike && f < fixed_rows.size(); ++f)
      if (fixed_rows[f] % n == 0 && node_rows[fixed_rows[f] / n].empty())
        node_rows[fixed_rows[f] / n].emplace_back(rows.GID(fixed_rows[f]) / n,
                                                  fixed_diagonal[f]);
    if (!all_ranks(alike, a.Comm()))
      return false;
    bool same_fixed = true;
    for (int l = 0; l < n_rows && same_fixed; ++l)
      same_fixed = fixed[l] == fixed[l - l % n];
    fixed_alike = all_ranks(same_fixed, a.Comm());

    // K's columns: the owned nodes first, in order, then the others.
    const Epetra_Comm &comm = a.Comm();
    node_map                = std::make_unique<Epetra_Map>(
      -1, static_cast<int>(node_gids.size()), node_gids.data(), 0, comm);
    std::vector<int> column_gids(node_gids), remote;
    for (const auto &row : node_rows)
      for (const auto &[column, offset] : row)
        if (!node_map->MyGID(column))
          remote.push_back(column);
    std::sort(remote.begin(), remote.end());
    remote.erase(std::unique(remote.begin(), remote.end()), remote.end());
    column_gids.insert(column_gids.end(), remote.begin(), remote.end());
    node_column_map = std::make_unique<Epetra_Map>(
      -1, static_cast<int>(column_gids.size()), column_gids.data(), 0, comm);

    std::vector<int> lengths;
    for (const auto &row : node_rows)
      lengths.push_back(row.size());
    row_map = std::make_unique<Epetra_Map>(rows);
    matrix  = std::make_unique<Epetra_CrsMatrix>(
      Copy, *node_map, *node_column_map, lengths.data(), true);
    std::vector<int>    indices;
    std::vector<double> zeros;
    for (std::size_t i = 0; i < node_rows.size(); ++i)
    {
      indices.clear();
      for (const auto &[column, offset] : node_rows[i])
        indices.push_back(node_column_map->LID(column));
      zeros.assign(indices.size(), 0.0);
      const int error =
        matrix->InsertMyValues(i, indices.size(), zeros.data(), indices.data());
      AssertThrow(error == 0, dealii::ExcMessage("Epetra: InsertMyValues"));
    }
    int error = matrix->FillComplete(*node_map, *node_map);
    AssertThrow(error == 0, dealii::ExcMessage("Epetra: FillComplete"));
    error = matrix->OptimizeStorage();
    AssertThrow(error == 0, dealii::ExcMessage("Epetra: OptimizeStorage"));

    // The sources in K's storage order.
    for (std::size_t i = 0; i < node_rows.size(); ++i)
    {
      int     length    = 0;
      double *values    = nullptr;
      int    *k_indices = nullptr;
      matrix->ExtractMyRowView(i, length, values, k_indices);
      // update() finds A's entries in K's rows by bisection.
      AssertThrow(std::is_sorted(k_indices, k_indices + length),
                  dealii::ExcMessage("Epetra left a row of K unsorted"));
      const auto &row = node_rows[i];
      for (int k = 0; k < length; ++k)
      {
        const int  column = node_column_map->GID(k_indices[k]);
        const auto at     = std::lower_bound(row.begin(),
                                         row.end(),
                                         column,
                                         [](const auto &entry, const int c)
                                         { return entry.first < c; });
        Assert(at != row.end() && at->first == column,
               dealii::ExcInternalError());
        source.push_back(at->second);
      }
    }
    fixed_values.resize(fixed_rows.size());
    components        = n;
    split_source      = std::make_unique<Epetra_MultiVector>(*node_map, n);
    split_destination = std::make_unique<Epetra_MultiVector>(*node_map, n);
    return true;
  }


  bool
  ComponentBlock::update(const dealii::TrilinosWrappers::SparseMatrix &A)
  {
    Assert(matrix, dealii::ExcInternalError());
    const Epetra_CrsMatrix &a    = A.trilinos_matrix();
    const double           *base = a.NumMyRows() > 0 ? values_of(a) : nullptr;
    if (matrix->NumMyRows() > 0)
    {
      double *k_values = const_cast<double *>(values_of(*matrix));
      for (std::size_t p = 0; p < source.size(); ++p)
        k_values[p] = base[source[p]];
    }
    for (std::size_t f = 0; f < fixed_rows.size(); ++f)
      fixed_values[f] = base[fixed_diagonal[f]];
    if (values_checked)
      return true;

    // Every free row's entries against K's, A's columns translated to K's
    // once.
    values_checked         = true;
    bool             alike = true;
    const int        n     = components;
    const auto      &cols  = a.ColMap();
    std::vector<int> k_column(cols.NumMyElements());
    for (int k = 0; k < cols.NumMyElements(); ++k)
      k_column[k] = node_column_map->LID(cols.GID(k) / n);
    std::size_t next_fixed = 0;
    for (int l = 0; l < a.NumMyRows() && alike; ++l)
    {
      if (next_fixed < fixed_rows.size() && fixed_rows[next_fixed] == l)
      {
        ++next_fixed;
        continue;
      }
      int     length = 0, k_length = 0;
      double *values = nullptr, *k_values = nullptr;
      int    *indices = nullptr, *k_indices = nullptr;
      a.ExtractMyRowView(l, length, values, indices);
      matrix->ExtractMyRowView(l / n, k_length, k_values, k_indices);
      for (int k = 0; k < length && alike; ++k)
      {
        const int *at = std::lower_bound(k_indices,
                                         k_indices + k_length,
                                         k_column[indices[k]]);
        alike = at != k_indices + k_length && *at == k_column[indices[k]] &&
                k_values[at - k_indices] == values[k];
      }
    }
    return all_ranks(alike, a.Comm());
  }


  void
  ComponentBlock::split(const Epetra_MultiVector &interleaved,
                        Epetra_MultiVector       &split) const
  {
    const double *x = interleaved[0];
    const int     n = components;
    for (int c = 0; c < n; ++c)
    {
      double *y = split[c];
      for (int i = 0; i < split.MyLength(); ++i)
        y[i] = x[n * i + c];
    }
    for (const int l : fixed_rows)
      split[l % n][l / n] = 0;
  }


  void
  ComponentBlock::interleave(const Epetra_MultiVector &split,
                             const Epetra_MultiVector &fixed_source,
                             Epetra_MultiVector       &interleaved,
                             const bool                inverse_diagonal) const
  {
    // The fixed values first: @p fixed_source may be @p interleaved.
    const double *x = fixed_source[0];
    fixed_results.resize(fixed_rows.size());
    for (std::size_t f = 0; f < fixed_rows.size(); ++f)
    {
      const int l = fixed_rows[f];
      fixed_results[f] =
        inverse_diagonal ? x[l] / fixed_values[f] : fixed_values[f] * x[l];
    }
    double   *y = interleaved[0];
    const int n = components;
    for (int c = 0; c < n; ++c)
    {
      const double *z = split[c];
      for (int i = 0; i < split.MyLength(); ++i)
        y[n * i + c] = z[i];
    }
    for (std::size_t f = 0; f < fixed_rows.size(); ++f)
      y[fixed_rows[f]] = fixed_results[f];
  }


  void
  ComponentBlock::vmult(dealii::TrilinosWrappers::MPI::Vector       &dst,
                        const dealii::TrilinosWrappers::MPI::Vector &src) const
  {
    vmult(dst.trilinos_vector(), src.trilinos_vector());
  }


  void
  ComponentBlock::vmult(Epetra_MultiVector       &dst,
                        const Epetra_MultiVector &src) const
  {
    split(src, *split_source);
    const int error =
      matrix->Multiply(false, *split_source, *split_destination);
    AssertThrow(error == 0, dealii::ExcMessage("Epetra: Multiply"));
    interleave(*split_destination, src, dst, false);
  }


  const Epetra_CrsMatrix &
  ComponentBlock::scalar_matrix() const
  {
    return *matrix;
  }


  bool
  ComponentBlock::components_fixed_alike() const
  {
    return fixed_alike;
  }


  unsigned int
  ComponentBlock::n_components() const
  {
    return components;
  }


  const Epetra_Map &
  ComponentBlock::component_map() const
  {
    return *row_map;
  }
} // namespace ImmersedGrains
