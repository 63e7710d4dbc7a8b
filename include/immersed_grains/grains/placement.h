#ifndef immersed_grains_grains_placement_h
#define immersed_grains_grains_placement_h

#include <deal.II/base/point.h>
#include <deal.II/base/tensor.h>

#include <immersed_grains/grains/grain_parameters.h>
#include <immersed_grains/mesh/geometry.h>

#include <vector>

namespace ImmersedGrains
{
  /** One grain of the initial population. */
  template <int dim>
  struct GrainSeed
  {
    dealii::Point<dim>     position;
    dealii::Tensor<1, dim> velocity;
    double                 radius;
  };

  /**
   * The initial grains described by `subsection Grains/Placement`, in a
   * deterministic order (the same on every MPI rank, so the grain ids do not
   * depend on the number of ranks). Throws InputError, naming the entry, for
   * grains outside the domain, overlapping input grains, a region that
   * cannot hold the requested grains, and unreadable files.
   *
   * Random fills use random sequential addition: grains (largest first) are
   * put at uniformly drawn positions that do not overlap those already
   * placed. It jams near a solid fraction of 0.547 for equal discs and 0.38
   * for equal spheres (Feder 1980; Torquato, Uche & Stillinger 2006), in
   * practice (5000 tries per grain) lower. Grains that find no place are
   * put at random positions and overlapping pairs pushed apart until none
   * overlaps; a fill denser than the densest packing, or one that 20000
   * rounds of this leave overlapping (towards random close packing), is an
   * InputError instead of a hang.
   */
  template <int dim>
  std::vector<GrainSeed<dim>>
  place_grains(const GrainParameters<dim> &parameters,
               const Geometry<dim>        &geometry);
} // namespace ImmersedGrains

#endif
