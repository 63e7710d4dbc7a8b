// CellScatter adds cell matrices and right-hand sides into the fluid's
// Trilinos block system as AffineConstraints::distribute_local_to_global
// does, on a mesh with hanging nodes, a periodic direction and walls (zero
// velocity, constraints without entries): the cells with hanging or
// periodic DoFs are condensed in the cell, the others added entry by entry.
// Both systems are assembled from the same pseudo-random cell matrices
// (the component coupling of the fluid solver; zero diagonals in some
// cells, where a constrained row takes the mean diagonal or the l1 norm,
// and zero matrices in some) and must
// agree to round-off; serial and in parallel (.mpirun=2, where cells that
// write other ranks' rows, added entry by entry or condensed, send those
// rows' sums to their owner in one message; with the sums of the cells
// added entry by entry left out, the matrix lines read NO). With a wall
// that moves (inhomogeneous constraints) the cells on it take deal.II's
// path, and on two ranks the cells that write other ranks' rows are
// condensed, those rows going through deal.II's non-local buffers and
// compress().
#include <deal.II/base/function.h>
#include <deal.II/base/mpi.h>
#include <deal.II/distributed/tria.h>
#include <deal.II/dofs/dof_renumbering.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_q.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/grid/grid_generator.h>
#include <deal.II/grid/grid_tools.h>
#include <deal.II/lac/trilinos_sparsity_pattern.h>
#include <deal.II/numerics/vector_tools.h>

#include <immersed_grains/fluid/cell_scatter.h>

#include <cmath>
#include <cstdio>

using namespace dealii;
using namespace ImmersedGrains;

