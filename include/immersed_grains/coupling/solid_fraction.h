#ifndef immersed_grains_coupling_solid_fraction_h
#define immersed_grains_coupling_solid_fraction_h

#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/tensor.h>
#include <deal.II/distributed/tria.h>
#include <deal.II/lac/trilinos_vector.h>

#include <immersed_grains/coupling/closure_porosity.h>
#include <immersed_grains/coupling/helmholtz_filter.h>
#include <immersed_grains/fluid/mixture_fields.h>
#include <immersed_grains/mesh/cell_point_shapes.h>
#include <immersed_grains/mesh/geometry.h>

#include <array>
#include <functional>
#include <vector>

namespace ImmersedGrains
{
  /** One grain as the projection sees it. */
  template <int dim>
  struct GrainSample
  {
    dealii::Point<dim>     reference_location; // in its cell
    double                 volume;
    double                 diameter;
    dealii::Tensor<1, dim> velocity;
  };

  /**
   * The solid fraction phi_s = 1 - phi and the solid volume flux
   * (1 - phi) u_p on Q1, projected from the grains:
   *
   *   (M + l^2 K) phi_s = b,   b_j = sum_i V_i N_j(x_i),
   *
   * with M the consistent or the lumped (row-sum) mass matrix and l the
   * smoothing length (0: plain L2 projection). Since K 1 = 0 and the N_j
   * sum to one, the integral of phi_s equals the grains' total volume
   * whatever M, l, the mesh or the partition (up to the linear solver's
   * tolerance, 1e-14 relative): the projection conserves volume. The same
   * operator maps the grains' momentum-volume V_i v_i to the flux field.
   * doc/theory.md shows what the smoothing does to the field.
   */
  template <int dim>
  class SolidFraction : public MixtureFields<dim>
  {
  public:
    struct Parameters
    {
      static void
      declare_parameters(dealii::ParameterHandler &prm);
      void
      parse_parameters(dealii::ParameterHandler &prm, const std::string &file);

      /** The least fluid fraction of the field the fluid sees: the one
       *  the closure reads as Minimum fluid fraction. */
      double
      fluid_fraction_bound() const
      {
        return closure_porosity.fluid_fraction_of(min_fluid_fraction);
      }

      bool            lumped             = false;
      double          smoothing_length   = 0;
      double          min_fluid_fraction = 0.3; // of the closure's porosity
      ClosurePorosity closure_porosity;
      // Whether to project the grains' surface too, for mean_diameter():
      // set by the coupling when its drag law reads it.
      bool with_mean_diameter = false;
    };

    SolidFraction(
      const Parameters                                        &parameters,
      const Geometry<dim>                                     &geometry,
      const dealii::parallel::distributed::Triangulation<dim> &tria);

    /** (Re)builds DoFs and matrices; call after every mesh change. */
    void
    setup();

    /**
     * Fills the fields from @p samples, which lists the grains of each
     * locally owned cell; the flux only if @p with_flux (else zero: the
     * implicit coupling supplies its own). With @p with_rate the flux is
     * projected all the same, for its divergence only: the fluid
     * fraction's rate of change that the skew-symmetric advection needs
     * (MixtureValues::solid_flux_divergence).
     */
    void
    project(const std::function<void(
              const typename dealii::Triangulation<dim>::active_cell_iterator &,
              std::vector<GrainSample<dim>> &)> &samples,
            bool                                 with_flux = true,
            bool                                 with_rate = false);

    /**
     * The mixture's volume sink of grains that left through open
     * boundaries: their volumes V_k projected like phi_s (the same filter)
     * from where each was last inside, divided by the step @p dt, is the
     * mass_source -r of the fluid's continuity over the next step: the
     * water that takes their place, as much as their volume in all (the
     * projection conserves it). Without any grain (on any rank) the sink
     * is zero. @p grains: this rank's, each in a locally owned cell
     * (their velocities are not read). Collective.
     */
    void
    project_sink(
      const std::vector<
        std::pair<typename dealii::Triangulation<dim>::active_cell_iterator,
                  GrainSample<dim>>> &grains,
      double                          dt);

    /** Integral of phi_s over the mesh. */
    double
    integral() const;

    /**
     * Integral of the fluid fraction phi the mixture sees (evaluate():
     * clamped node by node), from the filter's shape integrals.
     */
    double
    fluid_volume() const;

    /** Number of Q1 nodes where phi was clamped to the minimum. */
    unsigned int
    n_clamped() const;

