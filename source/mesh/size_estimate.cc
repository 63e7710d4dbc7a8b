#include <immersed_grains/mesh/size_estimate.h>

#include <unistd.h>

#include <cmath>

namespace ImmersedGrains
{
  template <int dim>
  SizeEstimate
  estimate_size(const Geometry<dim> &geometry,
                const bool           with_fluid,
                const std::size_t    n_grains)
  {
    // Measured peak resident memory (one rank, Release, doc/performance.md):
    // 2D cloud, 18,915 and 296,835 DoFs: 229 and 736 MB; 3D cloud with
    // 10,000 grains, 15,468 and 112,724 DoFs: 243 and 730 MB. Hence about
    // 200 MB of libraries and set-up, 1.9 kB per DoF in 2D and 5.2 kB in 3D
    // (the velocity block's rows hold 25 and 81 entries of the same
    // component, plus its AMG hierarchy and ILU), with a margin of 15 %.
    // A grain with its copies in the step arrays, the contact list and
    // the ghost layer: about 2 kB.
    const double base            = 200e6;
    const double bytes_per_dof   = (dim == 2 ? 1.9e3 : 5.2e3) * 1.15;
    const double bytes_per_grain = 2e3;
    const double bytes_per_cell  = 1e3; // p4est, Triangulation, grain sorting
    // With a fluid, the positions of each cell matrix's entries in the
    // matrix rows (CellScatter: 2 bytes per coupled pair of the Q2-Q1
    // cell's DoFs, 4 per DoF): 0.7 kB in 2D, 7.5 kB in 3D.
    const double bytes_per_fluid_cell = dim == 2 ? 0.75e3 : 7.5e3;

    SizeEstimate e;
    double       velocity_nodes = 1, pressure_nodes = 1;
    e.cells = 1;
    for (unsigned int d = 0; d < dim; ++d)
    {
      const double n =
        geometry.subdivisions[d] * std::pow(2.0, geometry.initial_refinement);
      e.cells *= n;
      velocity_nodes *= 2 * n + 1;
      pressure_nodes *= n + 1;
    }
    if (with_fluid)
      e.dofs = dim * velocity_nodes + pressure_nodes;
    e.peak_bytes =
      base + bytes_per_dof * e.dofs +
      (bytes_per_cell + (with_fluid ? bytes_per_fluid_cell : 0)) * e.cells +
      bytes_per_grain * n_grains;
    return e;
  }


  double
  machine_memory(MPI_Comm comm)
  {
    // One rank per machine (the lowest of those that share memory) counts
    // its machine's memory.
    MPI_Comm shared;
    MPI_Comm_split_type(comm, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &shared);
    int rank_on_machine = 0;
    MPI_Comm_rank(shared, &rank_on_machine);
    MPI_Comm_free(&shared);
    const double own = rank_on_machine == 0 ?
                         static_cast<double>(sysconf(_SC_PHYS_PAGES)) *
                           static_cast<double>(sysconf(_SC_PAGESIZE)) :
                         0.0;
    return dealii::Utilities::MPI::sum(own, comm);
  }


  template SizeEstimate
  estimate_size(const Geometry<2> &, bool, std::size_t);
  template SizeEstimate
  estimate_size(const Geometry<3> &, bool, std::size_t);
} // namespace ImmersedGrains
