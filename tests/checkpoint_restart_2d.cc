// Checkpoint/restart: a 2D cloud of 81 discs with contacts on an adaptive
// mesh (adapted every 3 steps) runs 10 fluid steps straight through,
// saving a checkpoint every 2 (Checkpoint/Every steps). A second run in
// another directory stops after step 5, as if killed one step after its
// last checkpoint (step 4), and a third resumes it (Resume = true) and runs
// to step 10: it keeps the rows 0-4 of statistics.csv, drops the row of
// step 5 and computes it again. Its statistics must equal the straight
// run's in every column but wall_time: on one rank to the last digit
// (relative difference 0), on two within 1e-12 (measured: exact too). Also
// checked: no row lost or doubled, the run said it resumed (the grains are
// not placed again), and only the two newest checkpoints are kept. The
// reference is the code's own straight run: a restart must reproduce it,
// so no independent value enters. On two ranks the first part also runs
// on one rank and is resumed on two: every grain kept, the centroid within
// 0.1 % of the distance fallen of the straight two-rank run (one rank and
// two split the contact sweeps differently and so round differently; the
// window holds that round-off as the contacts amplify it). The same again
// with Adaptivity/Every steps = auto, whose schedule depends on the grains'
// travel since the last adaptation: that sum must survive the restart; and with
// Band lookahead, whose schedule depends on when the band was made and on each
// grain's deviation from its straight path. Last, a fresh run in a directory
// that holds another run's checkpoints keeps only its own, and a resume with
// other physics (friction added) stops with an input error that names
// Checkpoint/Resume and leaves the run as it was, and so does a resume with the
// band's lookahead from sets written before physics.txt (the same sets with the
// file taken away), and a resume of sets whose grains carry a layout no setting
// gives (another version's) says so.
#include <deal.II/base/mpi.h>
#include <deal.II/base/parameter_handler.h>

#include <immersed_grains/parameters.h>
#include <immersed_grains/simulation.h>

#include "checkpoint_test_support.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

using namespace dealii;
using namespace ImmersedGrains;

namespace
{

