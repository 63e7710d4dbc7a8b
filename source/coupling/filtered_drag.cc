#include <deal.II/base/quadrature_lib.h>
#include <deal.II/fe/fe_values.h>

#include <immersed_grains/coupling/filtered_drag.h>

namespace ImmersedGrains
{
  namespace
  {
    // The solid scale at the quadrature points of @p fe_values' cell; empty
    // where it is 1 everywhere.
    template <int dim>
    std::vector<double>
    scale_at(const typename FilteredDrag<dim>::SolidScale &solid_scale,
             const dealii::FEValues<dim>                  &fe_values)
    {
      if (!solid_scale)
        return {};
      const typename dealii::Triangulation<dim>::active_cell_iterator cell(
        fe_values.get_cell());
      return solid_scale(cell, fe_values.get_quadrature().get_points());
    }
  } // namespace


  template <int dim>
  FilteredDrag<dim>::FilteredDrag(
    const dealii::parallel::distributed::Triangulation<dim> &tria,
    const Geometry<dim>                                     &geometry,
    const double                                             length,
    const bool                                               drag_as_field,
    const bool                                               implicit_velocity)
      : filter(tria, geometry)
      , shapes(filter.get_fe())
      , length(length)
      , drag_as_field(drag_as_field)
      , implicit_velocity(implicit_velocity)
  {
  }


  template <int dim>
  void
  FilteredDrag<dim>::setup()
  {
    // Lumped: an M-matrix, so beta_h >= 0 wherever grains are.
    filter.setup(true, length);
    beta     = filter.make_ghosted_vector();
    alpha    = filter.make_ghosted_vector();
    mobility = filter.make_ghosted_vector();
    for (unsigned int d = 0; d < dim; ++d)
    {
      free_flux[d]         = filter.make_ghosted_vector();
      momentum[d]          = filter.make_ghosted_vector();
      velocity[d]          = filter.make_ghosted_vector();
      pressure_gradient[d] = filter.make_ghosted_vector();
    }
  }


  template <int dim>
  void
  FilteredDrag<dim>::spread(
    const std::function<
      void(const typename dealii::Triangulation<dim>::active_cell_iterator &,
           std::vector<PointDrag<dim>> &)> &drags)
  {
    auto beta_rhs     = filter.make_owned_vector();
    auto alpha_rhs    = filter.make_owned_vector();
    auto mobility_rhs = filter.make_owned_vector();
    std::array<typename HelmholtzFilter<dim>::Vector, dim> flux_rhs;
    for (auto &f : flux_rhs)
      f = filter.make_owned_vector();
    std::array<typename HelmholtzFilter<dim>::Vector, dim> momentum_rhs;
    for (auto &m : momentum_rhs)
      m = filter.make_owned_vector();

    const auto                                  &fe = filter.get_fe();
    const unsigned int                           n  = fe.n_dofs_per_cell();
    std::vector<dealii::types::global_dof_index> indices(n);
    std::vector<PointDrag<dim>>                  cell_drags;
    dealii::Vector<double> cell_beta(n), cell_alpha(n), cell_mobility(n);
    std::array<dealii::Vector<double>, dim> cell_flux;
    for (auto &f : cell_flux)
      f.reinit(n);
    std::array<dealii::Vector<double>, dim> cell_momentum;
    for (auto &m : cell_momentum)
      m.reinit(n);

    for (const auto &cell : filter.get_dof_handler().active_cell_iterators())
      if (cell->is_locally_owned())
      {
        cell_drags.clear();
        drags(cell, cell_drags);
        if (cell_drags.empty())
          continue;
        cell_beta     = 0;
        cell_alpha    = 0;
        cell_mobility = 0;
        for (auto &f : cell_flux)
          f = 0;
        for (auto &m : cell_momentum)
          m = 0;
        for (const auto &drag : cell_drags)
          for (unsigned int j = 0; j < n; ++j)
          {
            const double N = fe.shape_value(j, drag.reference_location);
            cell_beta(j) += drag.beta * N;
            cell_alpha(j) += drag.pressure_weight * N;
            cell_mobility(j) += drag.pressure_mobility * N;
            for (unsigned int d = 0; d < dim; ++d)
              cell_flux[d](j) += drag.free_flux[d] * N;
            for (unsigned int d = 0; d < dim; ++d)
              cell_momentum[d](j) += drag.beta * drag.velocity[d] * N;
          }
        filter.add_cell_contribution(cell, cell_beta, indices, beta_rhs);
        filter.add_cell_contribution(cell, cell_alpha, indices, alpha_rhs);
        filter.add_cell_contribution(cell,
                                     cell_mobility,
                                     indices,
                                     mobility_rhs);
        for (unsigned int d = 0; d < dim; ++d)
          filter.add_cell_contribution(cell,
                                       cell_flux[d],
                                       indices,
                                       flux_rhs[d]);
        for (unsigned int d = 0; d < dim; ++d)
          filter.add_cell_contribution(cell,
                                       cell_momentum[d],
                                       indices,
                                       momentum_rhs[d]);
      }
    beta_rhs.compress(dealii::VectorOperation::add);
    alpha_rhs.compress(dealii::VectorOperation::add);
    mobility_rhs.compress(dealii::VectorOperation::add);
    for (auto &f : flux_rhs)
      f.compress(dealii::VectorOperation::add);
    for (auto &m : momentum_rhs)
      m.compress(dealii::VectorOperation::add);

    if (implicit_velocity)
    {
      filter.solve(alpha_rhs, alpha);
      filter.solve(mobility_rhs, mobility);
      for (unsigned int d = 0; d < dim; ++d)
        filter.solve(flux_rhs[d], free_flux[d]);
    }
    if (!drag_as_field)
      return;
    filter.solve(beta_rhs, beta);
    for (unsigned int d = 0; d < dim; ++d)
      filter.solve(momentum_rhs[d], momentum[d]);
  }


