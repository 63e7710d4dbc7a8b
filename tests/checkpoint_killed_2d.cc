// A run killed with SIGKILL while it writes a checkpoint, and the wall-clock
// interval of Checkpoint.
//
// An adaptive 2D cloud with contacts (the scene of checkpoint_restart_2d)
// runs 10 fluid steps straight through with a checkpoint every 2 steps. A
// second run of the same scene kills itself (SIGKILL) in the middle of
// writing the checkpoint of step 6: the mesh of that set is on disk, its
// state is not (Checkpoint::maybe_die_while_writing). Then:
// - the killed run left the set of step 4 complete and that of step 6
//   unfinished under its temporary name;
// - the same command again (Resume = auto) resumes from step 4, not from
//   the unfinished set, and runs to step 10;
// - its statistics.csv has every step 0-10 once, and every column but
//   wall_time equals the straight run's to the last digit.
// Both runs are separate processes of the executable, as a user's are.
// The reference is the code's own straight run: a resumed run must
// reproduce it exactly, so no independent value enters.
//
// Wall time interval: a run of 4 steps with Every steps = 0 and an
// interval of a microsecond saves after every step (and keeps the two
// newest sets, steps 3 and 4); with an interval of 60 s it saves none (the
// interval counts from the run's start, not from the clock's epoch, which
// made every run save at its first step).
#include <sys/wait.h>

#include "checkpoint_test_support.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace
{

  // Writes DIRECTORY.prm and runs the executable on it in a child process
  // (with IMMERSED_GRAINS_KILL_DURING_CHECKPOINT = @p kill_at if not
  // empty); returns the child's wait status.
  int
  run(const std::string &directory,
      const double       end_time,
      const std::string &checkpoint,
      const std::string &kill_at = "")
  {
    const std::string file = directory + ".prm";
    {
      std::ofstream prm(file);
      prm << adaptive_cloud_scene << "set End time = " << end_time
          << "\nset Output directory = " << directory
          << "\nsubsection Checkpoint\n"
          << checkpoint << "end\n";
    }
    // What this process has buffered must not be written twice, by the
    // child too.
    std::cout.flush();
    std::fflush(stdout);
    const pid_t child = fork();
    if (child == 0)
    {
      if (!kill_at.empty())
        setenv("IMMERSED_GRAINS_KILL_DURING_CHECKPOINT", kill_at.c_str(), 1);
      const std::string log = directory + ".stdout";
      if (std::freopen(log.c_str(), "w", stdout) == nullptr)
        _exit(127);
      execl(IMMERSED_GRAINS_EXECUTABLE,
            IMMERSED_GRAINS_EXECUTABLE,
            file.c_str(),
            static_cast<char *>(nullptr));
      _exit(127);
    }
    int status = 0;
    waitpid(child, &status, 0);
    return status;
  }


  std::string
  checkpoint_sets(const std::string &directory)
  {
    std::vector<std::string> names;
    if (fs::is_directory(directory + "/checkpoints"))
      for (const auto &entry :
           fs::directory_iterator(directory + "/checkpoints"))
        names.push_back(entry.path().filename().string());
    std::sort(names.begin(), names.end());
    std::string list;
    for (const auto &name : names)
      list += " " + name;
    return names.empty() ? " none" : list;
  }

  std::string
  describe(const int status)
  {
    if (WIFSIGNALED(status))
      return WTERMSIG(status) == SIGKILL ? "killed by SIGKILL" :
                                           "killed by another signal";
    return "exit " + std::to_string(WEXITSTATUS(status));
  }
} // namespace


int
main()
{
  for (const char *d : {"straight", "killed", "interval", "no_interval"})
    fs::remove_all(d);
  const std::string every_two = "  set Every steps = 2\n";

  std::cout << "straight run: " << describe(run("straight", 0.5, every_two))
            << '\n';
  std::cout << "run killed while writing step 6: "
            << describe(run("killed", 0.5, every_two, "6")) << '\n';
  std::cout << "  checkpoints left:" << checkpoint_sets("killed") << '\n';
  std::cout << "  statistics rows left: "
            << read_csv_rows("killed/statistics.csv").size() - 1 << '\n';
  std::cout << "the same command again: "
            << describe(run("killed", 0.5, every_two)) << '\n';

  const auto        straight = read_csv_rows("straight/statistics.csv");
  const auto        resumed  = read_csv_rows("killed/statistics.csv");
  std::ifstream     log("killed/log.txt");
  const std::string text((std::istreambuf_iterator<char>(log)),
                         std::istreambuf_iterator<char>());
  std::cout << "  resumed from the set of step 4: "
            << (text.find("resumed from killed/checkpoints/step_00000004") !=
                    std::string::npos ?
                  "yes" :
                  "no")
            << '\n';

  // Every step once, in order.
  bool steps_once = resumed.size() == straight.size();
  for (unsigned int r = 1; r < resumed.size(); ++r)
    steps_once = steps_once && std::stod(resumed[r][0]) == r - 1;
  std::cout << "  steps 0-" << straight.size() - 2
            << " each once: " << (steps_once ? "yes" : "no") << '\n';

  unsigned int wall = 0;
  for (unsigned int c = 0; c < straight[0].size(); ++c)
    if (straight[0][c] == "wall_time")
      wall = c;
  double largest = 0;
  for (unsigned int r = 1; r < std::min(straight.size(), resumed.size()); ++r)
    for (unsigned int c = 0; c < straight[r].size(); ++c)
      if (c != wall && straight[r][c] != resumed[r][c])
      {
        const double a = std::stod(straight[r][c]);
        const double b = std::stod(resumed[r][c]);
        largest        = std::max(largest,
                           a == b ? 0.0 :
                                           std::abs(a - b) /
                                      std::max(std::abs(a), std::abs(b)));
      }
  std::cout << "  statistics equal to the straight run's exactly: "
            << (largest == 0 ? "yes" : "no") << '\n';
  if (largest > 0)
    std::cerr << "largest relative difference " << largest << '\n';
  std::cout << "  checkpoints now:" << checkpoint_sets("killed") << '\n';

  std::cout << "Wall time interval = 1e-6 s, 4 steps: "
            << describe(run("interval",
                            0.2,
                            "  set Every steps = 0\n"
                            "  set Wall time interval = 1e-6\n"))
            << ", checkpoints" << checkpoint_sets("interval") << '\n';
  std::cout << "Wall time interval = 60 s, 4 steps: "
            << describe(run("no_interval",
                            0.2,
                            "  set Every steps = 0\n"
                            "  set Wall time interval = 60\n"))
            << ", checkpoints" << checkpoint_sets("no_interval") << '\n';
}
