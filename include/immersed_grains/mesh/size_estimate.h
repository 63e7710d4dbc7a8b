#ifndef immersed_grains_mesh_size_estimate_h
#define immersed_grains_mesh_size_estimate_h

#include <deal.II/base/mpi.h>

#include <immersed_grains/mesh/geometry.h>

#include <cstddef>

namespace ImmersedGrains
{
  /**
   * What a scene will allocate, known from its parameters before anything
   * is: the cells and Taylor-Hood DoFs of the refined box, and the peak
   * memory these and the grains take, from constants measured on the
   * benchmark scenes (doc/performance.md, "Memory").
   */
  struct SizeEstimate
  {
    double cells      = 0;
    double dofs       = 0; // 0 without a fluid
    double peak_bytes = 0;
  };

  template <int dim>
  SizeEstimate
  estimate_size(const Geometry<dim> &geometry,
                bool                 with_fluid,
                std::size_t          n_grains);

  /** Physical memory of the machines the ranks of @p comm run on, summed
   * over machines (collective). */
  double
  machine_memory(MPI_Comm comm);
} // namespace ImmersedGrains

#endif
