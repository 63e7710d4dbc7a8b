#ifndef immersed_grains_io_checkpoint_h
#define immersed_grains_io_checkpoint_h

#include <deal.II/base/mpi.h>
#include <deal.II/base/parameter_handler.h>

#include <string>

namespace ImmersedGrains
{
  /**
   * Where and when a run saves its whole state (subsection Checkpoint), and
   * which saved state a run resumes from. Each checkpoint is a directory
   * OUTPUT/checkpoints/step_NNNNNNNN written under a temporary name and
   * renamed once complete, so that a run killed while writing leaves the
   * previous complete one; the two newest are kept. What goes into it is
   * each concept's own business (Simulation::write_checkpoint()).
   */
  class Checkpoint
  {
  public:
    enum class Resume
    {
      automatic, // from the newest complete checkpoint if there is one
      always,    // from it, and fail if there is none
      never
    };

    struct Parameters
    {
      static void
      declare_parameters(dealii::ParameterHandler &prm);
      void
      parse_parameters(dealii::ParameterHandler &prm, const std::string &file);

      unsigned int every_steps  = 0;
      double       wall_seconds = 0;
      Resume       resume       = Resume::automatic;
    };

    Checkpoint(const Parameters  &parameters,
               const std::string &output_directory,
               MPI_Comm           comm);

    /** Removes the checkpoints an earlier run left (collective): a run
     *  that starts afresh writes its own history, and the sets of another
     *  would be taken for its newest. */
    void
    discard_earlier_runs() const;

    /** The newest complete checkpoint directory, or "" (collective). */
    std::string
    newest() const;

    /** Whether to write one after step @p step (collective: rank 0's wall
     *  clock decides). */
    bool
    due(unsigned int step, double wall_now) const;

    /** A fresh temporary directory for the checkpoint of @p step
     *  (collective). */
    std::string
    begin(unsigned int step) const;

    /** Renames it to its final name, removes all but the two newest
     *  (collective, after every rank has written its part) and returns
     *  the final name. */
    std::string
    commit(unsigned int step, double wall_now);

    /** Fault injection for the tests: if the environment variable
     *  IMMERSED_GRAINS_KILL_DURING_CHECKPOINT names @p step, the process
     *  kills itself with SIGKILL, as a machine or a batch system would,
     *  leaving the set it is writing unfinished. */
    static void
    maybe_die_while_writing(unsigned int step);

  private:
    const Parameters &parameters;
    std::string       directory;
    MPI_Comm          comm;
    double            last_wall = 0;
  };
} // namespace ImmersedGrains

#endif
