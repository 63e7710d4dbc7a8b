#include <deal.II/base/utilities.h>

#include <immersed_grains/io/checkpoint.h>
#include <immersed_grains/io/progress_line.h>
#include <immersed_grains/parameters.h>

#include <algorithm>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <iomanip>
#include <sstream>
#include <vector>

namespace ImmersedGrains
{
  namespace
  {
    std::string
    set_name(const unsigned int step)
    {
      std::ostringstream name;
      name << "step_" << std::setw(8) << std::setfill('0') << step;
      return name.str();
    }
  } // namespace


  void
  Checkpoint::Parameters::declare_parameters(dealii::ParameterHandler &prm)
  {
    using namespace dealii::Patterns;
    prm.enter_subsection("Checkpoint");
    {
      prm.declare_entry("Every steps",
                        "0",
                        Integer(0),
                        "Save the whole state of the run after every this "
                        "many steps into OUTPUT/checkpoints/ (0: never).");
      prm.declare_entry("Wall time interval",
                        "0",
                        Double(0),
                        "Also save it when this many wall-clock seconds "
                        "have passed since the last save, or since the run "
                        "started (0: never).");
      prm.declare_entry(
        "Resume",
        "auto",
        Selection("auto|true|false"),
        "auto: continue from the newest complete checkpoint in the output "
        "directory if there is one, else start afresh; true: continue from "
        "it and fail if there is none; false: start afresh (the old "
        "checkpoints are replaced as new ones are written).");
    }
    prm.leave_subsection();
  }


  void
  Checkpoint::Parameters::parse_parameters(dealii::ParameterHandler &prm,
                                           const std::string &)
  {
    prm.enter_subsection("Checkpoint");
    {
      every_steps        = prm.get_integer("Every steps");
      wall_seconds       = prm.get_double("Wall time interval");
      const auto resumed = prm.get("Resume");
      resume             = resumed == "auto" ? Resume::automatic :
                           resumed == "true" ? Resume::always :
                                               Resume::never;
    }
    prm.leave_subsection();
  }


  Checkpoint::Checkpoint(const Parameters  &parameters,
                         const std::string &output_directory,
                         MPI_Comm           comm)
      : parameters(parameters)
      , directory(output_directory + "/checkpoints")
      , comm(comm)
      // The interval counts from the run's start: a run (or a resumed
      // one) does not save at its first step.
      , last_wall(wall_clock())
  {
  }


  void
  Checkpoint::discard_earlier_runs() const
  {
    if (dealii::Utilities::MPI::this_mpi_process(comm) == 0 &&
        std::filesystem::is_directory(directory))
    {
      std::vector<std::filesystem::path> sets;
      for (const auto &entry : std::filesystem::directory_iterator(directory))
        if (entry.path().filename().string().rfind("step_", 0) == 0)
          sets.push_back(entry.path());
      for (const auto &set : sets)
        std::filesystem::remove_all(set);
    }
    MPI_Barrier(comm);
  }


  std::string
  Checkpoint::newest() const
  {
    std::string found;
    if (dealii::Utilities::MPI::this_mpi_process(comm) == 0 &&
        std::filesystem::is_directory(directory))
    {
      std::vector<std::string> sets;
      for (const auto &entry : std::filesystem::directory_iterator(directory))
      {
        const std::string name = entry.path().filename().string();
        // Complete sets only: a temporary one was not finished.
        if (name.rfind("step_", 0) == 0 &&
            name.find(".tmp") == std::string::npos &&
            std::filesystem::exists(entry.path() / "state.txt"))
          sets.push_back(name);
      }
      std::sort(sets.begin(), sets.end());
      if (!sets.empty())
        found = directory + "/" + sets.back();
    }
    return dealii::Utilities::MPI::broadcast(comm, found, 0);
  }


  bool
  Checkpoint::due(const unsigned int step, const double wall_now) const
  {
    bool due = parameters.every_steps > 0 && step > 0 &&
               step % parameters.every_steps == 0;
    if (parameters.wall_seconds > 0 &&
        wall_now - last_wall >= parameters.wall_seconds)
      due = true;
    return dealii::Utilities::MPI::broadcast(comm, due, 0);
  }


  std::string
  Checkpoint::begin(const unsigned int step) const
  {
    const std::string path = directory + "/" + set_name(step) + ".tmp";
    if (dealii::Utilities::MPI::this_mpi_process(comm) == 0)
    {
      std::filesystem::remove_all(path);
      std::filesystem::create_directories(path);
    }
    MPI_Barrier(comm);
    return path;
  }


  std::string
  Checkpoint::commit(const unsigned int step, const double wall_now)
  {
    MPI_Barrier(comm);
    last_wall                    = wall_now;
    const std::string final_path = directory + "/" + set_name(step);
    if (dealii::Utilities::MPI::this_mpi_process(comm) != 0)
    {
      MPI_Barrier(comm);
      return final_path;
    }
    std::filesystem::remove_all(final_path);
    std::filesystem::rename(final_path + ".tmp", final_path);
    std::vector<std::string> sets;
    for (const auto &entry : std::filesystem::directory_iterator(directory))
    {
      const std::string name = entry.path().filename().string();
      if (name.rfind("step_", 0) == 0 && name.find(".tmp") == std::string::npos)
        sets.push_back(name);
    }
    std::sort(sets.begin(), sets.end());
    for (std::size_t k = 0; k + 2 < sets.size(); ++k)
      std::filesystem::remove_all(directory + "/" + sets[k]);
    MPI_Barrier(comm);
    return final_path;
  }


  void
  Checkpoint::maybe_die_while_writing(const unsigned int step)
  {
    // tests/checkpoint_killed_2d: a kill from outside cannot be timed to
    // fall inside the write.
    const char *when = std::getenv("IMMERSED_GRAINS_KILL_DURING_CHECKPOINT");
    if (when != nullptr && std::strtoul(when, nullptr, 10) == step)
      std::raise(SIGKILL);
  }
} // namespace ImmersedGrains
