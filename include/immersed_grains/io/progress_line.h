#ifndef immersed_grains_io_progress_line_h
#define immersed_grains_io_progress_line_h

#include <string>

namespace ImmersedGrains
{
  class RunLog;

  /**
   * The run's progress line on rank 0: simulated time, step, what the
   * caller adds, wall time and the remaining wall time estimated from the
   * pace so far. Rewritten in place four times a second on a terminal;
   * elsewhere (a file, a pipe, mpirun, CI) a line every Progress every
   * seconds.
   */
  class ProgressLine
  {
  public:
    /** @p enabled: rank 0 with Terminal output = normal. */
    ProgressLine(RunLog &log, double interval_seconds, bool enabled);

    /** Starts the clock: @p wall_start, the run's start (wall seconds);
     *  @p start_time, the simulated time it starts from. */
    void
    start(double wall_start, double start_time);

    /** Whether a line is due now (@p last: the run's last one, written
     *  unless one was written less than a second ago off a terminal);
     *  true also marks it written. */
    bool
    due(bool last);

    /** "t = T / END s, step N" + @p details + wall time and ETA. */
    void
    print(double             time,
          double             end_time,
          unsigned int       step,
          const std::string &details,
          bool               last);

  private:
    RunLog      &log;
    const double interval_seconds;
    const bool   enabled;
    double       wall_start = 0;
    double       start_time = 0;
    double       last_wall  = 0;
  };

  /** Wall-clock seconds (steady clock). */
  double
  wall_clock();
} // namespace ImmersedGrains

#endif
