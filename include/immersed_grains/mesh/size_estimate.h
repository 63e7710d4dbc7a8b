#ifndef immersed_grains_mesh_size_estimate_h
#define immersed_grains_mesh_size_estimate_h

#include <deal.II/base/mpi.h>

#include <immersed_grains/mesh/geometry.h>

#include <cstddef>
#include <vector>

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
    // Counted on the adaptive mesh around the initial grains (it is
    // larger than the initial mesh).
    bool adapted = false;
  };

  template <int dim>
  SizeEstimate
  estimate_size(const Geometry<dim> &geometry,
                bool                 with_fluid,
                std::size_t          n_grains);

  /**
   * What the grain band of an adaptive mesh refines (Adaptivity's
   * criterion `grains`): every cell below @p min_level, and on each level
   * from @p min_level up, the cells within @p band_width layers of a cell
   * that holds a grain, up to @p max_level or to the level whose children
   * would be smaller than @p smallest_cell. With @p lookahead (in finest
   * cells, Adaptivity/Band lookahead) the cells holding grains reach that
   * far along @p path_axis both ways before the layers grow, for the
   * grains' paths: where they will go is not known before they move, and
   * a path of that length along one axis stands for one in any direction.
   */
  struct GrainBand
  {
    unsigned int min_level     = 0;
    unsigned int max_level     = 0;
    unsigned int band_width    = 0;
    double       smallest_cell = 0;
    double       lookahead     = 0;
    unsigned int path_axis     = 0;
  };

  /**
   * The estimate for an adaptive mesh refined by @p band around the grains
   * at @p positions (their initial places): the larger of the initial
   * mesh (Mesh/Initial refinement) and the adapted one. The band's cells
   * are counted on the level grids without building a mesh, in
   * O(grains x band) time.
   */
  template <int dim>
  SizeEstimate
  estimate_adapted_size(const Geometry<dim>                   &geometry,
                        const GrainBand                       &band,
                        bool                                   with_fluid,
                        const std::vector<dealii::Point<dim>> &positions);

  /** Physical memory of the machines the ranks of @p comm run on, summed
   * over machines (collective). */
  double
  machine_memory(MPI_Comm comm);
} // namespace ImmersedGrains

#endif
