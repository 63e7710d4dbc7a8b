#ifndef immersed_grains_coupling_filtered_drag_h
#define immersed_grains_coupling_filtered_drag_h

#include <deal.II/base/tensor.h>
#include <deal.II/lac/trilinos_parallel_block_vector.h>

#include <immersed_grains/coupling/helmholtz_filter.h>
#include <immersed_grains/fluid/mixture_fields.h>

#include <array>
#include <functional>
#include <vector>

namespace ImmersedGrains
{
  /**
   * The grains' implicit drag as a continuous field (Coupling/Drag
   * distribution = filtered). The point drags beta_i (u - v~_i) are spread
   * with the Helmholtz filter A = M_L + l^2 K of length l,
   *
   *   A beta_h = sum_i beta_i N(x_i),   A m_h = sum_i beta_i v~_i N(x_i),
   *
   * and the fluid's momentum equation gains beta_h u - m_h; each grain feels
   * the filtered fluid velocity u_bar(x_i), A u_bar = (N, u). Because A is
   * symmetric, sum_i beta_i u_bar(x_i) = (beta_h, u): the grains and the
   * fluid exchange the same momentum to round-off, and since the filter
   * acts over the physical length l instead of a cell, what a grain feels
   * of its own disturbance no longer depends on the mesh (doc/theory.md
   * section 3.4).
   */
  template <int dim>
  class FilteredDrag
  {
  public:
    FilteredDrag(const dealii::parallel::distributed::Triangulation<dim> &tria,
                 const Geometry<dim> &geometry,
                 double               length);

    /** After every mesh change. */
    void
    setup();

    /** Spreads the point drags that @p drags lists for each owned cell. */
    void
    spread(const std::function<void(
             const typename dealii::Triangulation<dim>::active_cell_iterator &,
             std::vector<PointDrag<dim>> &)> &drags);

    /** Filters the velocity of a Q2^dim-Q1 fluid solution. */
    void
    filter_velocity(
      const dealii::DoFHandler<dim>                    &fluid_dof_handler,
      const dealii::TrilinosWrappers::MPI::BlockVector &fluid_solution);

    /** The filtered velocity at points of a cell. */
    std::vector<dealii::Tensor<1, dim>>
    filtered_velocity(
      const typename dealii::Triangulation<dim>::active_cell_iterator &cell,
      const std::vector<dealii::Point<dim>> &reference_points) const;

    /** Sets the drag coefficient beta_h and the velocity m_h / beta_h. */
    void
    evaluate(
      const typename dealii::Triangulation<dim>::active_cell_iterator &cell,
      const std::vector<dealii::Point<dim>> &reference_points,
      MixtureValues<dim>                    &values) const;

    /** Integral of beta_h (u - m_h / beta_h) over the mesh: the force the
     * grains' drag exerts on the fluid, measured through the fluid's own
     * fields. */
    dealii::Tensor<1, dim>
    force_on_fluid(
      const dealii::DoFHandler<dim>                    &fluid_dof_handler,
      const dealii::TrilinosWrappers::MPI::BlockVector &fluid_solution) const;

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

    HelmholtzFilter<dim>                                   filter;
    const double                                           length;
    typename HelmholtzFilter<dim>::Vector                  beta;
    std::array<typename HelmholtzFilter<dim>::Vector, dim> momentum;
    std::array<typename HelmholtzFilter<dim>::Vector, dim> velocity;
  };
} // namespace ImmersedGrains

#endif
