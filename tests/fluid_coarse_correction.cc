// The two-level preconditioner (`Fluid/Linear solver/Coarse correction`) on
// the case the block preconditioner alone handles worst: steady Stokes in a
// walled column 1 x 8 with a ball of radius 0.3 at three quarters of its
// height (fluid fraction 0.35, drag beta h^2/mu = 0, 1e4, 1e8 inside, none
// outside), driven by a swirling body force, at a tolerance of 1e-8. The
// block preconditioner alone takes 25-40 FGMRES iterations at levels 3-5
// (doc/adaptivity.md); with the coarse correction the solve must converge
// within 24 (measured 13-22 on one rank and on two), and give the same
// solution as the solve without it: the largest velocity component within
// 1e-6 relative and the pressure difference across the ball within 1e-4
// (at this tolerance the two solves differ by up to 3e-8 and 1.5e-5). The
// test prints whether each held, not the counts, which vary a little
// between Trilinos versions.
//
// Second, a flow that has to pass through a drag region, where the coarse
// space's drag part carries it: the same column with periodic sides, fed
// at its foot (u = (0, 1)) and open at its head, with a bed across it
// (2 < y < 7, fluid fraction 0.4, beta h^2/mu = 10 and 30 at level 4,
// where mass and drag are more than half of A's diagonal). The solve must
// converge within 24 iterations (measured 10; 13 without the correction)
// with the pressure drop across the bed within 1e-4 of the solve without
// it. (A coarse space cut at the edge of the packed 2D bed takes four
// times the iterations; coupled_packed_bed_2d's check on fluid_iterations
// guards that.) Both references are solves of this code: the question is
// whether the coarse correction changes the solution beyond the solver's
// tolerance, which a second solve of the same system answers directly.
#include <deal.II/base/mpi.h>
#include <deal.II/base/parameter_handler.h>
#include <deal.II/distributed/tria.h>

#include <immersed_grains/fluid/fluid_solver.h>
#include <immersed_grains/simulation.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

using namespace dealii;
using namespace ImmersedGrains;

// A field that takes one value inside the drag region (the ball, or the
// bed across the column) and another outside.
class Region : public Function<2>
{
public:
  Region(const bool bed, const double inside, const double outside)
      : bed(bed)
      , inside(inside)
      , outside(outside)
  {
  }
  double
  value(const Point<2> &x, unsigned int) const override
  {
    const bool in =
      bed ? std::abs(x[1] - 4.5) < 2.5 : x.distance(Point<2>(0.5, 6)) < 0.3;
    return in ? inside : outside;
  }

private:
  bool   bed;
  double inside, outside;
};

class Swirl : public Function<2>
{
public:
  Swirl()
      : Function<2>(2)
  {
  }
  double
  value(const Point<2> &x, unsigned int i) const override
  {
    const double s = std::sin(M_PI * x[0]) * std::sin(M_PI * x[1]);
    return i == 0 ? s * (x[1] - 0.5) : -s * (x[0] - 0.5) + 1.0;
  }
};

struct Solution
{
  bool   converged;
  double max_velocity;
  double pressure_drop; // between points below and above the ball
};

// The column at @p level with drag beta h^2/mu = @p beta_scaled: the ball
// with the swirling force in a walled column, or (@p bed) the bed across a
// column fed at its foot.
Solution
solve_column(const bool         coarse_correction,
             const unsigned int level,
             const double       beta_scaled,
             const unsigned int max_iterations,
             const bool         bed = false)
{
  ParameterHandler prm;
  Simulation<2>::declare_parameters(prm);
  prm.parse_input_from_string(
    std::string("subsection Mesh\n set Upper corner = 1, 8\n"
                " set Subdivisions = 1, 8\n") +
    (bed ? " set Boundary conditions = periodic, periodic, velocity, open\n" :
           "") +
    "end\n"
    "subsection Fluid\n set Viscosity = 1\n"
    " set Advection = false\n set Time derivative = false\n" +
    (bed ? " subsection Boundary velocity\n"
           "  set Function expression = 0; 1\n end\n" :
           "") +
    " subsection Linear solver\n  set Tolerance = 1e-8\n"
    "  set Max iterations = " +
    std::to_string(max_iterations) + "\n  set Coarse correction = " +
    (coarse_correction ? "true" : "false") + "\n end\nend\n");
  Geometry<2> geometry;
  geometry.parse_parameters(prm, "coarse_correction");
  geometry.initial_refinement = level;
  FluidParameters<2> parameters;
  parameters.parse_parameters(prm, "coarse_correction", geometry);

  const double       h    = 1.0 / (1 << level);
  const double       beta = beta_scaled * parameters.viscosity / (h * h);
  ConditionalOStream pcout(std::cout, false);
  TimerOutput        timer(pcout, TimerOutput::never, TimerOutput::wall_times);
  parallel::distributed::Triangulation<2> tria(MPI_COMM_WORLD);
  geometry.create_mesh(tria);
  FluidSolver<2> fluid(parameters, geometry, tria, timer, pcout);
  fluid.set_mixture_fields(std::make_shared<PrescribedMixtureFields<2>>(
    std::make_shared<Region>(bed, bed ? 0.4 : 0.35, 1.0),
    std::make_shared<Region>(bed, beta, 0.0),
    std::make_shared<Functions::ZeroFunction<2>>(2)));
  if (!bed)
    fluid.set_forcing(std::make_shared<Swirl>());
  fluid.setup_dofs();
  fluid.set_initial_condition();
  try
  {
    fluid.solve_time_step(1.0, 1.0);
  }
  catch (const std::exception &)
  {
    return {false, 0, 0};
  }
  const double below = bed ? 1.5 : 5.5, above = bed ? 7.5 : 6.5;
  return {true,
          fluid.max_velocity(),
          fluid.pressure_at(Point<2>(0.5, below)) -
            fluid.pressure_at(Point<2>(0.5, above))};
}

int
main(int argc, char **argv)
{
  Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  const bool root = Utilities::MPI::this_mpi_process(MPI_COMM_WORLD) == 0;
  struct Case
  {
    bool         bed;
    unsigned int level;
    double       beta_scaled;
  };
  const Case cases[] = {{false, 3, 0},
                        {false, 3, 1e4},
                        {false, 3, 1e8},
                        {false, 4, 0},
                        {false, 4, 1e4},
                        {false, 4, 1e8},
                        {false, 5, 1e4},
                        {true, 4, 10},
                        {true, 4, 30}};
  for (const auto &[bed, level, beta_scaled] : cases)
  {
    const Solution with = solve_column(true, level, beta_scaled, 24, bed);
    const Solution reference =
      solve_column(false, level, beta_scaled, 200, bed);
    const bool same = with.converged && reference.converged &&
                      std::abs(with.max_velocity - reference.max_velocity) <=
                        1e-6 * std::abs(reference.max_velocity) &&
                      std::abs(with.pressure_drop - reference.pressure_drop) <=
                        1e-4 * std::abs(reference.pressure_drop);
    if (root)
      std::printf("%s level %u, beta h^2/mu = %g: %s, %s\n",
                  bed ? "bed," : "ball,",
                  level,
                  beta_scaled,
                  with.converged ? "converged within 24 iterations" :
                                   "NOT converged within 24 iterations",
                  same ? "same solution as without the correction" :
                         "NOT the same solution as without the correction");
  }
}
