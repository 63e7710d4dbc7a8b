// An underwater avalanche starting on an inclined plane, loose and dense
// (Pailha, Nicolas & Pouliquen 2008): the ready scenes
// prm/avalanche_2d_{loose,dense}.prm for their first 0.5 s. 799 glass
// discs (radius 112.5 um +- 20 %, 2500 kg/m^3), a layer about 20
// diameters deep on a base of fixed discs, in a liquid of 1010 kg/m^3 and
// 0.012 Pa s, periodic along the slope, gravity tilted by 25 degrees.
// The packings are prm/packings/avalanche_2d_{loose,dense}.txt (bulk
// packing 0.755 and 0.821).
//
// What Pailha et al. measured, checked as the mechanism: a loose layer
// contracts as it is sheared, the liquid it expels carries part of its
// weight, the pore pressure under it rises above hydrostatic, and it
// flows at once; a dense layer must dilate to flow, draws liquid in, the
// pore pressure under it falls below hydrostatic and holds it, and it
// creeps (in the full scene for about 8 s, then it fails). Read over
// 0.1-0.5 s (after the release's jolt), the excess pressure on the probe
// 0.25 mm above the base in units of the layer's buoyant weight per area
// normal to the slope, W = (rho_p - rho) g cos(25) phi H:
//  - the loose layer moves along the slope more than ten times faster
//    than the dense one (7.6 mm/s against 0.14 mm/s, 54 times; on two
//    ranks 8.8 and 0.15 mm/s);
//  - the mean excess is positive under the loose layer and negative under
//    the dense one, each by more than 2 % of W (+0.10 W, -0.17 W; on two
//    ranks +0.13 W, -0.18 W; over 0.05-0.3 s, +0.02 W and -0.20 W);
//  - the dense layer dilates and the loose one does not: the moving
//    discs' centroid rises by more than 2 % of a mean diameter (4.5 um)
//    under the dense layer (+11.7 um; two ranks +12.7 um) and by less
//    under the loose one (-1.9 um, -4.6 um: it compacts).
// The scenes' own text is run (ready_scene_text), to 0.5 s.
// The two runs take about a minute, serial or on two ranks.
#include <deal.II/base/mpi.h>

#include "checkpoint_test_support.h"

#include <cmath>
#include <iostream>
#include <string>

using namespace dealii;

namespace
{
  void
  avalanche(const std::string &name)
  {
    run_2d_scene(name + ".prm",
                 ready_scene_text("avalanche_2d_" + name) +
                   "set End time = 0.5\nset Output directory = " + name +
                   "\nsubsection Output\n  set Terminal output = quiet\n"
                   "  set Write fields every = 0\nend\n");
  }

  struct Layer
  {
    double velocity = 0; // along the slope, mean over 0.1-0.5 s
    double excess   = 0; // mean over 0.1-0.5 s, in W
    double rise     = 0; // of the moving discs' centroid, 0 to 0.5 s
  };

  Layer
  measure(const std::string &name, const double weight)
  {
    const auto         rows  = read_csv_rows(name + "/statistics.csv");
    const unsigned int t     = column_index(rows, "time"),
                       n     = column_index(rows, "particles"),
                       fixed = column_index(rows, "fixed_particles"),
                       vx    = column_index(rows, "mean_velocity_x"),
                       cy    = column_index(rows, "centroid_y"),
                       fy    = column_index(rows, "fixed_centroid_y"),
                       p     = column_index(rows, "probe_base_pressure");
    // The moving discs' centroid from all discs' and the fixed ones'.
    const auto centroid = [&](const std::vector<std::string> &row)
    {
      const double all = std::stod(row[n]), held = std::stod(row[fixed]);
      return (std::stod(row[cy]) * all - std::stod(row[fy]) * held) /
             (all - held);
    };
    Layer        layer;
    unsigned int count = 0;
    for (unsigned int r = 1; r < rows.size(); ++r)
      if (std::stod(rows[r][t]) > 0.1 + 1e-9)
      {
        layer.velocity += std::stod(rows[r][vx]);
        layer.excess += std::stod(rows[r][p]);
        ++count;
      }
    layer.velocity /= count;
    layer.excess /= count * weight;
    layer.rise = centroid(rows.back()) - centroid(rows[1]);
    return layer;
  }
} // namespace


int
main(int argc, char **argv)
{
  Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  avalanche("loose");
  avalanche("dense");
  if (Utilities::MPI::this_mpi_process(MPI_COMM_WORLD) != 0)
    return 0;

  // (rho_p - rho) g cos(25 degrees) phi H of each layer, as prepared.
  const double g_normal = 9.81 * std::cos(25 * M_PI / 180);
  const Layer  loose    = measure("loose", 1490 * g_normal * 0.755 * 4.77e-3);
  const Layer  dense    = measure("dense", 1490 * g_normal * 0.821 * 4.38e-3);
  const auto   yes      = [](const bool b) { return b ? "yes" : "no"; };
  std::cout << "the loose layer moves more than ten times faster than the "
               "dense one: "
            << yes(loose.velocity > 10 * dense.velocity) << '\n'
            << "loose: mean excess pore pressure > +0.02 W: "
            << yes(loose.excess > 0.02) << '\n'
            << "dense: mean excess pore pressure < -0.02 W: "
            << yes(dense.excess < -0.02) << '\n'
            << "dense: the layer dilates (its centroid rises > 4.5 um): "
            << yes(dense.rise > 4.5e-6) << '\n'
            << "loose: the layer does not (its centroid rises < 4.5 um): "
            << yes(loose.rise < 4.5e-6) << '\n';
}
