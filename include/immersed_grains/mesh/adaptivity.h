#ifndef immersed_grains_mesh_adaptivity_h
#define immersed_grains_mesh_adaptivity_h

#include <deal.II/base/parameter_handler.h>
#include <deal.II/distributed/tria.h>
#include <deal.II/particles/particle_handler.h>

#include <immersed_grains/box_buckets.h>

#include <array>
#include <string>
#include <vector>

namespace ImmersedGrains
{
  template <int dim>
  class FluidSolver;
  template <int dim>
  class Geometry;

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

      bool         enabled   = false;
      unsigned int min_level = 2;
      unsigned int max_level = 5;
      // Every steps = auto: by the grains' travel (travel_allowance()),
      // and with the velocity criterion every 5 steps too.
      bool         follow_grains    = true;
      unsigned int every_steps      = 5;
      bool         around_grains    = true;
      bool         velocity_kelly   = false;
      unsigned int band_width       = 2;
      double       refine_fraction  = 0.1;
      double       coarsen_fraction = 0.3;
      double       min_cell_size    = 1; // grain diameters
      /** Solid fraction a Max-level cell's volume must hold for the grains
       *  in it to start the band (0: any grain). */
      double min_solid_fraction = 0;
      /** Band lookahead: how many finest cells the band reaches ahead of
       *  the fastest grain along its velocity (0: no lookahead). */
      double band_lookahead = 0;

      /** Whether the band looks ahead: Band lookahead > 0 where the mesh
       *  follows the grains (Criteria = grains, Every steps = auto). */
      bool
      looks_ahead() const
      {
        return band_lookahead > 0 && follow_grains && around_grains;
      }
    };

    /** @p smallest_cell: no cell is refined into children smaller than
     *  this (Minimum cell size times the largest grain diameter). */
    Adaptivity(const Parameters                                  &parameters,
               const Geometry<dim>                               &geometry,
               dealii::parallel::distributed::Triangulation<dim> &tria,
               double smallest_cell);

    /** Where the grains' properties lie (GrainPropertyLayout). */
    struct GrainProperties
    {
      unsigned int radius   = 0;
      unsigned int velocity = 0;
    };

    /**
     * Sets refine and coarsen flags on the locally owned cells and lets
     * the triangulation smooth them (prepare_coarsening_and_refinement()).
     * Returns whether any cell anywhere is flagged (collective). With
     * @p refine_only only the band's cells below Max level are flagged
     * (the further passes of one adaptation: a cell climbs one level per
     * pass, and the lookahead band reaches cells several levels coarser).
     * Without it the lookahead horizon is set anew from the grains'
     * velocities and @p shortest_edge, the mesh's shortest cell edge.
     */
    bool
    mark_cells(const dealii::Particles::ParticleHandler<dim> *grains,
               const GrainProperties                         &properties,
               const FluidSolver<dim>                        *fluid,
               double                                         shortest_edge,
               bool refine_only = false);

    /**
     * Band lookahead > 0: for how long after the last marking every
     * grain that starts the band is covered along its straight path
     * x_0 + v_0 t (the band holds it as long as it strays from that line
     * by less than travel_allowance()). 0 without lookahead, or where
     * the grains were at rest. Saved with a checkpoint.
     */
    double
    lookahead_horizon() const
    {
      return horizon;
    }
    void
    set_lookahead_horizon(const double t)
    {
      horizon = t;
    }

    /**
     * Whether the mesh should change before step @p step, when the grains
     * may have travelled @p grain_reach since the last adaptation by the
     * end of that step, on a mesh whose shortest cell edge is
     * @p shortest_edge. (@p grain_reach is ignored without Every steps =
     * auto or without grains.)
     */
    bool
    due(unsigned int step,
        double       grain_reach,
        double       shortest_edge,
        bool         with_grains) const;

    /** How far a grain may travel between two adaptations before it could
     *  leave the band: half of it, Band width / 2 cells of @p shortest_edge
     *  (the band's cells are the finest, or the grains' cells are coarser
     *  and the margin larger). */
    double
    travel_allowance(double shortest_edge) const
    {
      return 0.5 * parameters.band_width * shortest_edge;
    }

  private:
    /** For each owned cell (by active_cell_index()): 1 if it holds a
     *  grain, k + 1 if it is k layers of cells (sharing a vertex) away from
     *  one, up to band_width + 1 layers; 0 farther. Ghost values are
     *  exchanged between layers, so that the band does not depend on the
     *  partition. */
    std::vector<unsigned int>
    grain_band(const dealii::Particles::ParticleHandler<dim> &grains,
               const GrainProperties                         &properties,
               double                                         shortest_edge,
               bool                                           new_horizon);

    /** The active cell (owned, ghost or artificial) holding @p point in
     *  the box, periodic faces wrapped; the end iterator outside. */
    typename dealii::Triangulation<dim>::active_cell_iterator
    active_cell_at(dealii::Point<dim> point) const;

    /** Whether the grains in @p cell fill at least Minimum solid fraction of
     *  the volume of some cell of the finest size the cell can be refined
     *  to (Max level and the cell-size floor) within it. */
    bool
    dense_enough(
      const typename dealii::Triangulation<dim>::active_cell_iterator &cell,
      const dealii::Particles::ParticleHandler<dim>                   &grains,
      unsigned int radius_property) const;

    const Parameters                                  &parameters;
    const Geometry<dim>                               &geometry;
    dealii::parallel::distributed::Triangulation<dim> &triangulation;
    const double                                       smallest_cell;
    double                                             horizon = 0;
    /** active_cell_at() on a Gmsh mesh. */
    typename dealii::Triangulation<dim>::active_cell_iterator
    mesh_cell_at(const dealii::Point<dim> &point) const;

    /// The coarse cells (level 0) in the box's lexicographic order; for a
    /// Gmsh mesh in the triangulation's order, with their bounding boxes.
    std::vector<typename dealii::Triangulation<dim>::cell_iterator> coarse;
    std::vector<dealii::BoundingBox<dim>> coarse_boxes;
    BoxBuckets<dim>                       coarse_buckets;
  };
} // namespace ImmersedGrains

#endif
