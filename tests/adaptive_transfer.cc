// What moves across a mesh change, through the same calls the simulation
// makes (FluidSolver and Grains: prepare_for_mesh_change, the
// triangulation's change, finish_mesh_change), in 2D and 3D, on one rank
// and on two (where p4est repartitions the refined mesh and grains move to
// other ranks):
// - the fluid velocity. Refining interpolates the parent's Q2 function
//   onto its children, so any field comes through unchanged: its L2 norm,
//   integrated exactly, stays the same (to 1e-12 relative). A
//   field in the coarse Q2 space (x(1-x)y(1-y)(z(1-z)), zero on the walls)
//   also survives coarsening back, to round-off (L2 error below 1e-14).
//   One that is not (sin(pi x) sin(pi y) (sin(pi z))), interpolated on the
//   mesh refined everywhere, loses what only the fine cells held when
//   coarsened back: its error grows about eightfold (h^3), which shows the
//   checks are not vacuous.
// - the grains (in the runs with the Q2 field, where the cells around them
//   are refined). 200 grains with distinct positions, radii and velocities
//   go through a refinement of the cells around them and the coarsening
//   back: every grain comes back with its location and every property
//   equal to the last bit, and the mesh with its cell count.
#include <deal.II/base/function.h>
#include <deal.II/base/mpi.h>
#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/timer.h>
#include <deal.II/base/utilities.h>
#include <deal.II/distributed/tria.h>
#include <deal.II/fe/mapping_q1.h>
#include <deal.II/lac/vector.h>
#include <deal.II/numerics/vector_tools.h>

#include <immersed_grains/fluid/fluid_solver.h>
#include <immersed_grains/fluid/mixture_fields.h>
#include <immersed_grains/grains/grains.h>
#include <immersed_grains/grains/placement.h>
#include <immersed_grains/simulation.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <map>
#include <string>
#include <vector>

using namespace dealii;
using namespace ImmersedGrains;

namespace
{
  // The velocity fields as muparser expressions (Fluid/Initial velocity)
  // and as a Function for the error; the pressure component is zero.
  template <int dim>
  std::string
  expression(const bool polynomial)
  {
    const std::string x = polynomial ? "x*(1-x)" : "sin(pi*x)";
    const std::string y = polynomial ? "y*(1-y)" : "sin(pi*y)";
    const std::string z = polynomial ? "z*(1-z)" : "sin(pi*z)";
    const std::string f = dim == 2 ? x + "*" + y : x + "*" + y + "*" + z;
    std::string       all;
    for (unsigned int d = 0; d < dim; ++d)
      all += (d ? "; " : "") + std::to_string(d + 1) + "*" + f;
    return all;
  }

  template <int dim>
  class ExactVelocity : public Function<dim>
  {
  public:
    explicit ExactVelocity(const bool polynomial)
        : Function<dim>(dim + 1)
        , polynomial(polynomial)
    {
    }
    double
    value(const Point<dim> &p, const unsigned int component) const override
    {
      if (component == dim)
        return 0;
      double f = 1;
      for (unsigned int d = 0; d < dim; ++d)
        f *= polynomial ? p[d] * (1 - p[d]) : std::sin(M_PI * p[d]);
      return (component + 1) * f;
    }

  private:
    const bool polynomial;
  };

  // The L2 norm of the velocity minus @p exact, with @p points Gauss
  // points per direction (3 integrate a Q2 function's square exactly).
  template <int dim>
  double
  velocity_distance(const FluidSolver<dim> &fluid,
                    const Function<dim>    &exact,
                    const unsigned int      points)
  {
    Vector<double> cellwise(
      fluid.get_dof_handler().get_triangulation().n_active_cells());
    const ComponentSelectFunction<dim> velocity(std::make_pair(0u, dim),
                                                dim + 1);
    const MappingQ1<dim>               mapping;
    VectorTools::integrate_difference(mapping,
                                      fluid.get_dof_handler(),
                                      fluid.get_solution(),
                                      exact,
                                      cellwise,
                                      QGauss<dim>(points),
                                      VectorTools::L2_norm,
                                      &velocity);
    return VectorTools::compute_global_error(
      fluid.get_dof_handler().get_triangulation(),
      cellwise,
      VectorTools::L2_norm);
  }

