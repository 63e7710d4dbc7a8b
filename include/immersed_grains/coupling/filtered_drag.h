#ifndef immersed_grains_coupling_filtered_drag_h
#define immersed_grains_coupling_filtered_drag_h

#include <deal.II/base/tensor.h>
#include <deal.II/lac/trilinos_parallel_block_vector.h>

#include <immersed_grains/coupling/helmholtz_filter.h>
#include <immersed_grains/fluid/mixture_fields.h>
#include <immersed_grains/mesh/cell_point_shapes.h>

#include <array>
#include <functional>
#include <vector>

namespace ImmersedGrains
{
  template <int dim>
  class CellGather;

  /**
   * The grains' implicit drag as a continuous field (Coupling/Drag
   * distribution = filtered). The point drags beta_i (u - v~_i) are spread
   * with the Helmholtz filter A = M_L + l^2 K of length l,
   *
   *   A beta_h = sum_i beta_i N(x_i),   A m_h = sum_i beta_i v~_i N(x_i),
   *
   * and the fluid's momentum equation gains beta_h u - m_h. Drags marked
   * PointDrag::against_last_velocity are also spread into beta_n, and the
   * equation gains - beta_n u^n: their v~_i is already less the velocity
   * they felt of u^n (doc/theory.md "Drag distributions"). Each grain feels
   * the filtered fluid velocity u_bar(x_i), A u_bar = (N, u). Because A is
   * symmetric, sum_i beta_i u_bar(x_i) = (beta_h, u): the grains and the
   * fluid exchange the same momentum to round-off, and since the filter
   * acts over the physical length l instead of a cell, what a grain feels
   * of its own disturbance no longer depends on the mesh (doc/theory.md
   * section 3).
   *
   * With the grains' new velocity eliminated into the fluid solve
   * (@p implicit_velocity, doc/theory.md 3), the weights alpha_i, the
   * mobilities k_i and the free fluxes of PointDrag are spread the same
   * way: the fluid's momentum equation gains alpha_h grad p and the solid
   * flux becomes s_h + alpha_h u - k_h grad p. That part is used with
   * every Drag distribution (@p drag_as_field false: only it).
   */
  template <int dim>
  class FilteredDrag
  {
  public:
    /**
     * The share of the grains' volume the mixture sees at points of a cell
     * (SolidFraction::solid_scale(); empty: 1 everywhere).
     */
    using SolidScale = std::function<std::vector<double>(
      const typename dealii::Triangulation<dim>::active_cell_iterator &,
      const std::vector<dealii::Point<dim>> &)>;

    FilteredDrag(const dealii::parallel::distributed::Triangulation<dim> &tria,
                 const Geometry<dim> &geometry,
                 double               length,
                 bool                 drag_as_field,
                 bool                 implicit_velocity);

    /** After every mesh change. */
    void
    setup();

    /** Spreads the point drags that @p drags lists for each owned cell. */
    void
    spread(const std::function<void(
             const typename dealii::Triangulation<dim>::active_cell_iterator &,
             std::vector<PointDrag<dim>> &)> &drags);

    /** Filters the velocity (if @p with_velocity) and the pressure
     * gradient times @p solid_scale, the force per volume on the grains
     * (if @p with_pressure_gradient), of a Q2^dim-Q1 fluid solution, read
     * cell by cell through @p gather (FluidSolver::get_cell_gather()). */
    void
    filter_fluid(
      const dealii::DoFHandler<dim>                    &fluid_dof_handler,
      const CellGather<dim>                            &gather,
      const dealii::TrilinosWrappers::MPI::BlockVector &fluid_solution,
      bool                                              with_velocity,
      bool                                              with_pressure_gradient,
      const SolidScale &solid_scale = SolidScale());

    /** The filtered velocity at points of a cell. */
    std::vector<dealii::Tensor<1, dim>>
    filtered_velocity(
      const typename dealii::Triangulation<dim>::active_cell_iterator &cell,
      const std::vector<dealii::Point<dim>> &reference_points) const;