  template <int dim>
  template <typename F>
  void
  FilteredDrag<dim>::for_each_cell(
    const dealii::DoFHandler<dim> &fluid_dof_handler,
    const F                       &f) const
  {
    const auto               &fluid_fe = fluid_dof_handler.get_fe();
    const dealii::QGauss<dim> quadrature(fluid_fe.degree + 1);
    dealii::FEValues<dim>     fluid_values(filter.get_mapping(),
                                       fluid_fe,
                                       quadrature,
                                       dealii::update_values |
                                         dealii::update_gradients |
                                         dealii::update_JxW_values);
    dealii::FEValues<dim>     filter_values(filter.get_mapping(),
                                        filter.get_fe(),
                                        quadrature,
                                        dealii::update_values);
    for (const auto &cell : fluid_dof_handler.active_cell_iterators())
      if (cell->is_locally_owned())
      {
        fluid_values.reinit(cell);
        const auto filter_cell = filter.dof_cell(cell);
        filter_values.reinit(filter_cell);
        f(fluid_values, filter_values, filter_cell);
      }
  }


  template <int dim>
  template <typename Quantity>
  void
  FilteredDrag<dim>::filter_quantity(
    const dealii::DoFHandler<dim>                          &fluid_dof_handler,
    const Quantity                                         &quantity,
    std::array<typename HelmholtzFilter<dim>::Vector, dim> &result)
  {
    std::array<typename HelmholtzFilter<dim>::Vector, dim> rhs;
    for (auto &r : rhs)
      r = filter.make_owned_vector();

    const unsigned int                  n = filter.get_fe().n_dofs_per_cell();
    std::vector<dealii::Tensor<1, dim>> values;
    std::array<dealii::Vector<double>, dim>      local;
    std::vector<dealii::types::global_dof_index> indices(n);
    for (auto &l : local)
      l.reinit(n);

    for_each_cell(fluid_dof_handler,
                  [&](const dealii::FEValues<dim> &fluid_values,
                      const dealii::FEValues<dim> &filter_values,
                      const auto                  &filter_cell)
                  {
                    values.resize(fluid_values.n_quadrature_points);
                    quantity(fluid_values, values);
                    for (auto &l : local)
                      l = 0;
                    for (unsigned int q = 0; q < values.size(); ++q)
                      for (unsigned int j = 0; j < n; ++j)
                      {
                        const double weight =
                          filter_values.shape_value(j, q) * fluid_values.JxW(q);
                        for (unsigned int d = 0; d < dim; ++d)
                          local[d](j) += values[q][d] * weight;
                      }
                    for (unsigned int d = 0; d < dim; ++d)
                      filter.add_cell_contribution(filter_cell,
                                                   local[d],
                                                   indices,
                                                   rhs[d]);
                  });
    for (unsigned int d = 0; d < dim; ++d)
    {
      rhs[d].compress(dealii::VectorOperation::add);
      filter.solve(rhs[d], result[d]);
    }
  }


