// Robustness of the fluid solver's block preconditioner: outer FGMRES
// iterations for one time step of the averaged Stokes-Brinkman system over
// mesh levels, time steps (including steady), drag coefficients
// (beta h^2/mu) and a fluid fraction that jumps between 0.35 and 1.
//
//   fluid_preconditioner DIM LEVEL_MIN LEVEL_MAX [stokes|advection] [schur]
//                        [AMG cycles] ["Name = value; Name = value"]
//
// prints one markdown row per (level, dt, beta) with iterations, solve time
// per DoF and peak memory. The last argument sets further entries of
// `subsection Fluid/Linear solver`. FLUID_BENCH_DT and FLUID_BENCH_BETA
// (comma lists, e.g. "1,steady" and "1e8") restrict the cells run;
// FLUID_BENCH_DRAG_AVERAGING (jump|quadrature|cell) sets `Fluid/Drag
// coefficient averaging`; FLUID_BENCH_BETA_FIXED=1 reads the drags as
// beta L^2/mu with L = 1 the box (the same beta on every level, where the
// default beta h^2/mu grows beta fourfold per level); FLUID_BENCH_ALIGNED=1
// replaces the ball by the box |x - 0.5|_inf < 0.25, whose faces are mesh
// faces (no cell is cut by the jump: the diagnosis of doc/benchmarks.md,
// the drag-jump cells).
// FLUID_BENCH_GEOMETRY sets the domain the preconditioner's constants were
// not fitted on (they were fitted on the unit box, `unit`):
//   column    a tall box 1 x 8 (x 1), the ball at 3/4 of its height;
//   periodic_column, slip_column
//             the same column with periodic or slip faces sideways (walls
//             only at its ends);
//   bed_column
//             the walled column with the low fluid fraction in a layer
//             across it, |y - 6| < 0.5 (a packed bed that the flow must
//             cross);
//   slab      a thin box 1 x 1/8 in 2D, 1 x 1 x 1/8 in 3D, with the ball
//             replaced by a cylinder of radius 0.3 through its thickness;
//   adaptive  the unit box at LEVEL_MIN, refined in a band around the
//             ball's surface up to LEVEL_MAX (one row per mesh, its finest
//             level in the level column).
// benchmarks/run_fluid_benchmarks.sh makes the tables of doc/benchmarks.md.
#include <deal.II/base/mpi.h>
#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/utilities.h>
#include <deal.II/distributed/tria.h>

#include <immersed_grains/fluid/fluid_solver.h>
#include <immersed_grains/simulation.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <limits>
#include <string>
#include <vector>

using namespace dealii;
using namespace ImmersedGrains;

// phi = 0.35 inside a ball of radius 0.3 around the centre of the unit box,
// 1 outside, with a jump (no smoothing) that cuts cells: the hard case for
// the preconditioner. beta follows phi (grains only where phi < 1).
template <int dim>
class JumpField : public Function<dim>
{
public:
  JumpField(double inside, double outside)
      : inside(inside)
      , outside(outside)
  {
  }
  double
  value(const Point<dim> &x, unsigned int) const override
  {
    return is_inside(x) ? inside : outside;
  }
  Tensor<1, dim>
  gradient(const Point<dim> &, unsigned int) const override
  {
    return Tensor<1, dim>();
  }

  // The region of low fluid fraction: a ball of radius 0.3 around (0.5,
  // 0.5, 0.5) in the unit box, (0.5, 6, 0.5) in the column; in the slab a
  // cylinder through the thin direction (the last one).
  static bool
  is_inside(const Point<dim> &x)
  {
    const std::string geometry = bench_geometry();
    if (geometry == "bed_column")
      return std::abs(x[1] - 6) < 0.5;
    Point<dim> c;
    for (unsigned int d = 0; d < dim; ++d)
      c[d] = 0.5;
    if (geometry.find("column") != std::string::npos)
      c[1] = 6;
    if (std::getenv("FLUID_BENCH_ALIGNED") != nullptr)
    {
      for (unsigned int d = 0; d < dim; ++d)
        if (std::abs(x[d] - c[d]) > 0.25)
          return false;
      return true;
    }
    double r2 = 0;
    for (unsigned int d = 0; d < (geometry == "slab" ? dim - 1 : dim); ++d)
      r2 += (x[d] - c[d]) * (x[d] - c[d]);
    return r2 < 0.09;
  }

