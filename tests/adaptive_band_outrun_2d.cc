// Adaptivity/Every steps = auto warns, once, when the fastest grain
// crosses more than the band of refined cells around the grains in a
// single fluid step: the 81-disc cloud of the checkpoint tests (0.3 mm/s,
// cells of 125 um at Max level 4, a band of 2 cells) with fluid steps of
// 1 s (300 um per step, the grains sub-stepping inside), against the same
// scene at its own step of 0.05 s (15 um per step: no warning). Also
// checked: with steps of 1 s the mesh adapts before every step (the
// travel of one step exceeds half the band). These runs use the band
// without lookahead (Band lookahead = 0, Band width 2). With the defaults
// (Band lookahead = 2, Band width = auto: 1) the band covers each grain's
// path 2 cells ahead as well, 375 um in all: steps of 1 s stay within
// it (no warning), steps of 3 s (0.18 mm/s: 540 um) do not, and the
// warning names the lookahead.
#include <deal.II/base/mpi.h>
#include <deal.II/base/parameter_handler.h>

#include <immersed_grains/parameters.h>
#include <immersed_grains/simulation.h>

#include "checkpoint_test_support.h"

#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <sstream>
#include <string>

using namespace dealii;
using namespace ImmersedGrains;

namespace
{
  // The number of times @p text occurs in @p directory's log.
  unsigned int
  count_in_log(const std::string &directory, const std::string &text)
  {
    std::ifstream     in(directory + "/log.txt");
    const std::string log((std::istreambuf_iterator<char>(in)),
                          std::istreambuf_iterator<char>());
    unsigned int      n = 0;
    for (auto at = log.find(text); at != std::string::npos;
         at      = log.find(text, at + 1))
      ++n;
    return n;
  }


  void
  run(const std::string &directory,
      const double       time_step,
      const double       end_time,
      const bool         lookahead = false)
  {
    std::filesystem::remove_all(directory);
    std::ostringstream text;
    text << adaptive_cloud_scene << "set Time step = " << time_step
         << "\nset End time = " << end_time
         << "\nset Output directory = " << directory
         << "\nsubsection Adaptivity\n  set Every steps = auto\n"
         << (lookahead ? "" : "  set Band lookahead = 0\n") << "end\n";
    run_2d_scene(directory + ".prm", text.str());
  }
} // namespace


int
main(int argc, char **argv)
{
  Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  run("long_steps", 1, 3);
  run("short_steps", 0.05, 0.15);
  run("lookahead_steps", 1, 3, true);
  run("lookahead_long_steps", 3, 6, true);
  const std::string warning = "warning: step";
  std::cout << "steps of 1 s: band warnings "
            << count_in_log("long_steps", warning) << ", mentions Band width: "
            << (count_in_log("long_steps", "Adaptivity/Band width") > 0 ?
                  "yes" :
                  "no")
            << ", adaptations before steps 2 and 3: "
            << count_in_log("long_steps", "mesh adapted before step 2") +
                 count_in_log("long_steps", "mesh adapted before step 3")
            << '\n';
  std::cout << "steps of 0.05 s: band warnings "
            << count_in_log("short_steps", warning) << '\n';
  std::cout << "with the lookahead (Band width 1 and 2 cells ahead): steps "
               "of 1 s: band warnings "
            << count_in_log("lookahead_steps", warning)
            << ", steps of 3 s: band warnings "
            << count_in_log("lookahead_long_steps", warning)
            << ", mentions Band lookahead: "
            << (count_in_log("lookahead_long_steps", "Band lookahead = 2") > 0 ?
                  "yes" :
                  "no")
            << '\n';
}
