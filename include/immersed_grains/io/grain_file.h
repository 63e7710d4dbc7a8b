#ifndef immersed_grains_io_grain_file_h
#define immersed_grains_io_grain_file_h

#include <deal.II/base/mpi.h>

#include <string>

namespace ImmersedGrains
{
  template <int dim>
  class Grains;

  /**
   * Writes every grain as a line 'x y [z] r vx vy [vz]' in the order of
   * their ids, the format Grains/Placement/Shape = file reads: a packing
   * one run prepares (poured, settled, compacted) is the initial state of
   * the next. Seventeen significant digits, so the positions read back
   * are the ones written. Rank 0 writes (collective); the file appears
   * whole or not at all (written beside, then renamed).
   */
  template <int dim>
  void
  write_grain_file(const Grains<dim> &grains,
                   const std::string &file_name,
                   double             time,
                   MPI_Comm           comm);
} // namespace ImmersedGrains

#endif