template <int dim>
void
check(const bool moving_wall)
{
  const MPI_Comm                            comm = MPI_COMM_WORLD;
  parallel::distributed::Triangulation<dim> tria(comm);
  GridGenerator::hyper_cube(tria, 0, 1, true);
  std::vector<
    GridTools::PeriodicFacePair<typename Triangulation<dim>::cell_iterator>>
    periodic;
  GridTools::collect_periodic_faces(tria, 0, 1, 0, periodic);
  tria.add_periodicity(periodic);
  tria.refine_global(dim == 2 ? 3 : 2);
  // Hanging nodes: a refined corner, touching the periodic faces.
  for (const auto &cell : tria.active_cell_iterators())
    if (cell->is_locally_owned() && cell->center()[1] < 0.4 &&
        cell->center()[0] > 0.3)
      cell->set_refine_flag();
  tria.execute_coarsening_and_refinement();

  const FESystem<dim> fe(FE_Q<dim>(2), dim, FE_Q<dim>(1), 1);
  DoFHandler<dim>     dof_handler(tria);
  dof_handler.distribute_dofs(fe);
  DoFRenumbering::Cuthill_McKee(dof_handler);
  std::vector<unsigned int> block_component(dim + 1, 0);
  block_component[dim] = 1;
  DoFRenumbering::component_wise(dof_handler, block_component);
  const auto dofs_per_block =
    DoFTools::count_dofs_per_fe_block(dof_handler, block_component);
  const auto     n_u = dofs_per_block[0], n_p = dofs_per_block[1];
  const IndexSet owned = dof_handler.locally_owned_dofs();
  IndexSet       relevant;
  DoFTools::extract_locally_relevant_dofs(dof_handler, relevant);
  const std::vector<IndexSet> owned_blocks    = {owned.get_view(0, n_u),
                                                 owned.get_view(n_u, n_u + n_p)};
  const std::vector<IndexSet> relevant_blocks = {relevant.get_view(0, n_u),
                                                 relevant.get_view(n_u,
                                                                   n_u + n_p)};

  AffineConstraints<double> constraints;
  constraints.reinit(relevant);
  DoFTools::make_hanging_node_constraints(dof_handler, constraints);
  DoFTools::make_periodicity_constraints(dof_handler, 0, 1, 0, constraints);
  const FEValuesExtractors::Vector velocities(0);
  for (unsigned int wall = 2; wall < 2 * dim; ++wall)
    VectorTools::interpolate_boundary_values(
      dof_handler,
      wall,
      Functions::ConstantFunction<dim>(moving_wall && wall == 2 ? 1.0 : 0.0,
                                       dim + 1),
      constraints,
      fe.component_mask(velocities));
  constraints.close();

  // The fluid solver's coupling: each velocity component with itself, the
  // pressure with everything.
  Table<2, DoFTools::Coupling> coupling(dim + 1, dim + 1);
  for (unsigned int c = 0; c < dim + 1; ++c)
    for (unsigned int d = 0; d < dim + 1; ++d)
      coupling[c][d] =
        (c == dim || d == dim || c == d) ? DoFTools::always : DoFTools::none;
  TrilinosWrappers::BlockSparsityPattern pattern(owned_blocks,
                                                 owned_blocks,
                                                 relevant_blocks,
                                                 comm);
  DoFTools::make_sparsity_pattern(dof_handler,
                                  coupling,
                                  pattern,
                                  constraints,
                                  false,
                                  Utilities::MPI::this_mpi_process(comm));
  pattern.compress();
  TrilinosWrappers::BlockSparseMatrix scattered, reference;
  scattered.reinit(pattern);
  reference.reinit(pattern);
  TrilinosWrappers::MPI::BlockVector scattered_rhs(owned_blocks, comm),
    reference_rhs(owned_blocks, comm);

  CellScatter<dim> scatter;
  scatter.reinit(dof_handler, coupling, constraints, scattered, scattered_rhs);
  scatter.zero_system(scattered, scattered_rhs);

  const unsigned int                   n = fe.n_dofs_per_cell();
  FullMatrix<double>                   cell_matrix(n, n);
  Vector<double>                       cell_rhs(n);
  std::vector<types::global_dof_index> dofs(n);
  unsigned int                         k = 0, direct = 0, constrained_cells = 0;
  for (const auto &cell : dof_handler.active_cell_iterators())
    if (cell->is_locally_owned())
    {
      cell->get_dof_indices(dofs);
      const Point<dim> x = cell->center();
      cell_matrix        = 0;
      for (unsigned int i = 0; i < n; ++i)
      {
        const unsigned int ci = fe.system_to_component_index(i).first;
        cell_rhs(i)           = std::cos(0.5 * i + 2 * x[0] - x[1]);
        for (unsigned int j = 0; j < n; ++j)
        {
          const unsigned int cj = fe.system_to_component_index(j).first;
          if (coupling[ci][cj] == DoFTools::none)
            continue;
          cell_matrix(i, j) =
            std::sin(1 + 0.37 * i + 0.11 * j + 3.1 * x[0] + 1.7 * x[1]);
        }
        // A zero pressure diagonal in every third cell, a zero velocity
        // diagonal in every fifth (a fixed row then takes the mean
        // absolute diagonal), a zero diagonal in every seventh (the l1
        // norm), and a zero matrix in every eleventh (then 1).
        cell_matrix(i, i) = ((ci == dim && k % 3 == 0) ||
                             (ci < dim && k % 5 == 4) || k % 7 == 1) ?
                              0.0 :
                              4 + i % 5;
      }
      if (k % 11 == 2)
        cell_matrix = 0;
      bool has_entries = false;
      for (const auto dof : dofs)
        has_entries =
          has_entries || (constraints.is_constrained(dof) &&
                          !constraints.get_constraint_entries(dof)->empty());
      constrained_cells += has_entries ? 1 : 0;

      if (scatter.is_direct(k))
      {
        scatter.add(k, cell_matrix, cell_rhs);
        ++direct;
      }
      else
        constraints.distribute_local_to_global(
          cell_matrix, cell_rhs, dofs, scattered, scattered_rhs);
      constraints.distribute_local_to_global(
        cell_matrix, cell_rhs, dofs, reference, reference_rhs);
      ++k;
    }
  scatter.compress_system(scattered, scattered_rhs);
  reference.compress(VectorOperation::add);
  reference_rhs.compress(VectorOperation::add);

  double matrix_difference = 0;
  for (unsigned int b = 0; b < 2; ++b)
    for (unsigned int c = 0; c < 2; ++c)
    {
      const double size = reference.block(b, c).frobenius_norm();
      scattered.block(b, c).add(-1.0, reference.block(b, c));
      matrix_difference =
        std::max(matrix_difference,
                 scattered.block(b, c).frobenius_norm() / size);
    }
  scattered_rhs -= reference_rhs;
  const double rhs_difference =
    scattered_rhs.l2_norm() / reference_rhs.l2_norm();

  const unsigned int cells = tria.n_global_active_cells();
  direct                   = Utilities::MPI::sum(direct, comm);
  constrained_cells        = Utilities::MPI::sum(constrained_cells, comm);
  if (Utilities::MPI::this_mpi_process(comm) == 0)
    std::printf("%dD%s: %u cells, %u with hanging or periodic DoFs, %u added "
                "directly, other ranks' rows by message: %s; matrix and "
                "right-hand side as distribute_local_to_global's: %s, %s "
                "(relative difference < 1e-14)\n",
                dim,
                moving_wall ? ", a moving wall" : "",
                cells,
                constrained_cells,
                direct,
                scatter.exchanges_remote_rows() ? "yes" : "no",
                matrix_difference < 1e-14 ? "yes" : "NO",
                rhs_difference < 1e-14 ? "yes" : "NO");
}


int
main(int argc, char **argv)
{
  Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  check<2>(false);
  check<3>(false);
  check<2>(true);
  check<3>(true);
}