    /** The filtered pressure gradient at points of a cell. */
    std::vector<dealii::Tensor<1, dim>>
    filtered_pressure_gradient(
      const typename dealii::Triangulation<dim>::active_cell_iterator &cell,
      const std::vector<dealii::Point<dim>> &reference_points) const;

    /** Sets alpha_h, and with the drag as a field the drag coefficient
     * beta_h and the velocity m_h / beta_h. */
    void
    evaluate(
      const typename dealii::Triangulation<dim>::active_cell_iterator &cell,
      const std::vector<dealii::Point<dim>> &reference_points,
      MixtureValues<dim>                    &values) const;

    /** Minus the integral of beta_h u - m_h (with the drag as a field) and
     * of s alpha_h grad p (s = @p solid_scale) over the mesh: the force the
     * grains' drag exerts on the fluid, measured through the fluid's own
     * fields. */
    dealii::Tensor<1, dim>
    force_on_fluid(
      const dealii::DoFHandler<dim>                    &fluid_dof_handler,
      const CellGather<dim>                            &gather,
      const dealii::TrilinosWrappers::MPI::BlockVector &fluid_solution,
      const SolidScale &solid_scale = SolidScale()) const;

  private:
    // Values of the Q1 fields @p fields at points of a cell, one vector per
    // field.
    template <std::size_t n_fields>
    std::array<std::vector<double>, n_fields>
    values_at(
      const typename dealii::Triangulation<dim>::active_cell_iterator &cell,
      const std::vector<dealii::Point<dim>> &reference_points,
      const std::array<const typename HelmholtzFilter<dim>::Vector *, n_fields>
        &fields) const;

    // The fluid's velocity and pressure gradient, and the filter's shape
    // functions, at the fluid's Gauss points of one cell (which integrate
    // Q1 x Q2 x Q2 exactly).
    struct CellQuadrature
    {
      std::vector<dealii::Tensor<1, dim>> velocity, pressure_gradient;
      std::vector<double>                 JxW;
      // The filter's shape functions at the points.
      const CellPointShapes<dim>                            *filter_shapes;
      std::vector<dealii::Point<dim>>                        reference_points;
      typename dealii::DoFHandler<dim>::active_cell_iterator filter_cell;
    };

    // Calls @p f(cell, quadrature) on each locally owned cell: the shape
    // functions through CellPointShapes (reference values kept across
    // cells) and the fluid's coefficients through @p gather, instead of two
    // FEValues::reinit and a look-up in Epetra's map per DoF and cell. The
    // velocity only @p with_velocity (its Q2 shapes cost most).
    template <typename F>
    void
    for_each_cell(
      const dealii::DoFHandler<dim>                    &fluid_dof_handler,
      const CellGather<dim>                            &gather,
      const dealii::TrilinosWrappers::MPI::BlockVector &fluid_solution,
      bool                                              with_velocity,
      const F                                          &f) const;

    std::vector<dealii::Tensor<1, dim>>
    vector_values(
      const typename dealii::Triangulation<dim>::active_cell_iterator &cell,
      const std::vector<dealii::Point<dim>> &reference_points,
      const std::array<typename HelmholtzFilter<dim>::Vector, dim> &) const;

    HelmholtzFilter<dim> filter;

    // The filter's Q1 shapes at the points last asked for.
    mutable CellPointShapes<dim> shapes;
    const double                 length;
    const bool                   drag_as_field;
    const bool                   implicit_velocity;
    // Whether beta_n was filtered in the last spread() (some drag was
    // against the last step's velocity).
    bool against_last = false;
    // beta_n: the part of beta from drags against the last step's velocity.
    typename HelmholtzFilter<dim>::Vector beta, beta_last, alpha, mobility;
    std::array<typename HelmholtzFilter<dim>::Vector, dim> free_flux;
    std::array<typename HelmholtzFilter<dim>::Vector, dim> momentum;
    std::array<typename HelmholtzFilter<dim>::Vector, dim> velocity;
    std::array<typename HelmholtzFilter<dim>::Vector, dim> pressure_gradient;
  };
} // namespace ImmersedGrains

#endif
