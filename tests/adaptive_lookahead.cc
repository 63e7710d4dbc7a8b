// Adaptivity/Band lookahead: the band covers each grain's straight path
// over the lookahead horizon, at the finest level, after one adaptation
// from a mesh several levels coarser (the passes of refine_only marking).
// Seven grains in a box (walls; in 2D also a periodic x axis, which one
// path crosses), with velocities in different directions and of
// different sizes, on a mesh of 4^dim coarse cells and Max level 3 (cells
// of 1/32), Band width 1, lookahead 4 cells: along every path, sampled
// every 1/500 of the horizon, the points at the band's allowance (half a
// cell) from it on either side along each axis lie in cells of Max level.
// The horizon is 4 finest cells over the fastest grain's speed. Without
// the lookahead (the band around the grains only, also made in passes)
// the same check finds points outside the finest cells (the check can
// fail), and the band has fewer cells. Serial and on two
// ranks (where paths leave the rank that owns their grain). The size
// estimate made before the grains move (--check, the log) counts at least
// the band's cells with the lookahead.
#include <deal.II/base/mpi.h>
#include <deal.II/distributed/tria.h>
#include <deal.II/fe/mapping_cartesian.h>
#include <deal.II/grid/filtered_iterator.h>
#include <deal.II/grid/grid_tools.h>
#include <deal.II/particles/particle_handler.h>

#include <immersed_grains/mesh/adaptivity.h>
#include <immersed_grains/mesh/geometry.h>
#include <immersed_grains/mesh/size_estimate.h>

#include <iomanip>
#include <iostream>
#include <vector>

using namespace dealii;
using namespace ImmersedGrains;