  template <int dim>
  void
  FilteredDrag<dim>::filter_velocity(
    const dealii::DoFHandler<dim>                    &fluid_dof_handler,
    const dealii::TrilinosWrappers::MPI::BlockVector &fluid_solution,
    const bool                                        with_pressure_gradient,
    const SolidScale                                 &solid_scale)
  {
    const dealii::FEValuesExtractors::Vector velocities(0);
    const dealii::FEValuesExtractors::Scalar pressure(dim);
    filter_quantity(
      fluid_dof_handler,
      [&](const dealii::FEValues<dim>         &fe_values,
          std::vector<dealii::Tensor<1, dim>> &values)
      { fe_values[velocities].get_function_values(fluid_solution, values); },
      velocity);
    if (with_pressure_gradient)
      filter_quantity(
        fluid_dof_handler,
        [&](const dealii::FEValues<dim>         &fe_values,
            std::vector<dealii::Tensor<1, dim>> &values)
        {
          fe_values[pressure].get_function_gradients(fluid_solution, values);
          const auto scale = scale_at(solid_scale, fe_values);
          for (unsigned int q = 0; q < scale.size(); ++q)
            values[q] *= scale[q];
        },
        pressure_gradient);
  }


  template <int dim>
  template <std::size_t n_fields>
  std::array<std::vector<double>, n_fields>
  FilteredDrag<dim>::values_at(
    const typename dealii::Triangulation<dim>::active_cell_iterator &tria_cell,
    const std::vector<dealii::Point<dim>> &reference_points,
    const std::array<const typename HelmholtzFilter<dim>::Vector *, n_fields>
      &fields) const
  {
    const auto         cell = filter.dof_cell(tria_cell);
    const unsigned int n    = filter.get_fe().n_dofs_per_cell();
    std::vector<dealii::types::global_dof_index> indices(n);
    cell->get_dof_indices(indices);
    shapes.reinit(tria_cell, reference_points, false);
    std::vector<double>                       local(n);
    std::array<std::vector<double>, n_fields> result;
    for (std::size_t f = 0; f < n_fields; ++f)
    {
      for (unsigned int i = 0; i < n; ++i)
        local[i] = (*fields[f])[indices[i]];
      result[f].resize(reference_points.size());
      for (unsigned int q = 0; q < reference_points.size(); ++q)
        result[f][q] = shapes.value_of(local, q);
    }
    return result;
  }


  template <int dim>
  std::vector<dealii::Tensor<1, dim>>
  FilteredDrag<dim>::vector_values(
    const typename dealii::Triangulation<dim>::active_cell_iterator &cell,
    const std::vector<dealii::Point<dim>> &reference_points,
    const std::array<typename HelmholtzFilter<dim>::Vector, dim> &field) const
  {
    std::array<const typename HelmholtzFilter<dim>::Vector *, dim> fields;
    for (unsigned int d = 0; d < dim; ++d)
      fields[d] = &field[d];
    const auto values = values_at(cell, reference_points, fields);
    std::vector<dealii::Tensor<1, dim>> result(reference_points.size());
    for (unsigned int q = 0; q < result.size(); ++q)
      for (unsigned int d = 0; d < dim; ++d)
        result[q][d] = values[d][q];
    return result;
  }


  template <int dim>
  std::vector<dealii::Tensor<1, dim>>
  FilteredDrag<dim>::filtered_velocity(
    const typename dealii::Triangulation<dim>::active_cell_iterator &cell,
    const std::vector<dealii::Point<dim>> &reference_points) const
  {
    return vector_values(cell, reference_points, velocity);
  }


