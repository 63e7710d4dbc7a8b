// An exact solution of the coupled fluid-grain equations: a shear wave
// shared by the fluid and the grains, decaying through viscosity and
// drag. 64 discs (r = 50 um, 2500 kg/m^3) on a square lattice 8 x 8 in a
// periodic box L = 3.2 mm wide, in a fluid of 50 kg/m^3 and 1e-4 Pa s,
// transient Stokes (the wave's advection u.grad u vanishes), no gravity,
// Stokes' drag gamma = 12 mu per unit depth, spread with the Helmholtz
// filter (l = 0.4 mm = one lattice spacing). At t = 0 the fluid is at rest
// and the discs move along x with B0 sin(k y), k = 2 pi / L.
//
// Reference (exact, derived in doc/validation.md "A shear wave of grains
// and fluid"): in the continuum limit of the equations the code solves,
// the wave stays a single mode, u = A(t) sin(k y) and v = B(t) sin(k y),
// with
//   A' = -nu k^2 A - D a (a A - B),   B' = G (a A - B),
// nu = mu / rho, D = n gamma / (phi rho) (n discs per area, phi the fluid
// fraction), G = gamma / m, and a = 1 / (1 + k^2 l^2) the filter's factor
// on the mode: the discs feel the filtered velocity a A, and the fluid
// receives their drags spread back through the same filter. The
// eigenvalues are -125.4 and -3.758 1/s: a fast exchange of momentum
// between the phases, then the mixture's viscous decay, slowed by the
// discs' inertia. The test reads B from the grains' kinetic energy,
// m N B^2 / 4 (the rows sample sin^2 to exactly half), at every step up
// to 0.08 s (B/B0 = 0.391 there).
//
// Windows: the error converges as O(h^2) + O(dt) (doc/validation.md,
// benchmarks/coupled_shear_wave/run.py: at 0.08 s it is -1.08, -0.36 and
// -0.18 % on cells of 200, 100 and 50 um with steps of 250 us, and each
// halving of the step adds +0.03 to +0.08 %). Coarse run, h = 200 um and
// dt = 250 us: |B/B_exact - 1| <= 1.5 % over the steps (measured at most
// 1.09 %); fine run, h = 100 um and dt = 125 us: <= 0.6 % (measured at
// most 0.31 %), and its largest error at most 0.45 times the coarse run's
// (measured 0.29; halving both the cells and the step must gain more than
// a first-order method's 0.5).
// Models that miss a piece of the coupling fall far outside: the fluid
// fed the filtered drag coefficient times its own velocity (instead of
// the drags spread back) gives B/B0 = 0.058 at 0.08 s, the filter left out
// of the exchange 0.621, one-way coupling 0.0075.
#include <deal.II/base/mpi.h>

#include "checkpoint_test_support.h"

#include <cmath>
#include <iostream>
#include <sstream>
#include <string>

using namespace dealii;
using namespace ImmersedGrains;

namespace
{
  constexpr double L = 3.2e-3, radius = 5e-5, grain_density = 2500,
                   density = 50, viscosity = 1e-4, length = 4e-4, B0 = 1e-3,
                   end_time      = 0.08;
  constexpr unsigned int lattice = 8;

  // B(t) of the exact solution, from A(0) = 0, B(0) = B0.
  double
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

  // Runs the wave on cells of L / @p cells with step @p dt into
  // @p directory; returns the largest |B / B_exact - 1| over its steps.
  double
  largest_error(const std::string &directory,
                const unsigned int cells,
                const double       dt)
  {
    const double       s = L / lattice, k = 2 * M_PI / L;
    std::ostringstream positions, velocities;
    positions.precision(17);
    velocities.precision(17);
    for (unsigned int j = 0; j < lattice; ++j)
      for (unsigned int i = 0; i < lattice; ++i)
      {
        const char *separator = i + j == 0 ? "" : "; ";
        positions << separator << (i + 0.5) * s << ", " << (j + 0.5) * s;
        velocities << separator << B0 * std::sin(k * (j + 0.5) * s) << ", 0";
      }
    std::ostringstream text;
    text << "set Dimension = 2\nset Output directory = " << directory
         << "\nset End time = " << end_time << "\nset Time step = " << dt
         << "\nsubsection Mesh\n  set Lower corner = 0, 0\n"
         << "  set Upper corner = " << L << ", " << L
         << "\n  set Subdivisions = " << cells << ", " << cells << R"(
  set Initial refinement = 0
  set Boundary conditions = periodic, periodic, periodic, periodic
end
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

    const auto         rows   = read_csv_rows(directory + "/statistics.csv");
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
} // namespace


int
main(int argc, char **argv)
{
  Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  const double                     coarse = largest_error("coarse", 16, 2.5e-4);
  const double                     fine   = largest_error("fine", 32, 1.25e-4);
  if (Utilities::MPI::this_mpi_process(MPI_COMM_WORLD) != 0)
    return 0;
  std::cout.precision(4);
  std::cout << "exact B/B0 at 0.02, 0.05, 0.08 s: "
            << exact_amplitude(0.02) / B0 << ", " << exact_amplitude(0.05) / B0
            << ", " << exact_amplitude(0.08) / B0 << '\n'
            << "h = 200 um, dt = 250 us: |B/B_exact - 1| <= 1.5 %: "
            << (coarse <= 0.015 ? "yes" : "no") << '\n'
            << "h = 100 um, dt = 125 us: |B/B_exact - 1| <= 0.6 %: "
            << (fine <= 0.006 ? "yes" : "no") << '\n'
            << "fine error <= 0.45 coarse error: "
            << (fine <= 0.45 * coarse ? "yes" : "no") << '\n';
}
