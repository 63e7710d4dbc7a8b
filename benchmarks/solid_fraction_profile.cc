// The projected solid fraction along a line through a random 2D packing,
// on meshes from 8 to 128 cells across, without and with the Helmholtz
// smoothing: the data of doc/figures/solid_fraction_smoothing.png
// (doc/theory.md section 3). Prints CSV: x, then phi_s for each (length,
// level).
//
//   build/benchmarks/solid_fraction_profile > profile.csv
#include <deal.II/base/mpi.h>
#include <deal.II/base/parameter_handler.h>
#include <deal.II/distributed/tria.h>
#include <deal.II/fe/mapping_q1.h>
#include <deal.II/grid/grid_tools.h>

#include <immersed_grains/coupling/solid_fraction.h>
#include <immersed_grains/simulation.h>

#include <cstdio>
#include <map>
#include <random>

using namespace dealii;
using namespace ImmersedGrains;

int
main(int argc, char **argv)
{
  Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  constexpr int                    dim = 2;

  // 600 discs of radius 0.01 at random (overlaps allowed: only the field
  // matters here), phi_s = 0.19 on average.
  std::mt19937                           rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double                           r      = 0.01;
  const double                           volume = M_PI * r * r;
  std::vector<Point<dim>>                grains(600);
  for (auto &p : grains)
    p = Point<dim>(u(rng), u(rng));

  const std::vector<double>        lengths   = {0.0, 0.04};
  const std::vector<unsigned int>  levels    = {3, 4, 5, 6, 7};
  const unsigned int               n_samples = 801;
  std::vector<std::vector<double>> columns;
  std::vector<std::string>         names;

  for (const double l : lengths)
    for (const unsigned int level : levels)
    {
      ParameterHandler prm;
      Simulation<dim>::declare_parameters(prm);
      Geometry<dim> geometry;
      geometry.parse_parameters(prm, "solid_fraction_profile");
      geometry.initial_refinement = level;
      parallel::distributed::Triangulation<dim> tria(MPI_COMM_WORLD);
      geometry.create_mesh(tria);

      typename SolidFraction<dim>::Parameters parameters;
      parameters.lumped             = false;
      parameters.smoothing_length   = l;
      parameters.min_fluid_fraction = 0;
      SolidFraction<dim> projection(parameters, geometry, tria);
      projection.setup();

      MappingQ1<dim> mapping;
      std::map<typename Triangulation<dim>::active_cell_iterator,
               std::vector<GrainSample<dim>>>
        by_cell;
      for (const auto &p : grains)
      {
        const auto found =
          GridTools::find_active_cell_around_point(mapping, tria, p);
        by_cell[found.first].push_back(
          {found.second, volume, 2 * r, Tensor<1, dim>()});
      }
      projection.project(
        [&](const auto &cell, std::vector<GrainSample<dim>> &samples)
        {
          const auto it = by_cell.find(cell);
          if (it != by_cell.end())
            samples = it->second;
        });

      std::vector<double> column;
      MixtureValues<dim>  values;
      for (unsigned int k = 0; k < n_samples; ++k)
      {
        const Point<dim> x(k / double(n_samples - 1), 0.5);
        const auto       found =
          GridTools::find_active_cell_around_point(mapping, tria, x);
        projection.evaluate(found.first, {x}, {found.second}, 0, values);
        column.push_back(1 - values.fluid_fraction[0]);
      }
      columns.push_back(column);
      names.push_back("l=" + std::to_string(l).substr(0, 4) +
                      " cells=" + std::to_string(1 << level));
    }

  std::printf("x");
  for (const auto &name : names)
    std::printf(",%s", name.c_str());
  std::printf("\n");
  for (unsigned int k = 0; k < n_samples; ++k)
  {
    std::printf("%.5f", k / double(n_samples - 1));
    for (const auto &c : columns)
      std::printf(",%.6f", c[k]);
    std::printf("\n");
  }
}
