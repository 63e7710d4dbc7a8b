#include <immersed_grains/fluid/mixture_fields.h>

namespace ImmersedGrains
{
  template <int dim>
  void
  MixtureValues<dim>::resize(const unsigned int n)
  {
    fluid_fraction.resize(n);
    fluid_fraction_gradient.resize(n);
    drag_coefficient.resize(n);
    grain_velocity.resize(n);
    solid_flux.resize(n);
    mass_source.resize(n);
    solid_flux_divergence.assign(n, 0.0);
    pressure_gradient_weight.assign(n, 0.0);
    pressure_mobility.assign(n, 0.0);
    solid_scale.assign(n, 1.0);
    last_velocity_drag.assign(n, 0.0);
  }


  template <int dim>
  PrescribedMixtureFields<dim>::PrescribedMixtureFields(
    std::shared_ptr<dealii::Function<dim>> fluid_fraction,
    std::shared_ptr<dealii::Function<dim>> drag_coefficient,
    std::shared_ptr<dealii::Function<dim>> grain_velocity,
    std::shared_ptr<dealii::Function<dim>> mass_source)
      : fluid_fraction(fluid_fraction)
      , drag_coefficient(drag_coefficient)
      , grain_velocity(grain_velocity)
      , mass_source(mass_source)
  {
  }


  template <int dim>
  void
  PrescribedMixtureFields<dim>::evaluate(
    const typename dealii::Triangulation<dim>::active_cell_iterator &,
    const std::vector<dealii::Point<dim>> &points,
    const std::vector<dealii::Point<dim>> &,
    const double        time,
    MixtureValues<dim> &values) const
  {
    const unsigned int n = points.size();
    values.resize(n);
    fluid_fraction->set_time(time);
    drag_coefficient->set_time(time);
    grain_velocity->set_time(time);
    if (mass_source)
      mass_source->set_time(time);

    for (unsigned int q = 0; q < n; ++q)
    {
      const auto  &x                    = points[q];
      const double phi                  = fluid_fraction->value(x);
      const auto   grad_phi             = fluid_fraction->gradient(x);
      values.fluid_fraction[q]          = phi;
      values.fluid_fraction_gradient[q] = grad_phi;
      values.drag_coefficient[q]        = drag_coefficient->value(x);

      for (unsigned int d = 0; d < dim; ++d)
        values.grain_velocity[q][d] = grain_velocity->value(x, d);
      values.solid_flux[q]  = (1 - phi) * values.grain_velocity[q];
      values.mass_source[q] = mass_source ? mass_source->value(x) : 0.0;
    }
  }


  template struct MixtureValues<2>;
  template struct MixtureValues<3>;
  template class PrescribedMixtureFields<2>;
  template class PrescribedMixtureFields<3>;
} // namespace ImmersedGrains
