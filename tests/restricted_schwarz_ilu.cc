// RestrictedSchwarzILU, the fluid's ILU of the velocity block, on a
// scalar Q2 block of the velocity's form, A = c M + nu K, with c a hundred
// times larger in a ball (the drag of a cloud) and nu set so that the
// block's viscous number nu/(c h^2) is 1 outside it, where
// `Velocity preconditioner = auto` still takes the ILU; walls all round.
//
// - One rank: the preconditioner is the plain ILU(0), so one application
//   equals deal.II's PreconditionILU entry by entry (window zero).
// - GMRES to 1e-8 preconditioned by it: on two ranks (.mpirun=2) each rank
//   factorises its rows with one layer of overlap and keeps only its own
//   rows' solution. The count must stay within 2 of one rank's (15 in 2D,
//   14 in 3D; the ILU of the whole matrix is the reference the partition
//   approximates), and below the count with deal.II's additive
//   combination, which adds the overlap's corrections twice.
// - Two ILU sweeps as a stationary iteration (`Velocity ILU sweeps = 2`)
//   must reduce the residual: 20 sweeps by at least 10^-3. With the
//   additive combination 20 sweeps on two ranks leave a residual 1.9 (2D)
//   and 6.9 (3D) times the right-hand side's: they diverge, as they did in
//   the 2D clouds.
#include <deal.II/base/mpi.h>
#include <deal.II/base/quadrature_lib.h>
#include <deal.II/distributed/tria.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_q.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/grid/grid_generator.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/solver_control.h>
#include <deal.II/lac/solver_gmres.h>
#include <deal.II/lac/trilinos_precondition.h>
#include <deal.II/lac/trilinos_sparse_matrix.h>
#include <deal.II/lac/trilinos_sparsity_pattern.h>
#include <deal.II/lac/trilinos_vector.h>
#include <deal.II/numerics/vector_tools.h>

#include <immersed_grains/linear_algebra/restricted_schwarz_ilu.h>

#include <cmath>
#include <cstdio>

using namespace dealii;
using namespace ImmersedGrains;

namespace
{
  using MPIVector = TrilinosWrappers::MPI::Vector;

  unsigned int
  gmres_iterations(const TrilinosWrappers::SparseMatrix     &A,
                   const MPIVector                          &b,
                   const TrilinosWrappers::PreconditionBase &preconditioner)
  {
    SolverControl          control(500, 1e-8 * b.l2_norm(), false, false);
    SolverGMRES<MPIVector> gmres(control,
                                 SolverGMRES<MPIVector>::AdditionalData(50));
    MPIVector              x(b);
    x = 0;
    gmres.solve(A, x, b, preconditioner);
    return control.last_step();
  }

  // ||b - A x|| after `sweeps` steps of x += P (b - A x), over ||b||.
  double
  stationary_residual(const TrilinosWrappers::SparseMatrix     &A,
                      const MPIVector                          &b,
                      const TrilinosWrappers::PreconditionBase &P,
                      const unsigned int                        sweeps)
  {
    MPIVector x(b), r(b), correction(b);
    x = 0;
    for (unsigned int k = 0; k < sweeps; ++k)
    {
      A.vmult(r, x);
      r.sadd(-1.0, 1.0, b);
      P.vmult(correction, r);
      x += correction;
    }
    A.vmult(r, x);
    r.sadd(-1.0, 1.0, b);
    return r.l2_norm() / b.l2_norm();
  }
} // namespace


