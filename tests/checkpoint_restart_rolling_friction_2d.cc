// Checkpoint/restart with rolling friction: the dry column of
// prm/column_collapse_2d_dry.prm (502 discs, friction 0.4, rolling
// friction 0.2) collapses for 100 steps of 0.2 ms straight through,
// saving a checkpoint every 40 steps. A second run stops after step 90,
// as if killed 10 steps after its last checkpoint (step 80), and a third
// resumes it and runs to step 100. The contact solve starts each step from
// the impulses of the last, the rolling ones too, and a checkpoint keeps
// them: the resumed run's statistics must equal the straight run's in
// every column but wall_time, to the last digit. The reference is the
// code's own straight run: a restart must reproduce it, so no independent
// value enters. That the check can fail: the same resume from a
// checkpoint whose contact memory has lost its rolling impulses (each
// line cut after the tangential impulse, as a run without rolling
// friction writes it) parts from the straight run in the first step
// after the resume.
#include <deal.II/base/mpi.h>

#include "checkpoint_test_support.h"

#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

using namespace dealii;

namespace
{
  void
  run(const std::string &directory, const double end_time, const bool resume)
  {
    std::ostringstream text;
    text << ready_scene_text("column_collapse_2d_dry")
         << "set End time = " << end_time
         << "\nset Output directory = " << directory << R"(
subsection Output
  set Terminal output    = quiet
  set Write fields every = 0
  set Write grain file   = false
end
subsection Checkpoint
  set Every steps = 40
  set Resume      = )"
         << (resume ? "true" : "false") << "\nend\n";
    run_2d_scene(directory + ".prm", text.str());
  }

  // Cuts each line of every contacts_*.txt in @p checkpoint after the
  // normal and the two tangential impulses: the memory without rolling.
  void
  forget_rolling(const std::string &checkpoint)
  {
    for (const auto &entry : std::filesystem::directory_iterator(checkpoint))
    {
      const std::string name = entry.path().filename().string();
      if (name.rfind("contacts_", 0) != 0)
        continue;
      std::vector<std::string> lines;
      {
        std::ifstream in(entry.path());
        std::string   line;
        while (std::getline(in, line))
        {
          std::istringstream fields(line);
          std::string        field, cut;
          for (unsigned int f = 0; f < 5 && fields >> field; ++f)
            cut += (f > 0 ? " " : "") + field;
          lines.push_back(cut);
        }
      }
      std::ofstream out(entry.path());
      for (const std::string &line : lines)
        out << line << '\n';
    }
  }
} // namespace


int
main(int argc, char **argv)
{
  Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  const bool root = Utilities::MPI::this_mpi_process(MPI_COMM_WORLD) == 0;
  if (root)
    for (const std::string d : {"straight", "resumed", "forgotten"})
      std::filesystem::remove_all(d);
  MPI_Barrier(MPI_COMM_WORLD);

  run("straight", 0.02, false);
  run("resumed", 0.018, false);
  run("resumed", 0.02, true);
  run("forgotten", 0.018, false);
  if (root)
    forget_rolling("forgotten/checkpoints/step_00000080");
  MPI_Barrier(MPI_COMM_WORLD);
  run("forgotten", 0.02, true);

  if (root)
  {
    const auto straight  = read_csv_rows("straight/statistics.csv");
    const auto resumed   = read_csv_rows("resumed/statistics.csv");
    const auto forgotten = read_csv_rows("forgotten/statistics.csv");
    std::cout
      << "rows: " << straight.size() << " straight, " << resumed.size()
      << " resumed\n"
      << "statistics equal exactly (wall_time aside): "
      << (largest_statistics_difference(straight, resumed) == 0 ? "yes" : "no")
      << '\n'
      << "resumed without the rolling impulses: differs: "
      << (largest_statistics_difference(straight, forgotten) > 0 ? "yes" : "no")
      << '\n';
  }
}
