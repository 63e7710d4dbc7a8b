// ComponentSmoothedAMG is ML's AMG of A = K (x) I_3 whose finest level is
// smoothed by K's restricted-Schwarz ILU(0) instead of ML's own ILU of A.
// A is built here from K, a seven-point diffusion operator with a small
// mass term on a 16^3 lattice of nodes (12,288 unknowns, so that ML
// coarsens at least once), with the nodes on one face fixed in every
// component (a no-slip wall: rows holding only their diagonal), and
// again with those nodes fixed in the normal component only (a slip wall),
// where K's ILU is not A's and ML's own smoother must stay.
//
// Checked against deal.II's PreconditionAMG with the same parameters and
// ML's own ILU smoother on the finest level: one V-cycle applied to the
// same vector agrees to round-off (relative 1e-12), serial and on two
// ranks (.mpirun=2). K's ILU(0) is A's, the components never meeting in
// the factorisation; the residual comes from K's product, the same sums as
// A's; and ML's overlapping ILU, like RestrictedSchwarzILU, keeps each
// rank's own rows of its subdomain's solution. With the finest smoother
// not installed the no-slip lines read NO.
#include <deal.II/base/index_set.h>
#include <deal.II/base/mpi.h>
#include <deal.II/lac/trilinos_precondition.h>
#include <deal.II/lac/trilinos_sparse_matrix.h>
#include <deal.II/lac/trilinos_sparsity_pattern.h>
#include <deal.II/lac/trilinos_vector.h>

#include <immersed_grains/linear_algebra/component_block.h>
#include <immersed_grains/linear_algebra/component_smoothed_amg.h>

#include <Epetra_MultiVector.h>
#include <Teuchos_ParameterList.hpp>

#include <cmath>
#include <cstdio>
#include <memory>

using namespace dealii;
using namespace ImmersedGrains;

namespace
{
  constexpr unsigned int side = 16, n = 3;

  unsigned int
  node_of(const unsigned int i, const unsigned int j, const unsigned int k)
  {
    return (k * side + j) * side + i;
  }

  void
  check(const bool slip_wall)
  {
    // The nodes on the face k = 0 are fixed in every component (no-slip) or
    // only in the normal one, c = 2 (slip).
    const auto fixed =
      [slip_wall](const unsigned int node, const unsigned int c)
    { return node < side * side && (!slip_wall || c == 2); };
    const MPI_Comm     comm       = MPI_COMM_WORLD;
    const unsigned int n_ranks    = Utilities::MPI::n_mpi_processes(comm);
    const unsigned int rank       = Utilities::MPI::this_mpi_process(comm);
    const unsigned int nodes      = side * side * side;
    const unsigned int first_node = rank * nodes / n_ranks,
                       end_node   = (rank + 1) * nodes / n_ranks;
    IndexSet owned(nodes * n);
    owned.add_range(first_node * n, end_node * n);
    owned.compress();

    // K: 6 on the diagonal plus a mass of 0.001, -1 to each lattice
    // neighbour: diffusion dominates, as in a viscous cloud.
    const auto neighbours = [](const unsigned int node)
    {
      std::vector<unsigned int> result;
      const unsigned int        i = node % side, j = (node / side) % side,
                         k = node / (side * side);
      if (i > 0)
        result.push_back(node_of(i - 1, j, k));
      if (i + 1 < side)
        result.push_back(node_of(i + 1, j, k));
      if (j > 0)
        result.push_back(node_of(i, j - 1, k));
      if (j + 1 < side)
        result.push_back(node_of(i, j + 1, k));
      if (k > 0)
        result.push_back(node_of(i, j, k - 1));
      if (k + 1 < side)
        result.push_back(node_of(i, j, k + 1));
      return result;
    };
    TrilinosWrappers::SparsityPattern pattern(owned, owned, comm);
    for (unsigned int node = first_node; node < end_node; ++node)
      for (unsigned int c = 0; c < n; ++c)
      {
        const types::global_dof_index row = node * n + c;
        pattern.add(row, row);
        if (fixed(node, c))
          continue;
        for (const unsigned int other : neighbours(node))
          if (!fixed(other, c))
            pattern.add(row, other * n + c);
      }
    pattern.compress();
    TrilinosWrappers::SparseMatrix A;
    A.reinit(pattern);
    std::vector<bool> fixed_rows;
    for (unsigned int node = first_node; node < end_node; ++node)
      for (unsigned int c = 0; c < n; ++c)
      {
        const types::global_dof_index row = node * n + c;
        fixed_rows.push_back(fixed(node, c));
        if (fixed(node, c))
        {
          A.set(row, row, 6.0);
          continue;
        }
        A.set(row, row, 6.001);
        for (const unsigned int other : neighbours(node))
          if (!fixed(other, c))
            A.set(row, other * n + c, -1.0);
      }
    A.compress(VectorOperation::insert);

    ComponentBlock block;
    const bool recognised = block.reinit(A, n, fixed_rows) && block.update(A);

    // The velocity block's parameters (block_preconditioner.cc).
    TrilinosWrappers::PreconditionAMG::AdditionalData data;
    data.elliptic              = true;
    data.higher_order_elements = true;
    data.smoother_type         = "ILU";
    data.smoother_sweeps       = 1;
    data.smoother_overlap      = 1;
    std::vector<std::vector<bool>> modes(n,
                                         std::vector<bool>(owned.n_elements()));
    for (unsigned int l = 0; l < owned.n_elements(); ++l)
      modes[l % n][l] = true;
    data.constant_modes = modes;
    Teuchos::ParameterList              parameters;
    std::unique_ptr<Epetra_MultiVector> constant_modes;
    data.set_parameters(parameters, constant_modes, A);

    TrilinosWrappers::PreconditionAMG ml_own;
    ml_own.initialize(A, parameters);
    ComponentSmoothedAMG with_component_ilu;
    with_component_ilu.initialize(A, block, parameters, 1);

    TrilinosWrappers::MPI::Vector b(owned, comm);
    for (const auto row : owned)
      b(row) = fixed(row / n, row % n) ? 0.0 : std::sin(0.37 * row + 0.2);
    b.compress(VectorOperation::insert);
    TrilinosWrappers::MPI::Vector own_cycle(b), component_cycle(b);
    ml_own.vmult(own_cycle, b);
    with_component_ilu.vmult(component_cycle, b);
    const double norm   = own_cycle.l2_norm();
    const bool   finite = std::isfinite(component_cycle.l2_norm());
    component_cycle -= own_cycle;
    const double difference = component_cycle.l2_norm() / norm;

    if (rank == 0)
    {
      std::printf("%s, %u unknowns on %u rank(s): recognised as K (x) I_3: %s; "
                  "finest level smoothed by K's ILU: %s; ",
                  slip_wall ? "a slip wall" : "a no-slip wall",
                  nodes * n,
                  n_ranks,
                  recognised ? "yes" : "no",
                  with_component_ilu.smooths_through_components() ? "yes" :
                                                                    "no");
      std::printf("one V-cycle as with ML's own ILU: %s\n",
                  finite && difference < 1e-12 ?
                    "yes (relative difference < 1e-12)" :
                    "NO");
    }
  }
} // namespace


int
main(int argc, char **argv)
{
  Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  check(false);
  check(true);
}