template <int dim>
void
check(const unsigned int one_rank_iterations)
{
  const MPI_Comm                            comm = MPI_COMM_WORLD;
  parallel::distributed::Triangulation<dim> tria(comm);
  GridGenerator::hyper_cube(tria, 0, 1);
  tria.refine_global(dim == 2 ? 5 : 3);

  const FE_Q<dim> fe(2);
  DoFHandler<dim> dof_handler(tria);
  dof_handler.distribute_dofs(fe);
  const IndexSet owned = dof_handler.locally_owned_dofs();
  IndexSet       relevant;
  DoFTools::extract_locally_relevant_dofs(dof_handler, relevant);

  AffineConstraints<double> constraints;
  constraints.reinit(relevant);
  VectorTools::interpolate_boundary_values(dof_handler,
                                           0,
                                           Functions::ZeroFunction<dim>(),
                                           constraints);
  constraints.close();

  TrilinosWrappers::SparsityPattern pattern(owned, owned, relevant, comm);
  DoFTools::make_sparsity_pattern(dof_handler, pattern, constraints, false);
  pattern.compress();
  TrilinosWrappers::SparseMatrix A;
  A.reinit(pattern);
  MPIVector b(owned, comm);

  // Q2 node spacing h/2; viscous number nu / (c (h/2)^2) = 1 outside the
  // ball.
  const double                         c  = 1.0;
  const double                         h  = 1.0 / (dim == 2 ? 32 : 8);
  const double                         nu = c * 0.25 * h * h;
  const QGauss<dim>                    quadrature(3);
  FEValues<dim>                        fe_values(fe,
                          quadrature,
                          update_values | update_gradients |
                            update_quadrature_points | update_JxW_values);
  const unsigned int                   n = fe.n_dofs_per_cell();
  FullMatrix<double>                   cell_matrix(n, n);
  dealii::Vector<double>               cell_rhs(n);
  std::vector<types::global_dof_index> indices(n);
  Point<dim>                           centre;
  for (unsigned int d = 0; d < dim; ++d)
    centre[d] = 0.4;
  for (const auto &cell : dof_handler.active_cell_iterators())
    if (cell->is_locally_owned())
    {
      fe_values.reinit(cell);
      cell_matrix = 0;
      cell_rhs    = 0;
      for (unsigned int q = 0; q < quadrature.size(); ++q)
      {
        const Point<dim> &x  = fe_values.quadrature_point(q);
        const double      cq = x.distance(centre) < 0.25 ? 100 * c : c;
        const double      f  = std::sin(7 * x[0]) + x[dim - 1];
        for (unsigned int i = 0; i < n; ++i)
        {
          for (unsigned int j = 0; j < n; ++j)
            cell_matrix(i, j) +=
              (cq * fe_values.shape_value(i, q) * fe_values.shape_value(j, q) +
               nu * fe_values.shape_grad(i, q) * fe_values.shape_grad(j, q)) *
              fe_values.JxW(q);
          cell_rhs(i) += f * fe_values.shape_value(i, q) * fe_values.JxW(q);
        }
      }
      cell->get_dof_indices(indices);
      constraints.distribute_local_to_global(
        cell_matrix, cell_rhs, indices, A, b);
    }
  A.compress(VectorOperation::add);
  b.compress(VectorOperation::add);

  RestrictedSchwarzILU restricted;
  restricted.initialize(A, 1);
  TrilinosWrappers::PreconditionILU additive;
  additive.initialize(
    A, TrilinosWrappers::PreconditionILU::AdditionalData(0, 0., 1., 1));

  const unsigned int ranks = Utilities::MPI::n_mpi_processes(comm);
  const bool         root  = Utilities::MPI::this_mpi_process(comm) == 0;
  if (ranks == 1)
  {
    MPIVector x(owned, comm), y(owned, comm);
    restricted.vmult(x, b);
    additive.vmult(y, b);
    unsigned int different = 0;
    for (const auto i : owned)
      different += x(i) != y(i);
    if (root)
      std::printf("%dD, %u DoFs: one application equals deal.II's ILU: %s\n",
                  dim,
                  static_cast<unsigned int>(dof_handler.n_dofs()),
                  different == 0 ? "yes" : "no");
  }

  const unsigned int its_restricted = gmres_iterations(A, b, restricted);
  const unsigned int its_additive   = gmres_iterations(A, b, additive);
  const double       residual       = stationary_residual(A, b, restricted, 20);
  if (root)
  {
    std::printf("%dD, %u rank(s): GMRES within 2 of one rank's %u "
                "iterations: %s; fewer than with the additive combination: "
                "%s\n",
                dim,
                ranks,
                one_rank_iterations,
                its_restricted <= one_rank_iterations + 2 &&
                    its_restricted + 2 >= one_rank_iterations ?
                  "yes" :
                  "no",
                ranks == 1 ? "(one rank: the same)" :
                             (its_restricted < its_additive ? "yes" : "no"));
    std::printf("%dD, %u rank(s): 20 stationary sweeps reduce the residual "
                "below 1e-3: %s\n",
                dim,
                ranks,
                residual < 1e-3 ? "yes" : "no");
  }
}


int
main(int argc, char **argv)
{
  Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  check<2>(15);
  check<3>(14);
}
