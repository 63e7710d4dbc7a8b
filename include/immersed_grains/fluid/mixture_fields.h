#ifndef immersed_grains_fluid_mixture_fields_h
#define immersed_grains_fluid_mixture_fields_h

#include <deal.II/base/function.h>
#include <deal.II/base/point.h>
#include <deal.II/base/tensor.h>
#include <deal.II/grid/tria.h>

#include <memory>
#include <vector>

namespace ImmersedGrains
{
  /**
   * What the fluid sees of the grains at the quadrature points of one cell:
   * fluid fraction phi and its gradient, a continuous drag coefficient beta,
   * the grain velocity u_p, and the solid volume flux (1 - phi) u_p that
   * enters the mixture continuity equation.
   */
  template <int dim>
  struct MixtureValues
  {
    void
    resize(unsigned int n);

    std::vector<double>                 fluid_fraction;
    std::vector<dealii::Tensor<1, dim>> fluid_fraction_gradient;
    std::vector<double>                 drag_coefficient;
    std::vector<dealii::Tensor<1, dim>> grain_velocity;
    std::vector<dealii::Tensor<1, dim>> solid_flux; // (1 - phi) u_p
    std::vector<double>                 mass_source;
    // div of the grains' filtered volume flux at the start of the step:
    // -d(phi_s)/dt of the projection, the fluid fraction's rate of change
    // (the skew-symmetric advection form; 0 without grains).
    std::vector<double> solid_flux_divergence;
    // With the grains' velocity implicit (doc/theory.md 3): the momentum
    // equation gains alpha grad p (the pressure force on grains tied to the
    // fluid by drag), and the solid flux is s + alpha u - k grad p.
    std::vector<double> pressure_gradient_weight; // alpha
    std::vector<double> pressure_mobility;        // k
    // The share of the grains' volume the mixture sees: below 1 only where
    // the fluid fraction is clamped (SolidFraction::solid_scale()); the
    // fields above already include it.
    std::vector<double> solid_scale;
    // The share of the drag coefficient above whose implicit part is
    // taken against the last step's velocity u^n (the filtered drag's
    // deferred correction for free grains, doc/theory.md "Drag
    // distributions"): the momentum equation gains beta u - beta_n u^n -
    // beta u_p, where beta u_p already leaves out what those grains felt
    // of u^n.
    std::vector<double> last_velocity_drag; // beta_n
  };


  /**
   * The source of MixtureValues. Prescribed fields (functions in the .prm,
   * or exact solutions in a test) and the fields projected from grains are
   * two implementations; the fluid solver does not know which it has.
   */
  template <int dim>
  class MixtureFields
  {
  public:
    virtual ~MixtureFields() = default;

    /**
     * Values at @p points (physical) of @p cell, whose coordinates in the
     * reference cell are @p reference_points.
     */
    virtual void
    evaluate(
      const typename dealii::Triangulation<dim>::active_cell_iterator &cell,
      const std::vector<dealii::Point<dim>>                           &points,
      const std::vector<dealii::Point<dim>> &reference_points,
      double                                 time,
      MixtureValues<dim>                    &values) const = 0;
  };


  /**
   * Mixture fields given as functions of space and time. The gradient of
   * the fluid fraction and the divergence of the grain velocity come from
   * the functions' gradient(), so exact functions give exact coefficients.
   */
  template <int dim>
  class PrescribedMixtureFields : public MixtureFields<dim>
  {
  public:
    PrescribedMixtureFields(
      std::shared_ptr<dealii::Function<dim>> fluid_fraction,
      std::shared_ptr<dealii::Function<dim>> drag_coefficient,
      std::shared_ptr<dealii::Function<dim>> grain_velocity,
      std::shared_ptr<dealii::Function<dim>> mass_source = nullptr);

    void
    evaluate(
      const typename dealii::Triangulation<dim>::active_cell_iterator &cell,
      const std::vector<dealii::Point<dim>>                           &points,
      const std::vector<dealii::Point<dim>> &reference_points,
      double                                 time,
      MixtureValues<dim>                    &values) const override;

  private:
    std::shared_ptr<dealii::Function<dim>> fluid_fraction;
    std::shared_ptr<dealii::Function<dim>> drag_coefficient;
    std::shared_ptr<dealii::Function<dim>> grain_velocity;
    std::shared_ptr<dealii::Function<dim>> mass_source;
  };

  /**
   * A grain's implicit drag on the fluid: the momentum equation gains
   * beta_i (u(x_i) - v_i) delta(x - x_i), tested with the velocity shape
   * functions at x_i (deal.II step-70's way of putting particles into an
   * FE equation); beta_i u is assembled into the matrix, so the drag is
   * implicit in the fluid as it is in the grains.
   */
  template <int dim>
  struct PointDrag
  {
    dealii::Point<dim>     reference_location; // in its cell
    double                 beta;               // [kg/s]
    dealii::Tensor<1, dim> velocity;           // v_i
    // With the grain's new velocity eliminated into the fluid solve
    // (Coupling, doc/theory.md 3): theta_i = dt gamma_i / (m_i + dt gamma_i)
    // of its volume follows the fluid, alpha_i = V_i theta_i [m^3]; its
    // pressure mobility k_i = dt V_i^2 / (m_i + dt gamma_i) [m^4 s/kg]; and
    // the rest of its volume flux, V_i (1 - theta_i) v~_i [m^4/s].
    double                 pressure_weight   = 0;
    double                 pressure_mobility = 0;
    dealii::Tensor<1, dim> free_flux;
    // Whether @p velocity is less the velocity the grain felt of the last
    // step's fluid, so that the fluid's implicit drag for it is
    // beta (u - u^n) (FilteredDrag, doc/theory.md "Drag distributions").
    bool against_last_velocity = false;
  };


  /** Lists the point drags of one cell (the grains in it). */
  template <int dim>
  class PointDragSource
  {
  public:
    virtual ~PointDragSource() = default;

    virtual void
    point_drags(
      const typename dealii::Triangulation<dim>::active_cell_iterator &cell,
      std::vector<PointDrag<dim>> &drags) const = 0;
  };
} // namespace ImmersedGrains

#endif