  // Every grain's id, location and properties, gathered on rank 0 and
  // sorted by id.
  template <int dim>
  std::map<types::particle_index, std::vector<double>>
  all_grains(const Grains<dim> &grains, MPI_Comm comm)
  {
    std::vector<double> mine;
    for (const auto &particle : grains.particle_handler())
    {
      mine.push_back(particle.get_id());
      for (unsigned int d = 0; d < dim; ++d)
        mine.push_back(particle.get_location()[d]);
      const auto properties = particle.get_properties();
      mine.push_back(properties.size());
      mine.insert(mine.end(), properties.begin(), properties.end());
    }
    std::map<types::particle_index, std::vector<double>> grains_by_id;
    for (const auto &part : Utilities::MPI::gather(comm, mine, 0))
      for (std::size_t k = 0; k < part.size();)
      {
        const auto id = static_cast<types::particle_index>(part[k]);
        const auto n  = static_cast<std::size_t>(part[k + dim + 1]);
        grains_by_id[id].assign(part.begin() + k + 1,
                                part.begin() + k + dim + 2 + n);
        k += dim + 2 + n;
      }
    return grains_by_id;
  }

  template <int dim>
  void
  test(const bool polynomial)
  {
    MPI_Comm          comm = MPI_COMM_WORLD;
    const bool        root = Utilities::MPI::this_mpi_process(comm) == 0;
    const std::string corner =
      dim == 2 ? std::string("1, 1") : std::string("1, 1, 1");
    ParameterHandler prm;
    Simulation<dim>::declare_parameters(prm);
    prm.parse_input_from_string(
      "set Dimension = " + std::to_string(dim) +
      "\nsubsection Mesh\n set Lower corner = " +
      (dim == 2 ? "0, 0" : "0, 0, 0") + "\n set Upper corner = " + corner +
      "\n set Subdivisions = " + corner +
      "\n set Initial refinement = " + (dim == 2 ? "3" : "2") +
      "\nend\nsubsection Fluid\n set Advection = false\n"
      " subsection Initial velocity\n  set Function expression = " +
      expression<dim>(polynomial) +
      "\n end\nend\nsubsection Grains\n set Enabled = true\n set Radius = "
      "0.01\n"
      " set Radius distribution = uniform\n set Minimum radius = 0.007\n"
      " set Maximum radius = 0.013\n subsection Placement\n  set Shape = ball\n"
      "  set Center = " +
      (dim == 2 ? "0.5, 0.5" : "0.5, 0.5, 0.5") +
      "\n  set Size = 0.3\n  set Count = 200\n  set Random seed = 3\n"
      " end\nend\n");
    Geometry<dim> geometry;
    geometry.parse_parameters(prm, "adaptive_transfer");
    FluidParameters<dim> fluid_parameters;
    fluid_parameters.parse_parameters(prm, "adaptive_transfer", geometry);
    GrainParameters<dim> grain_parameters;
    grain_parameters.parse_parameters(prm, "adaptive_transfer");

    ConditionalOStream pcout(std::cout, false);
    TimerOutput timer(pcout, TimerOutput::never, TimerOutput::wall_times);
    parallel::distributed::Triangulation<dim> tria(comm);
    geometry.create_mesh(tria);
    FluidSolver<dim> fluid(fluid_parameters, geometry, tria, timer, pcout);
    fluid.set_mixture_fields(std::make_shared<PrescribedMixtureFields<dim>>(
      std::make_shared<Functions::ConstantFunction<dim>>(1.0),
      std::make_shared<Functions::ZeroFunction<dim>>(),
      std::make_shared<Functions::ZeroFunction<dim>>(dim)));
    fluid.setup_dofs();
    fluid.set_initial_condition();

    Grains<dim> grains(grain_parameters, geometry, tria, true, timer);
    auto        seeds = place_grains(grain_parameters, geometry);
    for (unsigned int k = 0; k < seeds.size(); ++k)
      for (unsigned int d = 0; d < dim; ++d)
        seeds[k].velocity[d] = std::sin(1.0 + k + 3.0 * d);
    grains.initialize(seeds);

    const ExactVelocity<dim>           exact(polynomial);
    const Functions::ZeroFunction<dim> zero(dim + 1);
    const double error_before  = velocity_distance(fluid, exact, 5);
    const double norm_before   = velocity_distance(fluid, zero, 3);
    const auto   grains_before = all_grains(grains, comm);
    const types::global_cell_index cells_before = tria.n_global_active_cells();

    Point<dim> centre;
    for (unsigned int d = 0; d < dim; ++d)
      centre[d] = 0.5;
    const auto change_mesh = [&](const bool refine)
    {
      for (const auto &cell : tria.active_cell_iterators())
        if (cell->is_locally_owned())
        {
          if (refine && (!polynomial || cell->center().distance(centre) < 0.35))
            cell->set_refine_flag();
          if (!refine &&
              cell->level() > static_cast<int>(geometry.initial_refinement))
            cell->set_coarsen_flag();
        }
      tria.prepare_coarsening_and_refinement();
      fluid.prepare_for_mesh_change();
      grains.prepare_for_mesh_change();
      tria.execute_coarsening_and_refinement();
      fluid.finish_mesh_change();
      grains.finish_mesh_change();
    };

    change_mesh(true);
    const double refined_error = velocity_distance(fluid, exact, 5);
    const double refined_norm  = velocity_distance(fluid, zero, 3);
    const types::global_cell_index cells_refined = tria.n_global_active_cells();
    // The sine field anew on the fine mesh: coarsening must now lose what
    // only the fine cells hold.
    if (!polynomial)
      fluid.set_initial_condition();
    const double fine_error = velocity_distance(fluid, exact, 5);
    change_mesh(false);
    const double coarsened_error = velocity_distance(fluid, exact, 5);
    const auto   grains_after    = all_grains(grains, comm);

    if (!root)
      return;
    std::cout << dim << "D, " << (polynomial ? "Q2 field" : "sine field")
              << ": cells " << cells_before << " -> " << cells_refined << " -> "
              << tria.n_global_active_cells() << '\n';
    std::cout << "  refined: the velocity unchanged (its L2 norm to 1e-12): "
              << (std::abs(refined_norm - norm_before) < 1e-12 * norm_before ?
                    "yes" :
                    "no")
              << '\n';
    if (polynomial)
      std::cout << "  L2 error below 1e-14 before, refined and coarsened: "
                << (error_before < 1e-14 && refined_error < 1e-14 &&
                        coarsened_error < 1e-14 ?
                      "yes" :
                      "no")
                << '\n';
    else
      std::cout << "  interpolated on the fine mesh, then coarsened: L2 "
                << "error grows more than fourfold: "
                << (coarsened_error > 4 * fine_error ? "yes" : "no") << '\n';
    if (!polynomial)
      return;
    unsigned int different = 0;
    for (const auto &[id, values] : grains_before)
    {
      const auto found = grains_after.find(id);
      different += found == grains_after.end() || found->second != values;
    }
    std::cout << "  grains " << grains_before.size() << " -> "
              << grains_after.size()
              << ", each with its location and properties to the last bit: "
              << (different == 0 &&
                      grains_after.size() == grains_before.size() ?
                    "yes" :
                    "no")
              << '\n';
  }
} // namespace


int
main(int argc, char **argv)
{
  Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  for (const bool polynomial : {true, false})
  {
    test<2>(polynomial);
    test<3>(polynomial);
  }
}