    /**
     * The share of the grains' volume the mixture sees at points of a cell:
     * (1 - phi) / phi_s where the fluid fraction phi is raised by the clamp
     * at the bound phi_min (in cells with a clamped node), else 1. Where the
     * fluid fraction is clamped, the solid flux, the grains' share of the
     * pressure gradient and the pressure force on the grains are scaled by it,
     * so that fluid and grains still fill the space (phi + s phi_s = 1) in the
     * mixture continuity and in the momentum balance. Empty when no node is
     * clamped (then it is 1 everywhere).
     */
    std::vector<double>
    solid_scale(
      const typename dealii::Triangulation<dim>::active_cell_iterator &cell,
      const std::vector<dealii::Point<dim>> &reference_points) const;

    /**
     * MixtureFields: phi, the Q1 field of max(1 - phi_s, min) at the nodes,
     * its gradient, the grain
     * velocity flux/phi_s, the solid flux scaled by solid_scale(); no
     * continuous drag (the grains' drag enters as point terms).
     */
    void
    evaluate(
      const typename dealii::Triangulation<dim>::active_cell_iterator &cell,
      const std::vector<dealii::Point<dim>>                           &points,
      const std::vector<dealii::Point<dim>> &reference_points,
      double                                 time,
      MixtureValues<dim>                    &values) const override;

    /**
     * The fluid fraction a grain's drag law sees at points of a cell:
     * with smoothing, the field phi_s filtered once more, A f = (N, phi_s).
     * The filtered field of one grain is the filter's Green's function,
     * singular at the grain in 3D (logarithmically in 2D), so its value
     * at the grain itself would grow without bound as the mesh is refined
     * under a fixed l; filtered twice it is bounded and converges. Clamped
     * to [Parameters::fluid_fraction_bound(), 1]; the drag law reads
     * Parameters::closure_porosity of it.
     */
    std::vector<double>
    felt_fluid_fraction(
      const typename dealii::Triangulation<dim>::active_cell_iterator &cell,
      const std::vector<dealii::Point<dim>> &reference_points) const;

    /**
     * The Sauter mean diameter of the grains around points of a cell,
     * sum V_i / sum (V_i / d_i) through the same kernel as the felt
     * fraction: the ratio of the volume field to the surface field
     * sum (V_i / d_i) N_j, projected (and filtered) alike. Kept within the
     * smallest and largest grain diameter (where both fields are small, at
     * the edge of a cloud, the ratio of two small numbers is not a mean;
     * 0 where either is not positive); exactly that diameter when all
     * grains have one. Empty unless
     * Parameters::with_mean_diameter.
     */
    std::vector<double>
    mean_diameter(
      const typename dealii::Triangulation<dim>::active_cell_iterator &cell,
      const std::vector<dealii::Point<dim>> &reference_points) const;

    const dealii::DoFHandler<dim> &
    get_dof_handler() const;

    /** Ghosted phi_s. */
    const dealii::TrilinosWrappers::MPI::Vector &
    solid_fraction() const;

  private:
    // A node's fluid fraction: 1 - @p solid, at least the bound. Not capped
    // at 1: where a consistent projection undershoots (phi_s < 0 next to a
    // cloud) the field keeps 1 - phi_s, so that its integral stays the
    // domain minus the grains' volume.
    double
    clamped_fluid_fraction(double solid) const;

    // The solid scale at a point of solid fraction @p solid and (clamped)
    // fluid fraction @p fluid_fraction.
    static double
    scale(double solid, double fluid_fraction);

    const Parameters    &parameters;
    HelmholtzFilter<dim> filter;
    // The filter's Q1 shapes at the points last asked for.
    mutable CellPointShapes<dim>                           shapes;
    typename HelmholtzFilter<dim>::Vector                  fraction;
    typename HelmholtzFilter<dim>::Vector                  felt; // smoothing
    std::array<typename HelmholtzFilter<dim>::Vector, dim> flux;
    // With_mean_diameter: sum (V_i / d_i) N_j projected, and filtered once
    // more like felt; the grains' smallest and largest diameter.
    typename HelmholtzFilter<dim>::Vector surface, felt_surface;
    // project_sink(): the departed grains' projected volume and 1 / dt
    // (0: no sink).
    typename HelmholtzFilter<dim>::Vector sink;
    double                                sink_rate = 0;
    // What the last project() made of the flux fields: the grains' flux
    // for the fluid, and/or its divergence only.
    bool         flux_for_fluid = true, flux_for_rate = false;
    double       smallest_diameter = 0, largest_diameter = 0;
    unsigned int clamped = 0;
  };
} // namespace ImmersedGrains

#endif