namespace
{
  template <int dim>
  void
  check(const double lookahead)
  {
    const MPI_Comm   comm = MPI_COMM_WORLD;
    Geometry<dim>    geometry;
    ParameterHandler prm;
    Geometry<dim>::declare_parameters(prm);
    prm.enter_subsection("Mesh");
    prm.set("Lower corner", dim == 2 ? "0, 0" : "0, 0, 0");
    prm.set("Upper corner", dim == 2 ? "1, 1" : "1, 1, 1");
    prm.set("Subdivisions", "4");
    prm.set("Initial refinement", "0");
    prm.set("Boundary conditions",
            dim == 2 ? "periodic, periodic, wall, wall" :
                       "wall, wall, wall, wall, wall, wall");
    prm.leave_subsection();
    geometry.parse_parameters(prm, "adaptive_lookahead");
    parallel::distributed::Triangulation<dim> tria(
      comm, Triangulation<dim>::limit_level_difference_at_vertices);
    geometry.create_mesh(tria);

    typename Adaptivity<dim>::Parameters parameters;
    parameters.enabled        = true;
    parameters.min_level      = 0;
    parameters.max_level      = 3;
    parameters.band_width     = 1;
    parameters.band_lookahead = lookahead;
    Adaptivity<dim> adaptivity(parameters, geometry, tria, 1e-6);
    const typename Adaptivity<dim>::GrainProperties properties{dim, 0};

    // Start and velocity of each grain; the first is the fastest.
    std::vector<std::pair<Point<dim>, Tensor<1, dim>>> grains;
    const auto                                         add =
      [&](const std::vector<double> &x, const std::vector<double> &v)
    {
      Point<dim>     p;
      Tensor<1, dim> w;
      for (unsigned int d = 0; d < dim; ++d)
      {
        p[d] = x[d];
        w[d] = v[d];
      }
      grains.emplace_back(p, w);
    };
    add({0.5, 0.62, 0.5}, {0, -1, 0});
    add({0.3, 0.3, 0.7}, {0.6, 0.6, -0.3});
    add({0.93, 0.45, 0.2}, {0.7, 0.1, 0.2}); // through x = 1 in 2D
    add({0.21, 0.8, 0.4}, {-0.2, 0.5, 0.1});
    add({0.7, 0.2, 0.8}, {0, 0, 0});
    add({0.55, 0.13, 0.33}, {-0.4, -0.05, 0.3});
    add({0.12, 0.51, 0.9}, {0.05, 0.02, -0.6});

    const MappingCartesian<dim>     mapping;
    Particles::ParticleHandler<dim> particles(tria, mapping, dim + 1);
    for (const auto &cell : tria.active_cell_iterators())
      if (cell->is_locally_owned())
        for (unsigned int k = 0; k < grains.size(); ++k)
          if (cell->point_inside(grains[k].first))
          {
            const Particles::Particle<dim> particle(
              grains[k].first,
              mapping.transform_real_to_unit_cell(cell, grains[k].first),
              k);
            auto       p     = particles.insert_particle(particle, cell);
            const auto props = p->get_properties();
            for (unsigned int d = 0; d < dim; ++d)
              props[d] = grains[k].second[d];
            props[dim] = 0.001;
          }
    particles.update_cached_numbers();

    // One adaptation: a full pass, then refine-only passes.
    const double h_finest = 0.25 / 8;
    unsigned int passes   = 0;
    for (bool refine_only = false;
         adaptivity.mark_cells(
           &particles, properties, nullptr, h_finest, refine_only) &&
         passes < 10;
         refine_only = true, ++passes)
    {
      particles.prepare_for_coarsening_and_refinement();
      tria.execute_coarsening_and_refinement();
      particles.unpack_after_coarsening_and_refinement();
    }
    const double horizon = adaptivity.lookahead_horizon();

    // Along each path, the points at the allowance from it on each side.
    const double  allowance = 0.5 * parameters.band_width * h_finest;
    const double  t_end     = 4 * h_finest; // the fastest grain moves at 1
    unsigned long checked = 0, outside = 0;
    const GridTools::Cache<dim> cache(tria, mapping);
    // (The search is slow where this rank's mesh does not reach.)
    const auto owned = GridTools::compute_mesh_predicate_bounding_box(
      tria, IteratorFilters::LocallyOwnedCell());
    for (const auto &[x0, v] : grains)
      for (unsigned int k = 0; k <= 500; ++k)
        for (unsigned int side = 0; side < 2 * dim + 1; ++side)
        {
          Point<dim> x = x0 + (k / 500.) * t_end * v;
          if (side < 2 * dim)
            x[side / 2] += (side % 2 ? 0.99 : -0.99) * allowance;
          if (dim == 2)
            x[0] -= std::floor(x[0]);
          bool outside_box = false;
          for (unsigned int d = 0; d < dim; ++d)
            outside_box = outside_box || x[d] <= 0 || x[d] >= 1;
          bool here = false;
          for (const auto &box : owned)
            here = here || box.point_inside(x);
          if (outside_box || !here)
            continue;
          const auto cell =
            GridTools::find_active_cell_around_point(cache, x).first;
          // (Not found where this rank's mesh does not reach.)
          if (cell.state() != IteratorState::valid || !cell->is_locally_owned())
            continue;
          ++checked;
          if (cell->level() < static_cast<int>(parameters.max_level))
            ++outside;
        }
    checked = Utilities::MPI::sum(checked, comm);
    outside = Utilities::MPI::sum(outside, comm);

    // The size estimate (--check, the log) before the grains move: it
    // counts the paths along one axis (y: the fastest grain's), both ways,
    // and must not fall below the band made (without the lookahead it
    // falls below by up to 10 %: the band made in passes grows over
    // coarser cells, which the estimate's level grids do not count).
    GrainBand band;
    band.min_level     = parameters.min_level;
    band.max_level     = parameters.max_level;
    band.band_width    = parameters.band_width;
    band.smallest_cell = 1e-6;
    band.lookahead     = lookahead;
    band.path_axis     = 1;
    std::vector<Point<dim>> starts;
    for (const auto &grain : grains)
      starts.push_back(grain.first);
    const double estimate =
      estimate_adapted_size(geometry, band, true, starts).cells;

    if (Utilities::MPI::this_mpi_process(comm) == 0)
      std::cout << dim << "D, Band lookahead " << lookahead
                << ": horizon * fastest speed / finest cell "
                << horizon * 1.0 / h_finest << ", passes " << passes
                << ", cells " << tria.n_global_active_cells() << ", points "
                << checked << ", outside the finest cells " << outside
                << ", estimated cells " << estimate << " ("
                << std::setprecision(2)
                << estimate / tria.n_global_active_cells() << " of those)"
                << std::setprecision(6) << '\n';
  }
} // namespace


int
main(int argc, char **argv)
{
  Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  check<2>(4);
  check<2>(0);
  check<3>(4);
  check<3>(0);
}
