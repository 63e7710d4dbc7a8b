// A packing one run prepares is the next run's initial state: 120 discs
// (r = 1 mm +- 20 %, friction 0.5) poured into a box 2 cm wide settle
// under gravity for 0.4 s and are written at the end (Output/Write grain
// file); a second run reads the file (Placement/Shape = file) and starts
// from it.
//
// Checked (exact, the file holds 17 significant digits): the second run's
// first statistics row has the grains, centroid and mean velocity of the
// first run's last row, to 1e-11 relative (the table's 12 digits). The
// packing holds overlaps of the contact solver's size (up to Contacts/
// Overlap tolerance, 1e-3 r): it must read back although grains given
// by hand may overlap by no more than 1e-9 r; the test says whether the
// file has overlaps beyond 1e-9 r (it has) and that none exceeds the
// tolerance.
#include <deal.II/base/mpi.h>

#include "checkpoint_test_support.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

using namespace dealii;

namespace
{
  std::string
  scene(const std::string &directory,
        const double       end_time,
        const std::string &placement)
  {
    return "set Dimension = 2\nset Output directory = " + directory +
           "\nset End time = " + std::to_string(end_time) +
           "\nset Time step = 2e-3\n" + R"(subsection Mesh
  set Lower corner = 0, 0
  set Upper corner = 0.02, 0.04
  set Subdivisions = 2, 4
end
subsection Fluid
  set Enabled = false
end
subsection Grains
  set Enabled           = true
  set Size distribution = uniform
  set Radius            = 1e-3
  set Radius spread     = 2e-4
  set Density           = 2500
  subsection Placement
)" + placement +
           R"(
  end
end
subsection Contacts
  set Friction = 0.5
end
subsection Gravity
  set Vector = 0, -9.81
end
subsection Output
  set Terminal output  = quiet
  set Write grain file = true
end
)";
  }
} // namespace


int
main(int argc, char **argv)
{
  Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  run_2d_scene("poured.prm",
               scene("poured",
                     0.4,
                     "    set Shape       = box\n    set Center      = 0.01, "
                     "0.02\n    set Size        = 0.02, 0.04\n    set Count  "
                     "     = 120\n    set Random seed = 3"));
  run_2d_scene("read.prm",
               scene("read",
                     2e-3,
                     "    set Shape = file\n    set File  = "
                     "poured/grains.txt"));
  if (Utilities::MPI::this_mpi_process(MPI_COMM_WORLD) != 0)
    return 0;

  const auto poured  = read_csv_rows("poured/statistics.csv");
  const auto read    = read_csv_rows("read/statistics.csv");
  double     largest = 0;
  for (const std::string name : {"particles",
                                 "centroid_x",
                                 "centroid_y",
                                 "mean_velocity_x",
                                 "mean_velocity_y"})
  {
    const double a = std::stod(poured.back()[column_index(poured, name)]);
    const double b = std::stod(read[1][column_index(read, name)]);
    largest        = std::max(largest,
                       std::abs(a - b) /
                         std::max(1e-300, std::max(std::abs(a), std::abs(b))));
  }
  std::cout << "read back: grains, centroid and mean velocity of the last "
               "row to 1e-11: "
            << (largest < 1e-11 ? "yes" : "no") << '\n';

  // The file's overlaps, every pair (120 discs), relative to the smaller
  // radius.
  std::vector<std::array<double, 3>> discs;
  std::ifstream                      in("poured/grains.txt");
  for (std::string line; std::getline(in, line);)
    if (!line.empty() && line[0] != '#')
    {
      std::istringstream words(line);
      double             x, y, r;
      words >> x >> y >> r;
      discs.push_back({{x, y, r}});
    }
  double overlap = 0;
  for (unsigned int i = 0; i < discs.size(); ++i)
  {
    const auto &a = discs[i];
    // The floor and the side walls.
    for (const double gap : {a[1] - a[2], a[0] - a[2], 0.02 - a[0] - a[2]})
      overlap = std::max(overlap, -gap / a[2]);
    for (unsigned int j = i + 1; j < discs.size(); ++j)
    {
      const auto  &b = discs[j];
      const double d = std::hypot(a[0] - b[0], a[1] - b[1]);
      overlap = std::max(overlap, (a[2] + b[2] - d) / std::min(a[2], b[2]));
    }
  }
  std::cout << "the file holds " << discs.size() << " grains\n"
            << "its largest overlap beyond 1e-9 r and within the tolerance "
               "1e-3 r: "
            << (overlap > 1e-9 && overlap <= 1e-3 ? "yes" : "no") << '\n';
}