  static std::string
  bench_geometry()
  {
    const char *text = std::getenv("FLUID_BENCH_GEOMETRY");
    return text == nullptr ? "unit" : text;
  }

private:
  double inside, outside;
};

// Refines the cells within 1.5 of their own diameters of the ball's surface
// (the jump) until the finest ones have @p finest levels; the rest keep
// their level, with the 2:1 balance p4est enforces.
template <int dim>
void
refine_around_jump(parallel::distributed::Triangulation<dim> &tria,
                   const unsigned int                         finest)
{
  Point<dim> c;
  for (unsigned int d = 0; d < dim; ++d)
    c[d] = 0.5;
  for (unsigned int pass = 0; pass < finest; ++pass)
  {
    bool marked = false;
    for (const auto &cell : tria.active_cell_iterators())
      if (cell->is_locally_owned() &&
          cell->level() < static_cast<int>(finest) &&
          std::abs(cell->center().distance(c) - 0.3) < 1.5 * cell->diameter())
      {
        cell->set_refine_flag();
        marked = true;
      }
    if (!Utilities::MPI::logical_or(marked, tria.get_communicator()))
      break;
    tria.execute_coarsening_and_refinement();
  }
}

// A swirling body force that makes flow through and around the porous ball.
template <int dim>
class Swirl : public Function<dim>
{
public:
  Swirl()
      : Function<dim>(dim)
  {
  }
  double
  value(const Point<dim> &x, unsigned int i) const override
  {
    const double s = std::sin(M_PI * x[0]) * std::sin(M_PI * x[1]);
    if (i == 0)
      return s * (x[1] - 0.5);
    if (i == 1)
      return -s * (x[0] - 0.5) + 1.0;
    return 0.3 * s;
  }
};

// The values of a comma-separated environment variable, or @p all.
std::vector<double>
selected(const char *variable, const std::vector<double> &all)
{
  const char *text = std::getenv(variable);
  if (text == nullptr)
    return all;
  std::vector<double> values;
  for (const std::string &entry :
       Utilities::split_string_list(std::string(text), ','))
    values.push_back(entry == "steady" ? 0.0 : std::stod(entry));
  return values;
}

double
peak_memory_mib()
{
  Utilities::System::MemoryStats stats;
  Utilities::System::get_memory_stats(stats);
  return stats.VmHWM / 1024.0;
}

// The Mesh subsection of FLUID_BENCH_GEOMETRY, with cubic cells.
template <int dim>
std::string
mesh_entries()
{
  const std::string geometry = JumpField<dim>::bench_geometry();
  std::string       upper = "1, 1", subdivisions = "1, 1";
  std::string       boundaries;
  if (geometry == "column" || geometry == "periodic_column" ||
      geometry == "slip_column" || geometry == "bed_column")
  {
    upper                  = dim == 2 ? "1, 8" : "1, 8, 1";
    subdivisions           = dim == 2 ? "1, 8" : "1, 8, 1";
    const std::string side = geometry == "periodic_column" ? "periodic" :
                             geometry == "slip_column"     ? "slip" :
                                                             "wall";
    boundaries = "\n set Boundary conditions = " + side + ", " + side +
                 ", wall, wall" +
                 (dim == 3 ? ", " + side + ", " + side : std::string());
  }
  else if (geometry == "slab")
  {
    upper        = dim == 2 ? "1, 0.125" : "1, 1, 0.125";
    subdivisions = dim == 2 ? "8, 1" : "8, 8, 1";
  }
  else
  {
    AssertThrow(geometry == "unit" || geometry == "adaptive",
                ExcMessage("FLUID_BENCH_GEOMETRY: unit, column, "
                           "periodic_column, slip_column, slab or "
                           "adaptive, not " +
                           geometry));
    upper        = dim == 2 ? "1, 1" : "1, 1, 1";
    subdivisions = dim == 2 ? "1, 1" : "1, 1, 1";
  }
  return "subsection Mesh\n set Lower corner = " +
         std::string(dim == 2 ? "0, 0" : "0, 0, 0") +
         "\n set Upper corner = " + upper +
         "\n set Subdivisions = " + subdivisions + boundaries + "\nend\n";
}

