// GhostExchange copies between a distributed Trilinos vector and its
// ghosted twin, and distributes constraints through them, as deal.II's
// assignment and AffineConstraints::distribute() do, to the last bit: the
// fluid's Q2-Q1 block vectors and the filter's scalar Q1 vectors, on a mesh
// with hanging nodes, a periodic direction and walls with a nonzero
// (inhomogeneous) velocity, filled with pseudo-random values. The copies
// are exact in both, so any difference is a wrong entry: the window is
// zero. Also with vectors that do not share the exchange's Epetra maps
// (Epetra compares the maps then), and a vector of another layout, which
// must be refused with a message. Serial and in parallel (.mpirun=2, where
// the ghosts travel).
#include <deal.II/base/mpi.h>
#include <deal.II/distributed/tria.h>
#include <deal.II/dofs/dof_renumbering.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_q.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/grid/grid_generator.h>
#include <deal.II/grid/grid_tools.h>
#include <deal.II/numerics/vector_tools.h>

#include <immersed_grains/linear_algebra/ghost_exchange.h>

#include <Epetra_MultiVector.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <type_traits>

using namespace dealii;
using namespace ImmersedGrains;

namespace
{
  // Entries that differ, over this rank's storage (ghosts included).
  unsigned int
  differences(const TrilinosWrappers::MPI::Vector &a,
              const TrilinosWrappers::MPI::Vector &b)
  {
    const Epetra_MultiVector &x = a.trilinos_vector(), &y = b.trilinos_vector();
    if (x.MyLength() != y.MyLength())
      return 1;
    unsigned int n = 0;
    for (int i = 0; i < x.MyLength(); ++i)
      n += x[0][i] != y[0][i];
    return n;
  }

  unsigned int
  differences(const TrilinosWrappers::MPI::BlockVector &a,
              const TrilinosWrappers::MPI::BlockVector &b)
  {
    unsigned int n = 0;
    for (unsigned int c = 0; c < a.n_blocks(); ++c)
      n += differences(a.block(c), b.block(c));
    return n;
  }

  template <typename VectorType>
  void
  fill(VectorType &v, const double seed)
  {
    for (const auto i : v.locally_owned_elements())
      v(i) = std::sin(seed + 0.731 * i) + 0.1 * std::cos(3.3 * i);
    v.compress(VectorOperation::insert);
  }

  template <int dim, typename VectorType>
  void
  compare(const char                      *name,
          const AffineConstraints<double> &constraints,
          const VectorType                &owned_template,
          const VectorType                &ghosted_template,
          VectorType                       fresh_owned,
          VectorType                       fresh_ghosted,
          const VectorType                &other_layout)
  {
    const MPI_Comm comm = MPI_COMM_WORLD;
    GhostExchange  exchange;
    exchange.reinit(owned_template, ghosted_template);

    VectorType owned = owned_template;
    fill(owned, 1.0);

    // Owned to ghosted, and back.
    VectorType ghosted = ghosted_template, reference = ghosted_template;
    exchange.to_ghosted(owned, ghosted);
    reference          = owned;
    unsigned int wrong = differences(ghosted, reference);
    VectorType   back  = owned_template;
    exchange.to_owned(ghosted, back);
    wrong += differences(back, owned);

    // The constraints.
    VectorType distributed = owned, reference_distributed = owned;
    VectorType distributed_ghosted = ghosted_template;
    exchange.distribute(constraints, distributed, distributed_ghosted);
    constraints.distribute(reference_distributed);
    VectorType reference_ghosted = ghosted_template;
    reference_ghosted            = reference_distributed;
    const unsigned int wrong_distribute =
      differences(distributed, reference_distributed) +
      differences(distributed_ghosted, reference_ghosted);

    // Vectors made anew, with Epetra maps of their own.
    fresh_owned = owned;
    exchange.to_ghosted(fresh_owned, fresh_ghosted);
    const unsigned int wrong_fresh = differences(fresh_ghosted, reference);

    // A vector of another layout (taking the owned values, which needs no
    // message, so that every rank refuses on its own).
    bool refused = false;
    try
    {
      exchange.to_owned(other_layout, back);
    }
    catch (const std::exception &e)
    {
      refused =
        std::string(e.what()).find("another layout") != std::string::npos;
    }
    refused = Utilities::MPI::min(refused ? 1u : 0u, comm) == 1;

    wrong            = Utilities::MPI::sum(wrong, comm);
    const auto wd    = Utilities::MPI::sum(wrong_distribute, comm);
    const auto wf    = Utilities::MPI::sum(wrong_fresh, comm);
    const auto lines = Utilities::MPI::sum(
      static_cast<unsigned int>(constraints.n_constraints()), comm);
    if (Utilities::MPI::this_mpi_process(comm) == 0)
      std::printf("%dD %s: %u entries; copies as deal.II's: %s; distribute "
                  "(%s constraint lines over the ranks) as "
                  "AffineConstraints::distribute, ghosts included: %s; "
                  "vectors with maps of their own: %s; another layout "
                  "refused: %s\n",
                  dim,
                  name,
                  static_cast<unsigned int>(owned_template.size()),
                  wrong == 0 ? "yes" : "NO",
                  lines > 0 ? "some" : "NO",
                  wd == 0 ? "yes" : "NO",
                  wf == 0 ? "yes" : "NO",
                  refused ? "yes" : "NO");
  }
} // namespace