  void
  run(const std::string &directory,
      const double       end_time,
      const bool         resume,
      MPI_Comm           comm     = MPI_COMM_WORLD,
      const std::string &schedule = "")
  {
    std::ostringstream text;
    text << adaptive_cloud_scene << "set End time = " << end_time
         << "\nset Output directory = " << directory
         << "\nsubsection Checkpoint\n  set Every steps = 2\n  set Resume = "
         << (resume ? "true" : "false") << "\nend\n"
         << schedule;
    run_2d_scene(directory + ".prm", text.str(), comm);
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
  run("resumed", 0.25, false);
  run("resumed", 0.5, true);

  // Friction gives each grain an angular velocity: a checkpoint written
  // without it holds fewer numbers per grain, which a resume with friction
  // would read as something else (a 10^4-sphere pile came back with 7786
  // grains at infinite speed). It must stop with an input error naming
  // Checkpoint/Resume, before it changes anything.
  // The input error a resume of @p directory with @p text stops with.
  const auto resume_error =
    [](const std::string &directory, const std::string &text)
  {
    try
    {
      run(directory, 0.75, true, MPI_COMM_WORLD, text);
    }
    catch (const InputError &e)
    {
      return std::string(e.what());
    }
    return std::string();
  };
  const auto log_size = [](const std::string &directory)
  {
    return std::filesystem::exists(directory + "/log.txt") ?
             std::filesystem::file_size(directory + "/log.txt") :
             std::uintmax_t(0);
  };
  const std::uintmax_t log_before = log_size("resumed");
  const std::string    friction_error =
    resume_error("resumed", "subsection Contacts\n  set Friction = 0.3\nend\n");

  // A copy of the run's checkpoint sets in @p name, each set's
  // physics.txt handed to @p edit (on rank 0).
  const auto copy_sets =
    [root](const std::string                                        &name,
           const std::function<void(const std::filesystem::path &)> &edit)
  {
    if (root)
    {
      std::filesystem::remove_all(name);
      std::filesystem::copy("resumed",
                            name,
                            std::filesystem::copy_options::recursive);
      for (const auto &set :
           std::filesystem::directory_iterator(name + "/checkpoints"))
        edit(set.path() / "physics.txt");
    }
    MPI_Barrier(MPI_COMM_WORLD);
  };

  // Sets written before physics.txt existed are resumed without the check,
  // but never with the band's lookahead: their grains carry no straight
  // paths. (The same run's sets with the file taken away.)
  copy_sets("unlabelled",
            [](const std::filesystem::path &file)
            { std::filesystem::remove(file); });
  const std::string unlabelled_error =
    resume_error("unlabelled",
                 "subsection Adaptivity\n  set Every steps = auto\nend\n");

  // Sets whose grains carry a layout that no setting of this version
  // gives, as another version of the code writes (the same sets without
  // the property exchange_owed, which versions before it lacked): the
  // error says so, instead of listing settings that cannot help.
  copy_sets("foreign",
            [](const std::filesystem::path &file)
            {
              std::ifstream in(file);
              std::string   line;
              std::getline(in, line);
              in.close();
              const std::string owed = ", exchange_owed";
              if (line.find(owed) != std::string::npos)
                line.erase(line.find(owed), owed.size());
              std::ofstream(file) << line << '\n';
            });
  const std::string foreign_error = resume_error("foreign", "");

  // A run straight to step 10, and one stopped after step 5 and resumed
  // from its checkpoint of step 4, with the Adaptivity section @p text.
  const auto straight_and_resumed =
    [&](const std::string &name, const std::string &text)
  {
    if (root)
    {
      std::filesystem::remove_all("straight_" + name);
      std::filesystem::remove_all("resumed_" + name);
    }
    run("straight_" + name, 0.5, false, MPI_COMM_WORLD, text);
    run("resumed_" + name, 0.25, false, MPI_COMM_WORLD, text);
    run("resumed_" + name, 0.5, true, MPI_COMM_WORLD, text);
  };

  // Every steps = auto adapts by how far the grains went since the last
  // adaptation, a sum the checkpoint carries: on cells of 62.5 um (Max
  // level 5) the grains (0.3 mm/s, 17 um per step) call for one every 3
  // steps, so the resumed run must pick up the sum of the steps before the
  // checkpoint. (The band without lookahead, whose schedule is that sum
  // alone.)
  straight_and_resumed("auto",
                       "subsection Adaptivity\n  set Every steps = auto\n"
                       "  set Max level = 5\n  set Band lookahead = 0\nend\n");

  // With Band lookahead = 1 (and Band width 2) the band made before step 4
  // (the grains start at rest, so the first is made by their travel)
  // covers one cell (4 steps) of each grain's path. The schedule then
  // depends on when the band was made and on each grain's deviation from
  // its path (grain properties): the resumed run must carry both across
  // the checkpoint of step 4 to adapt again before step 7, as the straight
  // run does.
  straight_and_resumed("lookahead",
                       "subsection Adaptivity\n  set Every steps = auto\n"
                       "  set Max level = 5\n  set Band lookahead = 1\n"
                       "  set Band width = 2\nend\n");

  // A fresh run (Resume = false) where another run left its checkpoints
  // (steps 8 and 10): it must not take them for its own newest sets.
  if (root)
    std::filesystem::remove_all("again");
  run("again", 0.5, false);
  run("again", 0.15, false);

  // On several ranks: the first part on rank 0 alone, resumed on all.
  const unsigned int n_ranks = Utilities::MPI::n_mpi_processes(MPI_COMM_WORLD);
  if (n_ranks > 1)
  {
    if (root)
      std::filesystem::remove_all("regrouped");
    MPI_Comm first;
    MPI_Comm_split(MPI_COMM_WORLD, root ? 0 : MPI_UNDEFINED, 0, &first);
    run("regrouped", 0.25, false, first);
    if (first != MPI_COMM_NULL)
      MPI_Comm_free(&first);
    run("regrouped", 0.5, true);
  }

  if (!root)
    return 0;
  const bool one_rank = Utilities::MPI::n_mpi_processes(MPI_COMM_WORLD) == 1;
  // The largest relative difference between two runs' statistics, over
  // every column but wall_time; "same rows" when both end on the same step.
  const auto compare =
    [one_rank](const std::vector<std::vector<std::string>> &straight,
               const std::vector<std::vector<std::string>> &resumed)
  {
    const double largest = largest_statistics_difference(straight, resumed);
    std::cout << "same rows, same steps: "
              << (straight.size() == resumed.size() &&
                      straight.back()[0] == resumed.back()[0] ?
                    "yes" :
                    "no")
              << '\n';
    std::cout << "statistics equal " << (one_rank ? "exactly" : "within 1e-12")
              << ": " << (largest <= (one_rank ? 0.0 : 1e-12) ? "yes" : "no")
              << '\n';
    if (largest > 0)
      std::cerr << "largest relative difference " << largest << '\n';
  };
  const auto straight = read_csv_rows("straight/statistics.csv");
  const auto resumed  = read_csv_rows("resumed/statistics.csv");
  std::cout << "rows: straight " << straight.size() - 1 << ", resumed "
            << resumed.size() - 1 << '\n';
  compare(straight, resumed);

  std::cout << "a resume with friction added stops with an input error "
               "naming Checkpoint/Resume: "
            << (friction_error.find("Checkpoint/Resume") != std::string::npos &&
                    friction_error.find("angular_velocity") !=
                      std::string::npos ?
                  "yes" :
                  "no")
            << ", before writing to the run's log: "
            << (log_size("resumed") == log_before ? "yes" : "no") << '\n';
  std::cout << "a set without physics.txt resumed with the band's lookahead "
               "stops with an input error naming Band lookahead: "
            << (unlabelled_error.find("Band lookahead") != std::string::npos ?
                  "yes" :
                  "no")
            << '\n';

  std::cout << "a set of another version's layout stops with an input "
               "error saying so: "
            << (foreign_error.find("another version") != std::string::npos ?
                  "yes" :
                  "no")
            << '\n';

  std::ifstream log("resumed/log.txt");
  std::string   text((std::istreambuf_iterator<char>(log)),
                   std::istreambuf_iterator<char>());
  std::cout << "resumed from a checkpoint: "
            << (text.find("resumed from") != std::string::npos ? "yes" : "no")
            << '\n';
  if (n_ranks > 1)
  {
    // One rank and two round differently (the contact sweeps are split
    // between the ranks), so this run is compared by its figures: every
    // grain kept and the cloud where the straight run has it.
    const auto   regrouped = read_csv_rows("regrouped/statistics.csv");
    unsigned int particles = 0, centroid = 0;
    for (unsigned int c = 0; c < straight[0].size(); ++c)
    {
      if (straight[0][c] == "particles")
        particles = c;
      if (straight[0][c] == "centroid_y")
        centroid = c;
    }
    const double fallen =
      std::stod(straight[1][centroid]) - std::stod(straight.back()[centroid]);
    std::cout << "resumed on " << n_ranks << " ranks from one: rows "
              << regrouped.size() - 1 << ", grains "
              << regrouped.back()[particles] << ", centroid within 0.1 % of "
              << "the distance fallen: "
              << (std::abs(std::stod(regrouped.back()[centroid]) -
                           std::stod(straight.back()[centroid])) <
                      1e-3 * fallen ?
                    "yes" :
                    "no")
              << '\n';
  }
  {
    std::cout << "Every steps = auto:\n";
    const auto straight_auto = read_csv_rows("straight_auto/statistics.csv");
    compare(straight_auto, read_csv_rows("resumed_auto/statistics.csv"));
    // The mesh must change after the checkpoint of step 4. Since a run
    // goes on from each checkpoint it writes, a sum the checkpoint lost
    // would start from zero every 2 steps in both runs, and the grains
    // (4 steps to the allowance) would never call for an adaptation.
    unsigned int cells = 0;
    for (unsigned int c = 0; c < straight_auto[0].size(); ++c)
      if (straight_auto[0][c] == "cells")
        cells = c;
    bool changed = false;
    for (unsigned int r = 6; r < straight_auto.size(); ++r)
      changed |= straight_auto[r][cells] != straight_auto[r - 1][cells];
    std::cout << "mesh changed after the checkpoint: "
              << (changed ? "yes" : "no") << '\n';
  }
  {
    std::cout << "Band lookahead = 1:\n";
    const auto straight = read_csv_rows("straight_lookahead/statistics.csv");
    compare(straight, read_csv_rows("resumed_lookahead/statistics.csv"));
    // The adaptations after the checkpoint (the log says before which
    // step each came; the resumed run's log goes on from the first part's).
    const auto adaptations = [](const std::string &directory)
    {
      std::ifstream     in(directory + "/log.txt");
      std::string       line, steps;
      const std::string key = "mesh adapted before step ";
      while (std::getline(in, line))
        if (const auto at = line.find(key); at != std::string::npos)
        {
          const int step = std::atoi(line.c_str() + at + key.size());
          if (step > 4)
            steps += ' ' + std::to_string(step);
        }
      return steps;
    };
    std::cout << "adapted after the checkpoint, before steps:"
              << adaptations("straight_lookahead")
              << " (resumed:" << adaptations("resumed_lookahead") << ")\n";
  }
  {
    std::vector<std::string> sets;
    for (const auto &entry :
         std::filesystem::directory_iterator("again/checkpoints"))
      sets.push_back(entry.path().filename().string());
    std::sort(sets.begin(), sets.end());
    const auto rows = read_csv_rows("again/statistics.csv");
    std::cout << "a fresh run over another's checkpoints: rows "
              << rows.size() - 1 << ", checkpoints";
    for (const auto &set : sets)
      std::cout << ' ' << set;
    std::cout << '\n';
  }
  unsigned int kept = 0;
  for (const auto &entry :
       std::filesystem::directory_iterator("straight/checkpoints"))
    kept += entry.path().filename().string().rfind("step_", 0) == 0;
  std::cout << "checkpoints kept: " << kept << '\n';
}