template <int dim>
void
run(const unsigned int level_min,
    const unsigned int level_max,
    const bool         advection,
    const std::string &schur,
    const unsigned int cycles,
    const std::string &extra)
{
  std::string extra_entries;
  for (const std::string &entry : Utilities::split_string_list(extra, ';'))
    extra_entries += "  set " + entry + "\n";
  const bool  root      = Utilities::MPI::this_mpi_process(MPI_COMM_WORLD) == 0;
  const char *averaging = std::getenv("FLUID_BENCH_DRAG_AVERAGING");
  const std::string drag_averaging = averaging != nullptr ? averaging : "jump";
  if (root)
    std::printf(
      "| dim | level | DoFs | dt | beta h^2/mu | iterations | step s | "
      "s per MDoF | preconditioner s | FGMRES s | ms per iteration | peak MiB "
      "|\n|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (unsigned int level = level_min; level <= level_max; ++level)
    for (const double dt : selected("FLUID_BENCH_DT", {1e-8, 1e-4, 1.0, 0.0}))
      for (const double beta_scaled :
           selected("FLUID_BENCH_BETA", {0.0, 1.0, 1e4, 1e8}))
      {
        ParameterHandler prm;
        Simulation<dim>::declare_parameters(prm);
        prm.parse_input_from_string(
          mesh_entries<dim>() +
          std::string(
            "subsection Fluid\n set Density = 1000\n set Viscosity = 1\n") +
          " set Advection = " + (advection ? "true" : "false") +
          "\n set Drag coefficient averaging = " + drag_averaging +
          "\n set Time derivative = " + (dt > 0 ? "true" : "false") +
          "\n set Time scheme = BDF1\n subsection Linear solver\n"
          "  set Tolerance = 1e-8\n  set Max iterations = 1000\n"
          "  set Schur complement = " +
          schur +
          (cycles > 0 ?
             "\n  set Velocity AMG cycles = " + std::to_string(cycles) :
             std::string()) +
          "\n" + extra_entries + " end\nend\n");
        Geometry<dim> geometry;
        geometry.parse_parameters(prm, "benchmark");
        const bool adaptive = JumpField<dim>::bench_geometry() == "adaptive";
        geometry.initial_refinement = adaptive ? level_min : level;
        FluidParameters<dim> parameters;
        parameters.parse_parameters(prm, "benchmark", geometry);

        // The finest cell: the shortest side over its subdivisions.
        double h = std::numeric_limits<double>::max();
        for (unsigned int d = 0; d < dim; ++d)
          h = std::min(h,
                       (geometry.upper_corner[d] - geometry.lower_corner[d]) /
                         geometry.subdivisions[d]);
        h /= (1 << level);
        // FLUID_BENCH_BETA_FIXED=1: the listed values are beta L^2/mu with
        // L = 1 the box, the same physical drag on every level, instead of
        // beta h^2/mu, which grows beta fourfold per level.
        const double beta =
          beta_scaled * parameters.viscosity /
          (std::getenv("FLUID_BENCH_BETA_FIXED") != nullptr ? 1.0 : h * h);
        auto fields = std::make_shared<PrescribedMixtureFields<dim>>(
          std::make_shared<JumpField<dim>>(0.35, 1.0),
          std::make_shared<JumpField<dim>>(beta, 0.0),
          std::make_shared<Functions::ZeroFunction<dim>>(dim));

        ConditionalOStream pcout(std::cout, false);
        TimerOutput timer(pcout, TimerOutput::never, TimerOutput::wall_times);
        parallel::distributed::Triangulation<dim> tria(MPI_COMM_WORLD);
        geometry.create_mesh(tria);
        if (adaptive)
          refine_around_jump(tria, level);
        FluidSolver<dim> fluid(parameters, geometry, tria, timer, pcout);
        fluid.set_mixture_fields(fields);
        fluid.set_forcing(std::make_shared<Swirl<dim>>());
        fluid.setup_dofs();
        fluid.set_initial_condition();
        const auto   start      = std::chrono::steady_clock::now();
        unsigned int iterations = 0;
        bool         converged  = true;
        try
        {
          iterations =
            fluid.solve_time_step(dt > 0 ? dt : 1.0, dt > 0 ? dt : 1.0)
              .linear_iterations;
        }
        catch (const std::exception &e)
        {
          if (std::getenv("FLUID_BENCH_VERBOSE") != nullptr)
            std::cerr << e.what() << std::endl;
          converged = false;
        }
        const double seconds = std::chrono::duration<double>(
                                 std::chrono::steady_clock::now() - start)
                                 .count();
        // The step's phases: assembly, the preconditioner's set-up, FGMRES.
        const auto phases =
          timer.get_summary_data(TimerOutput::OutputData::total_wall_time);
        const auto phase = [&phases](const std::string &name)
        {
          const auto entry = phases.find(name);
          return entry == phases.end() ? 0.0 : entry->second;
        };
        const double setup_seconds = phase("fluid: preconditioner");
        const double solve_seconds = phase("fluid: solve");
        const double memory =
          Utilities::MPI::max(peak_memory_mib(), MPI_COMM_WORLD);
        if (root)
        {
          char dt_text[32];
          if (dt > 0)
            std::snprintf(dt_text, sizeof(dt_text), "%g", dt);
          else
            std::snprintf(dt_text, sizeof(dt_text), "steady");
          std::printf(
            "| %d | %u | %llu | %s | %g | %s | %.2f | %.2f | %.3f | %.3f | "
            "%.2f | %.0f |\n",
            dim,
            level,
            static_cast<unsigned long long>(fluid.n_dofs()),
            dt_text,
            beta_scaled,
            converged ?
              std::to_string(iterations).c_str() :
              ("> " + std::to_string(parameters.max_linear_iterations)).c_str(),
            seconds,
            seconds / (fluid.n_dofs() * 1e-6),
            setup_seconds,
            solve_seconds,
            1e3 * solve_seconds / std::max(1u, iterations),
            memory);
          std::fflush(stdout);
        }
      }
}

int
main(int argc, char **argv)
{
  Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  if (argc < 4)
  {
    std::cerr << "usage: fluid_preconditioner DIM LEVEL_MIN LEVEL_MAX "
                 "[stokes|advection] [Cahouet-Chabard|pressure mass|pressure "
                 "Laplacian] "
                 "[AMG cycles] [\"Name = value; ...\" (Linear solver)]\n";
    return 1;
  }
  const int          dim      = std::atoi(argv[1]);
  const unsigned int lmin     = std::atoi(argv[2]);
  const unsigned int lmax     = std::atoi(argv[3]);
  const bool        advection = argc > 4 && std::string(argv[4]) == "advection";
  const std::string schur     = argc > 5 ? argv[5] : "Cahouet-Chabard";
  const unsigned int cycles   = argc > 6 ? std::atoi(argv[6]) : 0;
  const std::string  extra    = argc > 7 ? argv[7] : "";
  if (dim == 2)
    run<2>(lmin, lmax, advection, schur, cycles, extra);
  else
    run<3>(lmin, lmax, advection, schur, cycles, extra);
}
