// The coupled shear wave shared by coupled_shear_wave_2d.cc and
// coupled_shear_wave_gmsh_2d.cc: 64 discs (r = 50 um, 2500 kg/m^3) on a
// square lattice 8 x 8 in a periodic square L = 3.2 mm wide, in a fluid of
// 50 kg/m^3 and 1e-4 Pa s, transient Stokes, no gravity, Stokes' drag
// spread with the Helmholtz filter (l = 0.4 mm); at t = 0 the fluid is at
// rest and the discs move along x with B0 sin(k y). The exact solution
// and its derivation: coupled_shear_wave_2d.cc and doc/validation.md,
// "A shear wave of grains and fluid".
#ifndef immersed_grains_tests_coupled_shear_wave_h
#define immersed_grains_tests_coupled_shear_wave_h

#include "checkpoint_test_support.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

namespace shear_wave
{
  constexpr double L = 3.2e-3, radius = 5e-5, grain_density = 2500,
                   density = 50, viscosity = 1e-4, length = 4e-4, B0 = 1e-3,
                   end_time      = 0.08;
  constexpr unsigned int lattice = 8;

  // B(t) of the exact solution, from A(0) = 0, B(0) = B0.
  inline double
  exact_amplitude(const double t)
  {
    const double k    = 2 * M_PI / L;
    const double N    = lattice * lattice;
    const double m    = grain_density * M_PI * radius * radius;
    const double gam  = 12 * viscosity;
    const double phi  = 1 - N * M_PI * radius * radius / (L * L);
    const double D    = N / (L * L) * gam / (phi * density);
    const double G    = gam / m;
    const double a    = 1 / (1 + k * k * length * length);
    const double m11  = -viscosity / density * k * k - D * a * a;
    const double m22  = -G;
    const double tr   = m11 + m22;
    const double det  = m11 * m22 - (D * a) * (G * a);
    const double root = std::sqrt(tr * tr - 4 * det);
    const double l1 = (tr + root) / 2, l2 = (tr - root) / 2;
    return B0 *
           ((m22 - l2) * std::exp(l1 * t) + (l1 - m22) * std::exp(l2 * t)) /
           (l1 - l2);
  }

  // Runs the wave to end_time in @p directory, on the mesh of
  // @p mesh_section (a whole `subsection Mesh`), with the lattice moved by
  // @p shift along x (the solution does not depend on it), and returns
  // its statistics rows (read_csv_rows()).
  inline std::vector<std::vector<std::string>>
  run(const std::string &directory,
      const std::string &mesh_section,
      const double       dt,
      const double       shift = 0)
  {
    const double       s = L / lattice, k = 2 * M_PI / L;
    std::ostringstream positions, velocities;
    positions.precision(17);
    velocities.precision(17);
    for (unsigned int j = 0; j < lattice; ++j)
      for (unsigned int i = 0; i < lattice; ++i)
      {
        const char *separator = i + j == 0 ? "" : "; ";
        positions << separator << (i + 0.5) * s + shift << ", "
                  << (j + 0.5) * s;
        velocities << separator << B0 * std::sin(k * (j + 0.5) * s) << ", 0";
      }
    std::ostringstream text;
    text << "set Dimension = 2\nset Output directory = " << directory
         << "\nset End time = " << end_time << "\nset Time step = " << dt
         << '\n'
         << mesh_section << R"(
subsection Fluid
  set Density   = 50
  set Viscosity = 1e-4
  set Advection = false
end
subsection Grains
  set Enabled = true
  set Radius  = 5e-5
  set Density = 2500
  subsection Placement
    set Shape = list
)"
         << "    set Positions = " << positions.str()
         << "\n    set Velocities = " << velocities.str() << R"(
  end
end
subsection Coupling
  set Drag law          = Stokes
  set Drag distribution = filtered
  set Smoothing length  = 4e-4
end
subsection Gravity
  set Vector = 0, 0
end
subsection Output
  set Terminal output = quiet
end
)";
    run_scene<2>(directory + ".prm", text.str());
    return read_csv_rows(directory + "/statistics.csv");
  }

  // The largest |B/B_exact - 1| over the steps of @p rows, B read from the
  // grains' kinetic energy, m N B^2 / 4 (the rows sample sin^2 to exactly
  // half).
  inline double
  largest_error(const std::vector<std::vector<std::string>> &rows)
  {
    const unsigned int time   = column_index(rows, "time"),
                       energy = column_index(rows, "kinetic_energy");
    const double m            = grain_density * M_PI * radius * radius;
    double       largest      = 0;
    for (unsigned int r = 1; r < rows.size(); ++r)
    {
      const double B =
        std::sqrt(4 * std::stod(rows[r][energy]) / (m * lattice * lattice));
      largest =
        std::max(largest,
                 std::abs(B / exact_amplitude(std::stod(rows[r][time])) - 1));
    }
    return largest;
  }
} // namespace shear_wave

#endif
