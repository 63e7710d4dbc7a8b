// immersed-grains: the executable (source/command_line.cc).
#include <immersed_grains/command_line.h>

int
main(int argc, char **argv)
{
  return ImmersedGrains::run_command_line(argc, argv);
}
