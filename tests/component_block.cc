// ComponentBlock stands for a matrix A = K (x) I_n whose unknowns are
// numbered node by node, with fixed unknowns (rows holding only their
// diagonal, no column elsewhere), as the fluid's velocity block is where
// its components couple only with themselves. A is built here from a
// pseudo-random K on a chain of nodes with couplings up to three nodes
// away (so that on two ranks K's columns reach the other rank's nodes),
// some nodes fixed in every component (a no-slip wall) and some in the
// first component only (a slip wall's normal component).
//
// Checked against A itself, serial and on two ranks (.mpirun=2):
// - the pattern and values are recognised (reinit(), update());
// - A's product through K equals Trilinos' product with A to round-off
//   (relative 1e-14: the same sums, in the same order, with zero terms
//   for the fixed columns);
// - with every node fixed alike in all components, K's ILU(0) applied to
//   each component equals RestrictedSchwarzILU on A to round-off (the
//   components never meet in A's factorisation); with the slip wall it is
//   only applied (it holds the wall's normal components as free: finite,
//   and the fixed unknowns divided by their diagonal exactly);
// - a matrix with an entry between two components, and one whose second
//   component differs in one value, are refused.
#include <deal.II/base/index_set.h>
#include <deal.II/base/mpi.h>
#include <deal.II/lac/trilinos_sparse_matrix.h>
#include <deal.II/lac/trilinos_sparsity_pattern.h>
#include <deal.II/lac/trilinos_vector.h>

#include <immersed_grains/linear_algebra/component_block.h>
#include <immersed_grains/linear_algebra/restricted_schwarz_ilu.h>

#include <Epetra_CrsMatrix.h>

#include <cmath>
#include <cstdio>

using namespace dealii;
using namespace ImmersedGrains;

namespace
{
  // A reproducible value in (0.5, 1.5) for a pair of nodes, symmetric.
  double
  coupling(unsigned int i, unsigned int j)
  {
    if (i > j)
      std::swap(i, j);
    return 1.0 + 0.5 * std::sin(1.7 * i + 0.3 * j * j + 0.1);
  }

  enum class Variant
  {
    alike,
    slip_wall,
    cross_component,
    second_component_differs
  };

  void
  check(const unsigned int n, const Variant variant)
  {
    const MPI_Comm     comm    = MPI_COMM_WORLD;
    const unsigned int n_ranks = Utilities::MPI::n_mpi_processes(comm);
    const unsigned int rank    = Utilities::MPI::this_mpi_process(comm);
    const unsigned int nodes   = 40;
    const unsigned int reach   = 3;
    // Nodes 0 and nodes-1 fixed in every component (no-slip); nodes 10
    // to 12 fixed in component 0 only with the slip wall.
    const auto fixed = [&](const unsigned int node, const unsigned int c)
    {
      if (node == 0 || node == nodes - 1)
        return true;
      return variant == Variant::slip_wall && c == 0 && node >= 10 &&
             node <= 12;
    };
    const unsigned int first_node = rank * nodes / n_ranks,
                       end_node   = (rank + 1) * nodes / n_ranks;
    IndexSet owned(nodes * n);
    owned.add_range(first_node * n, end_node * n);
    owned.compress();

    TrilinosWrappers::SparsityPattern pattern(owned, owned, comm);
    const auto                        for_each_entry = [&](const auto &f)
    {
      for (unsigned int i = first_node; i < end_node; ++i)
        for (unsigned int c = 0; c < n; ++c)
        {
          const unsigned int row = n * i + c;
          if (fixed(i, c))
          {
            f(row, row, 2.0 + 0.1 * c + 0.01 * i);
            continue;
          }
          for (unsigned int j = (i >= reach ? i - reach : 0);
               j <= std::min(nodes - 1, i + reach);
               ++j)
            if (!fixed(j, c))
            {
              double value = coupling(i, j) + (i == j ? 2 * reach + 1 : 0);
              if (variant == Variant::second_component_differs && c == 1 &&
                  i == 20 && j == 21)
                value *= 1 + 1e-12;
              f(row, n * j + c, value);
            }
          if (variant == Variant::cross_component && c == 0 && i == 20)
            f(row, n * i + 1, 0.25);
        }
    };
    for_each_entry([&](auto row, auto column, double)
                   { pattern.add(row, column); });
    pattern.compress();
    TrilinosWrappers::SparseMatrix A;
    A.reinit(pattern);
    for_each_entry([&](auto row, auto column, double value)
                   { A.set(row, column, value); });
    A.compress(VectorOperation::insert);

    const Epetra_Map &rows = A.trilinos_matrix().RowMap();
    std::vector<bool> fixed_rows(rows.NumMyElements());
    for (int l = 0; l < rows.NumMyElements(); ++l)
      fixed_rows[l] = fixed(rows.GID(l) / n, rows.GID(l) % n);

    const char    *names[] = {"components alike",
                              "a slip wall",
                              "an entry between components",
                              "a second component that differs"};
    ComponentBlock block;
    const bool     recognised  = block.reinit(A, n, fixed_rows);
    const bool     same_values = recognised && block.update(A);
    if (!same_values)
    {
      if (rank == 0)
        std::printf("%u components, %s: recognised: %s%s\n",
                    n,
                    names[static_cast<int>(variant)],
                    recognised ? "pattern yes, values no" : "no",
                    "");
      return;
    }

    TrilinosWrappers::MPI::Vector x(owned, comm), through_k(owned, comm),
      through_a(owned, comm);
    for (const auto i : owned)
      x[i] = std::cos(0.37 * i) + (i % 5 == 0 ? 1.0 : 0.0);
    x.compress(VectorOperation::insert);
    block.vmult(through_k, x);
    A.vmult(through_a, x);
    through_k -= through_a;
    const double product_error =
      through_k.linfty_norm() / through_a.linfty_norm();

    RestrictedSchwarzILU each_component, whole;
    each_component.initialize(block, 1);
    whole.initialize(A, 1);
    TrilinosWrappers::MPI::Vector z_k(owned, comm), z_a(owned, comm);
    each_component.vmult(z_k, x);
    whole.vmult(z_a, x);
    bool fixed_exact = true;
    for (int l = 0; l < rows.NumMyElements(); ++l)
      if (fixed_rows[l])
      {
        const auto i = rows.GID(l);
        fixed_exact  = fixed_exact && z_k[i] == x[i] / A.diag_element(i);
      }
    fixed_exact       = Utilities::MPI::min(fixed_exact ? 1 : 0, comm) == 1;
    const bool finite = std::isfinite(z_k.l2_norm());
    z_k -= z_a;
    const double ilu_error = z_k.linfty_norm() / z_a.linfty_norm();

    if (rank == 0)
    {
      std::printf("%u components, %s: recognised: yes; product as A's: %s "
                  "(relative difference < 1e-14); ILU(0): ",
                  n,
                  names[static_cast<int>(variant)],
                  product_error < 1e-14 ? "yes" : "NO");
      if (variant == Variant::alike)
        std::printf("as A's: %s (relative difference < 1e-14)\n",
                    ilu_error < 1e-14 ? "yes" : "NO");
      else
        std::printf("finite: %s, fixed unknowns divided by their diagonal: "
                    "%s\n",
                    finite ? "yes" : "NO",
                    fixed_exact ? "yes" : "NO");
    }
  }
} // namespace


int
main(int argc, char **argv)
{
  Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  for (const unsigned int n : {2u, 3u})
    for (const auto variant : {Variant::alike,
                               Variant::slip_wall,
                               Variant::cross_component,
                               Variant::second_component_differs})
      check(n, variant);
}
