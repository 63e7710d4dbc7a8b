#ifndef immersed_grains_mesh_adaptivity_h
#define immersed_grains_mesh_adaptivity_h

#include <deal.II/base/parameter_handler.h>
#include <deal.II/distributed/tria.h>
#include <deal.II/particles/particle_handler.h>

#include <string>

namespace ImmersedGrains
{
  template <int dim>
  class FluidSolver;

  /**
   * Where the mesh is refined and coarsened (subsection Adaptivity): cells
   * around the grains (a band of Band width cell layers around every cell
   * holding a grain) go to Max level, the rest back to Min level, and
   * optionally the Kelly estimator of the fluid velocity refines and
   * coarsens fixed fractions of the cells in between. This class only sets
   * the flags; each concept moves its own state across the change
   * (FluidSolver, Grains, Coupling), the simulation strings them together.
   */
  template <int dim>
  class Adaptivity
  {
  public:
    struct Parameters
    {
      static void
      declare_parameters(dealii::ParameterHandler &prm);
      void
      parse_parameters(dealii::ParameterHandler &prm,
                       const std::string        &file,
                       bool                      fluid_enabled);

      bool         enabled          = false;
      unsigned int min_level        = 2;
      unsigned int max_level        = 5;
      unsigned int every_steps      = 5;
      bool         around_grains    = true;
      bool         velocity_kelly   = false;
      unsigned int band_width       = 2;
      double       refine_fraction  = 0.1;
      double       coarsen_fraction = 0.3;
      double       min_cell_size    = 1; // grain diameters
    };

    /** @p smallest_cell: no cell is refined into children smaller than
     *  this (Minimum cell size times the largest grain diameter). */
    Adaptivity(const Parameters                                  &parameters,
               dealii::parallel::distributed::Triangulation<dim> &tria,
               double smallest_cell);

    /**
     * Sets refine and coarsen flags on the locally owned cells and lets
     * the triangulation smooth them (prepare_coarsening_and_refinement()).
     * Returns whether any cell anywhere is flagged (collective).
     */
    bool
    mark_cells(const dealii::Particles::ParticleHandler<dim> *grains,
               const FluidSolver<dim>                        *fluid);

    /** Whether the mesh should change before step @p step. */
    bool
    due(unsigned int step) const
    {
      return parameters.enabled && parameters.every_steps > 0 &&
             step % parameters.every_steps == 0;
    }

  private:
    /** For each owned cell (by active_cell_index()): 1 if it holds a
     *  grain, k + 1 if it is k layers of cells (sharing a vertex) away from
     *  one, up to band_width + 1 layers; 0 farther. Ghost values are
     *  exchanged between layers, so that the band does not depend on the
     *  partition. */
    std::vector<unsigned int>
    grain_band(const dealii::Particles::ParticleHandler<dim> &grains) const;

    const Parameters                                  &parameters;
    dealii::parallel::distributed::Triangulation<dim> &triangulation;
    const double                                       smallest_cell;
  };
} // namespace ImmersedGrains

#endif
