// A fluidized bed of two sizes segregates: glass beads (2500 kg/m^3) of
// d = 1 mm and 2 mm in equal volumes (144 and 18) in water, in a column
// 6 x 6 mm across (periodic sideways, cells of 2 mm) and 24 mm tall, the
// floor an inflow of superficial velocity U = 60 mm/s from the start
// (Fluid/Superficial inflow), the top open; Yin & Sundaresan's drag law
// for mixtures spread with the Helmholtz filter over l = 1 mm, the
// skew-symmetric advection. The beads start mixed at random.
// The filter: with the ready scene's 2 mm, as wide as a large bead, the
// large beads' layer packs denser than the reference in a bed this
// shallow (separation 1.14; pressure drop 0.962 of the weight here, the
// liquid's momentum loss 0.047 at that layer's fluid fraction, 0.555;
// doc/scenes/fluidized_bed_two_sizes_3d.md).
//
// Pressure drop. Reference (exact, the mixture's momentum balance): once
// the bed is lifted off the floor, the pressure drop across the column
// carries the beads' buoyant weight per area, sum N_k (rho_p - rho_f)
// V_k g / A = 61.64 Pa, whatever the drag law. Mean over 1.5-2.5 s,
// weighted by the step. Window [0.96, 1.02]: 2 % either way, as in
// fluidized_bed_3d (what collisions and the bed's rearrangement leave in
// its momentum over a second), and 2 % more below: in this column the
// Navier-Stokes drop reads lower than the Stokes one (with the 2 mm
// filter 0.963 against 0.992, the floor's contacts carrying 0 and 0.010),
// by about the momentum the liquid loses from the distributor (U/phi) to
// the top (U): measured over the floor and the top faces
// (scripts/column_balance.py), 0.017 of the weight, and the face drop
// 0.984, the floor's contacts 0.005: the balance closes to 0.6 % (0.047
// at the floor's fluid fraction 0.555 with 2 mm). The ready scene's wider
// column leaves 1.4-3.6 % unaccounted (doc/validation.md, "Several
// sizes"). Measured: 0.980 (two ranks 0.981).
// The floor. The lowest large beads touch the distributor now and then:
// its contact force (Output/Boundary contact forces), mean over the
// window, carries 0.46 % of the buoyant weight (two ranks 0.32 %);
// checked below 2 %: the liquid carries a fluidized bed.
//
// Segregation. Reference: both sizes fluidized at 60 mm/s (minimum
// fluidization about 8 and 22 mm/s by Wen & Yu) and the bed segregated
// completely into two layers, the large beads below, each expanded as a
// bed of its size alone by Richardson & Zaki with Garside & Al-Dibouni's
// exponent (eps = 0.616 for 2 mm, 0.762 for 1 mm; the serial model of
// Epstein, LeClair & Pruden 1981): the large beads' layer 0-5.45 mm, the
// small beads' 5.45-14.26 mm, centroids 2.73 and 9.85 mm, 7.13 mm apart.
// Checked: the centroids' separation, mean over 1.5-2.5 s, between 0.85
// and 1.2 of it. Mixed beads have none; 0.85 leaves room for a mixed zone
// between the layers (Epstein et al. observe one) a large bead thick;
// 1.2 for a bed three large beads across that breathes (over the window
// the centroids' rows span 0.16 and 0.40 mm). Measured: 1.05.
// This checks segregation and its extent, not the drag law's size
// correction: under Beetstra's law, blind to the size, the bed segregates
// as far (1.08); the hindered_settling_yin_sundaresan tests check that.
#include <deal.II/base/mpi.h>

#include <immersed_grains/parameters.h>
#include <immersed_grains/simulation.h>

#include "checkpoint_test_support.h"

#include <cmath>
#include <iostream>
#include <sstream>
#include <string>

using namespace dealii;
using namespace ImmersedGrains;

int
main(int argc, char **argv)
{
  Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  const bool root = Utilities::MPI::this_mpi_process(MPI_COMM_WORLD) == 0;

  const std::string text = R"(set Dimension = 3
set Output directory = bed
set End time = 2.5
set Time step = 2e-3
set Adaptive time step = true
subsection Mesh
  set Lower corner        = 0, 0, 0
  set Upper corner        = 0.006, 0.006, 0.024
  set Subdivisions        = 3, 3, 12
  set Initial refinement  = 0
  set Boundary conditions = periodic, periodic, periodic, periodic, inflow, open
end
subsection Fluid
  set Density            = 1000
  set Viscosity          = 1e-3
  set Advection form     = skew-symmetric
  set Superficial inflow = true
  set Inflow velocity    = 0; 0; 0.06
end
subsection Grains
  set Enabled           = true
  set Density           = 2500
  set Size distribution = classes
  set Class radii       = 5e-4, 1e-3
  set Class fractions   = 0.5, 0.5
  subsection Placement
    set Shape       = box
    set Center      = 0.003, 0.003, 0.008
    set Size        = 0.006, 0.006, 0.016
    set Count       = 162
    set Random seed = 1
  end
end
subsection Contacts
  set Restitution = 0
  set Friction    = 0.3
end
subsection Coupling
  set Drag distribution = filtered
  set Smoothing length  = 1e-3
  set Drag law          = Yin-Sundaresan
end
subsection Gravity
  set Vector = 0, 0, -9.81
end
subsection Output
  set Terminal output      = quiet
  set Pressure drop points = 0.003, 0.003, 0; 0.003, 0.003, 0.024
  set Boundary contact forces = 4
end
)";
  run_scene<3>("bed.prm", text);
  if (!root)
    return 0;

  const auto         rows  = read_csv_rows("bed/statistics.csv");
  const unsigned int small = column_index(rows, "class0_centroid_z"),
                     large = column_index(rows, "class1_centroid_z"),
                     n0    = column_index(rows, "class0_particles"),
                     n1    = column_index(rows, "class1_particles");
  const double pressure    = time_average(rows, 1.5, "pressure_drop");
  const double on_floor =
    -time_average(rows, 1.5, "boundary_contact_force_4_z");
  const double separation =
    time_average(rows,
                 1.5,
                 [&](const std::vector<std::string> &row)
                 { return std::stod(row[small]) - std::stod(row[large]); });

  const double area   = 0.006 * 0.006;
  const double volume = std::stod(rows.back()[n0]) * (M_PI / 6 * 1e-9) +
                        std::stod(rows.back()[n1]) * (M_PI / 6 * 8e-9);
  const double weight    = volume * (2500. - 1000.) * 9.81 / area;
  const double reference = 9.85e-3 - 2.73e-3;
  std::cout << "beads: " << rows.back()[n0] << " of 1 mm, " << rows.back()[n1]
            << " of 2 mm\n"
            << "mean pressure drop / buoyant weight per area in [0.96, 1.02]: "
            << (pressure > 0.96 * weight && pressure < 1.02 * weight ? "yes" :
                                                                       "no")
            << '\n'
            << "the distributor's contact force below 2 % of that weight: "
            << (on_floor >= 0 && on_floor < 0.02 * weight * area ? "yes" : "no")
            << '\n'
            << "the small beads' centroid above the large beads' by 0.85-1.2 "
               "of complete segregation: "
            << (separation > 0.85 * reference && separation < 1.2 * reference ?
                  "yes" :
                  "no")
            << '\n';
}