template <int dim>
void
check()
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
  for (const auto &cell : tria.active_cell_iterators())
    if (cell->is_locally_owned() && cell->center()[1] < 0.4 &&
        cell->center()[0] > 0.3)
      cell->set_refine_flag();
  tria.execute_coarsening_and_refinement();

  const FE_Q<dim> scalar_fe(1);
  DoFHandler<dim> scalar_dofs(tria);
  scalar_dofs.distribute_dofs(scalar_fe);
  TrilinosWrappers::MPI::Vector velocity_layout;

  // The fluid's layout: Q2^dim-Q1, velocity and pressure blocks.
  {
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
    const std::vector<IndexSet> relevant_blocks = {
      relevant.get_view(0, n_u), relevant.get_view(n_u, n_u + n_p)};

    AffineConstraints<double> constraints;
    constraints.reinit(relevant);
    DoFTools::make_hanging_node_constraints(dof_handler, constraints);
    DoFTools::make_periodicity_constraints(dof_handler, 0, 1, 0, constraints);
    const FEValuesExtractors::Vector velocities(0);
    VectorTools::interpolate_boundary_values(
      dof_handler,
      2,
      Functions::ConstantFunction<dim>(0.25, dim + 1),
      constraints,
      fe.component_mask(velocities));
    constraints.close();

    TrilinosWrappers::MPI::BlockVector owned_template(owned_blocks, comm);
    TrilinosWrappers::MPI::BlockVector ghosted_template(owned_blocks,
                                                        relevant_blocks,
                                                        comm);
    // Two blocks of the scalar layout below: other lengths on every rank.
    const IndexSet scalar_owned = scalar_dofs.locally_owned_dofs();
    TrilinosWrappers::MPI::BlockVector other(
      std::vector<IndexSet>{scalar_owned, scalar_owned}, comm);
    compare<dim>("Q2-Q1 blocks",
                 constraints,
                 owned_template,
                 ghosted_template,
                 TrilinosWrappers::MPI::BlockVector(owned_blocks, comm),
                 TrilinosWrappers::MPI::BlockVector(owned_blocks,
                                                    relevant_blocks,
                                                    comm),
                 other);
    velocity_layout.reinit(owned_blocks[0], comm);
  }

  // The filter's layout: scalar Q1.
  {
    const IndexSet owned = scalar_dofs.locally_owned_dofs();
    IndexSet       relevant;
    DoFTools::extract_locally_relevant_dofs(scalar_dofs, relevant);
    AffineConstraints<double> constraints;
    constraints.reinit(relevant);
    DoFTools::make_hanging_node_constraints(scalar_dofs, constraints);
    DoFTools::make_periodicity_constraints(scalar_dofs, 0, 1, 0, constraints);
    constraints.close();
    TrilinosWrappers::MPI::Vector owned_template(owned, comm);
    TrilinosWrappers::MPI::Vector ghosted_template(owned, relevant, comm);
    compare<dim>("Q1",
                 constraints,
                 owned_template,
                 ghosted_template,
                 TrilinosWrappers::MPI::Vector(owned, comm),
                 TrilinosWrappers::MPI::Vector(owned, relevant, comm),
                 velocity_layout);
  }
}


int
main(int argc, char **argv)
{
  Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  check<2>();
  check<3>();
}
