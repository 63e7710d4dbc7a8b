// Checkpoint/restart on a Gmsh mesh with an open boundary: the scene of
// grains_through_outlet_2d (seven grains, five of which fall out through
// the open part of the floor of meshes/outlet_2d.msh at steps 32, 35, 38,
// 40 and 43) runs 50 steps straight through, saving a checkpoint every 17
// steps. A second run stops after step 36, as if killed two steps after
// its last checkpoint (step 34, one grain gone), and a third resumes it
// and runs to step 50. Its statistics must equal the straight run's in
// every column but wall_time to the last digit: the mesh read again from
// its file, the grains in it and the count of those that left
// (grains_removed, 1 at the checkpoint) come back as they were. The
// reference is the code's own straight run: a restart must reproduce it,
// so no independent value enters.
#include <deal.II/base/mpi.h>

#include <immersed_grains/parameters.h>
#include <immersed_grains/simulation.h>

#include "checkpoint_test_support.h"

#include <filesystem>
#include <iostream>
#include <sstream>
#include <string>

using namespace dealii;
using namespace ImmersedGrains;

namespace
{
  void
  run(const std::string &directory, const double end_time, const bool resume)
  {
    std::ostringstream text;
    text << "set Dimension = 2\nset Time step = 0.01\nset End time = "
         << end_time << "\nset Output directory = " << directory
         << "\nsubsection Mesh\n  set Geometry = gmsh\n  set File = "
         << IMMERSED_GRAINS_TEST_MESHES << "/outlet_2d.msh\n"
         << "  set Initial refinement = 1\n"
         << "  set Boundary conditions = 1: wall, 2: open\nend\n"
         << "subsection Fluid\n  set Enabled = false\nend\n"
         << "subsection Grains\n  set Enabled = true\n  set Radius = 0.02\n"
         << "  set Density = 2500\n  subsection Placement\n"
         << "    set Shape = list\n    set Positions = 0.45, 0.5; 0.55, 0.6; "
         << "0.5, 0.7; 0.45, 0.8; 0.55, 0.9; 0.2, 0.3; 0.8, 0.3\n  end\nend\n"
         << "subsection Contacts\n  set Restitution = 0\nend\n"
         << "subsection Gravity\n  set Vector = 0, -9.81\nend\n"
         << "subsection Output\n  set Terminal output = quiet\nend\n"
         << "subsection Checkpoint\n  set Every steps = 17\n  set Resume = "
         << (resume ? "true" : "false") << "\nend\n";
    run_2d_scene(directory + ".prm", text.str());
  }
} // namespace


int
main(int argc, char **argv)
{
  Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  const bool root = Utilities::MPI::this_mpi_process(MPI_COMM_WORLD) == 0;
  if (root)
  {
    std::filesystem::remove_all("straight");
    std::filesystem::remove_all("resumed");
  }
  MPI_Barrier(MPI_COMM_WORLD);

  run("straight", 0.5, false);
  run("resumed", 0.36, false);
  run("resumed", 0.5, true);

  if (root)
  {
    const auto straight = read_csv_rows("straight/statistics.csv");
    const auto resumed  = read_csv_rows("resumed/statistics.csv");
    std::cout << "rows: " << straight.size() << " straight, " << resumed.size()
              << " resumed\n";
    const unsigned int removed_column =
      column_index(straight, "grains_removed");
    std::cout << "statistics equal exactly (wall_time aside): "
              << (largest_statistics_difference(straight, resumed) == 0 ?
                    "yes" :
                    "no")
              << '\n'
              << "grains_removed at step 34: " << resumed[35][removed_column]
              << ", at the end: " << resumed.back()[removed_column] << '\n';
  }
}
