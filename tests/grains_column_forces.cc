// A column of 10 touching grains (r = 0.05, m = 1) on the floor, stepped
// 1000 times through Grains<dim> on a ParticleHandler (gather, free
// velocities, distributed contact solve, position update, sort), 2D and
// 3D. Statics (doc/references.md, "Resting column"): the contact under
// grain j from the top carries j m g; checked for every contact at every
// step to 1e-8 relative (four orders above the contact solve's tolerance,
// 1e-12, as in contact_resting_column), and nothing may drift (centre
// heights to 1e-11 r).

#include <deal.II/base/conditional_ostream.h>
#include <deal.II/base/mpi.h>
#include <deal.II/base/timer.h>

#include <immersed_grains/grains/grains.h>

#include <cmath>
#include <iostream>
#include <sstream>

using namespace ImmersedGrains;

template <int dim>
void
column()
{
  const double       g = 10, r = 0.05, m = 1, dt = 1e-3;
  const unsigned int n = 10;
  std::ostringstream scene;
  scene.precision(17);
  scene << "subsection Mesh\n"
        << "  set Lower corner = " << (dim == 2 ? "0, 0" : "0, 0, 0") << '\n'
        << "  set Upper corner = " << (dim == 2 ? "1, 1.5" : "1, 1, 1.5")
        << '\n'
        << "  set Subdivisions = 1\n  set Initial refinement = 2\nend\n"
        << "subsection Grains\n  set Enabled = true\n  set Radius = " << r
        << "\n  set Density = " << m / grain_volume<dim>(r) << '\n'
        << "  subsection Placement\n    set Shape = lattice\n"
        << "    set Center = " << (dim == 2 ? "0.5, 0.5" : "0.5, 0.5, 0.5")
        << "\n    set Size = " << (dim == 2 ? "0.1, 1" : "0.1, 0.1, 1")
        << "\n  end\nend\n"
        << "subsection Contacts\n  set Tolerance = 1e-12\n"
        << "  set Max iterations = 20000\nend\n"
        << "subsection Gravity\n  set Vector = "
        << (dim == 2 ? "0, -10" : "0, 0, -10") << "\nend\n";

  dealii::ParameterHandler prm;
  Geometry<dim>::declare_parameters(prm);
  GrainParameters<dim>::declare_parameters(prm);
  prm.parse_input_from_string(scene.str());
  Geometry<dim> geometry;
  geometry.parse_parameters(prm, "column");
  GrainParameters<dim> parameters;
  parameters.parse_parameters(prm, "column");

  dealii::parallel::distributed::Triangulation<dim> tria(MPI_COMM_WORLD);
  geometry.create_mesh(tria);
  dealii::ConditionalOStream silent(std::cout, false);
  dealii::TimerOutput        timer(MPI_COMM_WORLD,
                            silent,
                            dealii::TimerOutput::never,
                            dealii::TimerOutput::wall_times);
  Grains<dim>                grains(parameters, geometry, tria, false, timer);
  grains.initialize(place_grains(parameters, geometry));

  // Lattice order: grain k is the k-th from the floor, so the contact
  // below it carries the weight of grains k .. n-1.
  double              worst = 0, drift = 0;
  unsigned int        complete = 0;
  std::vector<double> last(n + 1, 0.);
  for (unsigned int step = 1; step <= 1000; ++step)
  {
    grains.advance(dt);
    unsigned int count = 0;
    for (const ContactForce &c : grains.contact_forces())
    {
      const unsigned int k = c.wall ? 0 : std::max(c.grain, c.partner);
      if (c.force == 0)
        continue;
      const double expected = (n - k) * m * g;
      worst       = std::max(worst, std::abs(c.force - expected) / expected);
      last[n - k] = c.force / (m * g);
      ++count;
    }
    complete += (dealii::Utilities::MPI::sum(count, MPI_COMM_WORLD) == n);
    for (const auto &p : grains.particle_handler())
      drift = std::max(
        drift,
        std::abs(p.get_location()[dim - 1] - (r + 2 * r * p.get_id())) / r);
  }
  worst = dealii::Utilities::MPI::max(worst, MPI_COMM_WORLD);
  drift = dealii::Utilities::MPI::max(drift, MPI_COMM_WORLD);
  dealii::Utilities::MPI::max(last, MPI_COMM_WORLD, last);
  if (dealii::Utilities::MPI::this_mpi_process(MPI_COMM_WORLD) == 0)
  {
    std::cout << dim << "D: contact force / (m g), top to bottom:";
    for (unsigned int j = 1; j <= n; ++j)
      std::cout << ' ' << std::round(last[j] * 1e6) / 1e6;
    std::cout << "\n  all 10 contacts active at every step: "
              << (complete == 1000 ? "yes" : "no")
              << "\n  forces = j m g to 1e-8 at every step: "
              << (worst < 1e-8 ? "yes" : "no")
              << "\n  drift < 1e-11 r: " << (drift < 1e-11 ? "yes" : "no")
              << std::endl;
  }
}

int
main(int argc, char **argv)
{
  dealii::Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  column<2>();
  column<3>();
}