  template <int dim>
  std::vector<dealii::Tensor<1, dim>>
  FilteredDrag<dim>::filtered_pressure_gradient(
    const typename dealii::Triangulation<dim>::active_cell_iterator &cell,
    const std::vector<dealii::Point<dim>> &reference_points) const
  {
    return vector_values(cell, reference_points, pressure_gradient);
  }


  template <int dim>
  void
  FilteredDrag<dim>::evaluate(
    const typename dealii::Triangulation<dim>::active_cell_iterator &cell,
    const std::vector<dealii::Point<dim>> &reference_points,
    MixtureValues<dim>                    &values) const
  {
    if (implicit_velocity)
    {
      std::array<const typename HelmholtzFilter<dim>::Vector *, dim + 2>
        implicit_fields;
      implicit_fields[0] = &alpha;
      implicit_fields[1] = &mobility;
      for (unsigned int d = 0; d < dim; ++d)
        implicit_fields[d + 2] = &free_flux[d];
      const auto v = values_at(cell, reference_points, implicit_fields);
      for (unsigned int q = 0; q < reference_points.size(); ++q)
      {
        values.pressure_gradient_weight[q] = v[0][q];
        values.pressure_mobility[q]        = v[1][q];
        for (unsigned int d = 0; d < dim; ++d)
          values.solid_flux[q][d] = v[d + 2][q];
      }
    }
    if (!drag_as_field)
      return;
    std::array<const typename HelmholtzFilter<dim>::Vector *, dim + 1> fields;
    fields[0] = &beta;
    for (unsigned int d = 0; d < dim; ++d)
      fields[d + 1] = &momentum[d];
    const auto field_values = values_at(cell, reference_points, fields);
    for (unsigned int q = 0; q < reference_points.size(); ++q)
    {
      const double b             = field_values[0][q];
      values.drag_coefficient[q] = b;
      for (unsigned int d = 0; d < dim; ++d)
        values.grain_velocity[q][d] = b > 0 ? field_values[d + 1][q] / b : 0.0;
    }
  }


  template <int dim>
  dealii::Tensor<1, dim>
  FilteredDrag<dim>::force_on_fluid(
    const dealii::DoFHandler<dim>                    &fluid_dof_handler,
    const dealii::TrilinosWrappers::MPI::BlockVector &fluid_solution,
    const SolidScale                                 &solid_scale) const
  {
    const dealii::FEValuesExtractors::Vector velocities(0);
    const dealii::FEValuesExtractors::Scalar pressure(dim);
    std::vector<dealii::Tensor<1, dim>>      u, grad_p;
    std::vector<double>                      b, a;
    std::array<std::vector<double>, dim>     m;
    dealii::Tensor<1, dim>                   force;
    for_each_cell(
      fluid_dof_handler,
      [&](const dealii::FEValues<dim> &fluid_values,
          const dealii::FEValues<dim> &filter_values,
          const auto &)
      {
        const unsigned int n_q = fluid_values.n_quadrature_points;
        grad_p.resize(n_q);
        a.resize(n_q);
        fluid_values[pressure].get_function_gradients(fluid_solution, grad_p);
        filter_values.get_function_values(alpha, a);
        const auto scale = scale_at(solid_scale, fluid_values);
        for (unsigned int q = 0; q < n_q; ++q)
          force -= (scale.empty() ? 1.0 : scale[q]) * a[q] * grad_p[q] *
                   fluid_values.JxW(q);
        if (!drag_as_field)
          return;
        u.resize(n_q);
        b.resize(n_q);
        fluid_values[velocities].get_function_values(fluid_solution, u);
        filter_values.get_function_values(beta, b);
        for (unsigned int d = 0; d < dim; ++d)
        {
          m[d].resize(n_q);
          filter_values.get_function_values(momentum[d], m[d]);
        }
        for (unsigned int q = 0; q < n_q; ++q)
          for (unsigned int d = 0; d < dim; ++d)
            force[d] -= (b[q] * u[q][d] - m[d][q]) * fluid_values.JxW(q);
      });
    return dealii::Utilities::MPI::sum(
      force, fluid_dof_handler.get_triangulation().get_communicator());
  }


  template class FilteredDrag<2>;
  template class FilteredDrag<3>;
} // namespace ImmersedGrains
