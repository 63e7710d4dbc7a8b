// The 2D cloud in its compact stage against a single-fluid run of the same
// solver. In 2D a cloud has no unbounded steady velocity (Stokes'
// paradox), so there is no analytical value; the mixture model's own limit
// is the reference: a cloud whose grains follow the liquid within their
// Stokes velocity V_s is, to leading order in V_s/U, a drop of liquid
// carrying the excess weight phi_s (rho_p - rho) g per unit volume.
//
// The coupled run: the seed's cloud (321 glass discs, r = 12.5 um, in a
// disc of R = 0.5 mm at solid fraction 0.2, glycerine, Stokes) in a closed
// box 16 R wide, 5 fluid steps of 10 ms (the grains sub-step), its grains'
// mean velocity at t = 0.05 s, when the cloud has fallen a sixth of its
// radius. The single-fluid run: no drag, no solid fraction (the same grains
// as tracers, Coupling/Tracers = true, which take the liquid's velocity at
// their centres), the excess weight of the disc as Fluid/Forcing; the
// tracers' mean velocity is the drop's mean velocity at the grains.
//
// Both on two uniform meshes, cells of 125 um and 62.5 um (5 and 2.5 grain
// diameters). Checked: the two runs agree within 5 % on each mesh, and
// each run changes by less than 3 % from one mesh to the other. Measured:
// the cloud 1.78 / 1.80 mm/s, the drop 1.76 / 1.74 mm/s (0.9 % and 3.4 %
// apart; each 1.1-1.4 % from one mesh to the other). The two models
// differ by design inside the cloud: the mixture's viscous stress there
// is phi mu grad u (doc/theory.md), an interior viscosity of 0.8 mu, and a
// drop less viscous than its surroundings falls faster (in 3D, by 2.3 %
// for this ratio: Hadamard-Rybczynski, U ~ (1 + lambda)/(2 + 3 lambda));
// the cloud's edge is smoothed over the filter length (0.1 mm = R/5)
// while the forcing's is sharp; and the grains slip through the liquid
// at V_s = 0.2 % of U.
#include <deal.II/base/mpi.h>
#include <deal.II/base/parameter_handler.h>

#include <immersed_grains/parameters.h>
#include <immersed_grains/simulation.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

using namespace dealii;
using namespace ImmersedGrains;

namespace
{
  const double radius = 12.5e-6, cloud_radius = 5e-4, rho_p = 2400, rho = 1200,
               g = 9.81;

  const char *scene = R"(set Dimension = 2
set End time  = 0.05
set Time step = 0.01
set Adaptive time step = false
subsection Mesh
  set Lower corner = 0, 0
  set Upper corner = 8e-3, 8e-3
  set Subdivisions = 1, 1
  set Boundary conditions = wall, wall, wall, wall
end
subsection Fluid
  set Density   = 1200
  set Viscosity = 0.12
  set Advection = false
end
subsection Grains
  set Enabled = true
  set Radius  = 12.5e-6
  set Density = 2400
  subsection Placement
    set Shape          = ball
    set Center         = 4e-3, 4e-3
    set Size           = 5e-4
    set Solid fraction = 0.2
    set Random seed    = 1
  end
end
subsection Coupling
  set Smoothing length = 1e-4
end
subsection Gravity
  set Vector = 0, -9.81
end
subsection Output
  set Terminal output = quiet
end
)";

  // The last row of DIRECTORY/statistics.csv, by column name.
  double
  last_value(const std::string &directory, const std::string &column)
  {
    std::ifstream in(directory + "/statistics.csv");
    std::string   header, line, last;
    std::getline(in, header);
    while (std::getline(in, line))
      if (!line.empty())
        last = line;
    std::vector<std::string> names, values;
    std::string              field;
    for (std::istringstream s(header); std::getline(s, field, ',');)
      names.push_back(field);
    for (std::istringstream s(last); std::getline(s, field, ',');)
      values.push_back(field);
    for (unsigned int c = 0; c < names.size(); ++c)
      if (names[c] == column)
        return std::stod(values[c]);
    AssertThrow(false, ExcMessage("no column " + column));
    return 0;
  }

  double
  run(const std::string &directory,
      const unsigned int refinement,
      const double       excess_weight) // 0: the coupled run
  {
    const std::string file = directory + ".prm";
    if (Utilities::MPI::this_mpi_process(MPI_COMM_WORLD) == 0)
    {
      std::filesystem::remove_all(directory);
      std::ofstream prm(file);
      prm << scene << "set Output directory = " << directory
          << "\nsubsection Mesh\n  set Initial refinement = " << refinement
          << "\nend\n";
      if (excess_weight > 0)
        prm << "subsection Coupling\n  set Tracers = true\nend\n"
            << "subsection Fluid\n  subsection Forcing\n"
            << "    set Function constants = R=" << cloud_radius
            << ", f=" << excess_weight << '\n'
            << "    set Function expression = 0; "
            << "if((x-4e-3)^2 + (y-4e-3)^2 < R^2, -f, 0)\n  end\nend\n";
    }
    MPI_Barrier(MPI_COMM_WORLD);
    ParameterHandler prm;
    Simulation<2>::declare_parameters(prm);
    parse_parameter_file(prm, file);
    Simulation<2> simulation(prm, file, MPI_COMM_WORLD);
    simulation.run();
    MPI_Barrier(MPI_COMM_WORLD);
    return last_value(directory, "mean_velocity_y");
  }
} // namespace


int
main(int argc, char **argv)
{
  Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  const bool root = Utilities::MPI::this_mpi_process(MPI_COMM_WORLD) == 0;

  double coupled[2], single[2];
  for (unsigned int k = 0; k < 2; ++k)
  {
    const unsigned int refinement = 6 + k;
    coupled[k] = run("coupled_" + std::to_string(refinement), refinement, 0);
    // The excess weight of the grains actually placed, spread over the
    // disc: phi_s (rho_p - rho) g with phi_s = N r^2 / R^2.
    const double n_grains =
      last_value("coupled_" + std::to_string(refinement), "particles");
    const double phi_s =
      n_grains * radius * radius / (cloud_radius * cloud_radius);
    single[k] = run("single_" + std::to_string(refinement),
                    refinement,
                    phi_s * (rho_p - rho) * g);
    if (root)
    {
      const double difference = std::abs(coupled[k] / single[k] - 1);
      std::printf("cells %.4g um: grains %.0f (phi_s %.4f)\n",
                  8e3 / (1 << refinement),
                  n_grains,
                  phi_s);
      std::printf("  coupled and single-fluid within 5 %%: %s\n",
                  difference < 0.05 ? "yes" : "no");
      if (difference >= 0.05) // the figures, where the check fails
        std::printf("  cloud %.5g m/s, drop %.5g m/s, difference %.3g %%\n",
                    coupled[k],
                    single[k],
                    100 * difference);
    }
  }
  if (root)
    for (const auto &[name, u] : {std::make_pair("coupled", coupled),
                                  std::make_pair("single-fluid", single)})
    {
      const double change = std::abs(u[1] / u[0] - 1);
      std::printf("%s: finer mesh within 3 %%: %s\n",
                  name,
                  change < 0.03 ? "yes" : "no");
      if (change >= 0.03)
        std::printf("  %s mesh change %.3g %%\n", name, 100 * change);
    }
}
