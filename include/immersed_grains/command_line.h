#ifndef immersed_grains_command_line_h
#define immersed_grains_command_line_h

namespace ImmersedGrains
{
  /**
   * The executable's command line (`immersed-grains --help` lists it): runs
   * or checks a scene, or prints the parameters. Initialises and finalises
   * MPI itself, so it runs once per process. Returns the exit status: 0, 1
   * for bad input or usage (one line on standard error), 2 for a failure
   * inside the run.
   */
  int
  run_command_line(int argc, char **argv);
} // namespace ImmersedGrains

#endif
