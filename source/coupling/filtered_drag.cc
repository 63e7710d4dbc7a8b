#include <deal.II/base/quadrature_lib.h>
#include <deal.II/fe/fe_system.h>

#include <immersed_grains/coupling/filtered_drag.h>
#include <immersed_grains/fluid/assembly_terms.h>
#include <immersed_grains/fluid/cell_gather.h>

namespace ImmersedGrains
{
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
    beta      = filter.make_ghosted_vector();
    beta_last = filter.make_ghosted_vector();
    alpha     = filter.make_ghosted_vector();
    mobility  = filter.make_ghosted_vector();
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
    auto beta_rhs      = filter.make_owned_vector();
    auto beta_last_rhs = filter.make_owned_vector();
    auto alpha_rhs     = filter.make_owned_vector();
    auto mobility_rhs  = filter.make_owned_vector();
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
    dealii::Vector<double> cell_beta(n), cell_beta_last(n), cell_alpha(n),
      cell_mobility(n);
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
        cell_beta      = 0;
        cell_beta_last = 0;
        cell_alpha     = 0;
        cell_mobility  = 0;
        for (auto &f : cell_flux)
          f = 0;
        for (auto &m : cell_momentum)
          m = 0;
        for (const auto &drag : cell_drags)
        {
          const auto shape =
            HelmholtzFilter<dim>::shape_values(drag.reference_location);
          for (unsigned int j = 0; j < n; ++j)
          {
            const double N = shape[j];
            cell_beta(j) += drag.beta * N;
            if (drag.against_last_velocity)
              cell_beta_last(j) += drag.beta * N;
            cell_alpha(j) += drag.pressure_weight * N;
            cell_mobility(j) += drag.pressure_mobility * N;
            for (unsigned int d = 0; d < dim; ++d)
              cell_flux[d](j) += drag.free_flux[d] * N;
            for (unsigned int d = 0; d < dim; ++d)
              cell_momentum[d](j) += drag.beta * drag.velocity[d] * N;
          }
        }
        filter.add_cell_contribution(cell, cell_beta, indices, beta_rhs);
        filter.add_cell_contribution(cell,
                                     cell_beta_last,
                                     indices,
                                     beta_last_rhs);
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
    beta_last_rhs.compress(dealii::VectorOperation::add);
    // Filtered only if some grain's drag is against u^n (a norm over all
    // ranks): otherwise beta_n = 0.
    against_last = beta_last_rhs.linfty_norm() > 0;
    alpha_rhs.compress(dealii::VectorOperation::add);
    mobility_rhs.compress(dealii::VectorOperation::add);
    for (auto &f : flux_rhs)
      f.compress(dealii::VectorOperation::add);
    for (auto &m : momentum_rhs)
      m.compress(dealii::VectorOperation::add);

    std::vector<const typename HelmholtzFilter<dim>::Vector *> rhs;
    std::vector<typename HelmholtzFilter<dim>::Vector *>       fields;
    if (implicit_velocity)
    {
      rhs    = {&alpha_rhs, &mobility_rhs};
      fields = {&alpha, &mobility};
      for (unsigned int d = 0; d < dim; ++d)
      {
        rhs.push_back(&flux_rhs[d]);
        fields.push_back(&free_flux[d]);
      }
    }
    if (drag_as_field)
    {
      rhs.push_back(&beta_rhs);
      fields.push_back(&beta);
      if (against_last)
      {
        rhs.push_back(&beta_last_rhs);
        fields.push_back(&beta_last);
      }
      for (unsigned int d = 0; d < dim; ++d)
      {
        rhs.push_back(&momentum_rhs[d]);
        fields.push_back(&momentum[d]);
      }
    }
    if (!rhs.empty())
      filter.solve(rhs, fields);
  }


  template <int dim>
  template <typename F>
  void
  FilteredDrag<dim>::for_each_cell(
    const dealii::DoFHandler<dim>                    &fluid_dof_handler,
    const CellGather<dim>                            &gather,
    const dealii::TrilinosWrappers::MPI::BlockVector &fluid_solution,
    const bool                                        with_velocity,
    const F                                          &f) const
  {
    const auto &fluid_fe =
      dynamic_cast<const dealii::FESystem<dim> &>(fluid_dof_handler.get_fe());
    const ScalarDofs<dim>     dofs(fluid_fe);
    const dealii::QGauss<dim> quadrature(fluid_fe.degree + 1);
    const unsigned int        n_q = quadrature.size();
    // Reference values kept across cells (CellPointShapes): a cell costs
    // its Jacobians.
    CellPointShapes<dim> velocity_shapes(fluid_fe.base_element(0)),
      pressure_shapes(fluid_fe.base_element(1)), filter_shapes(filter.get_fe());
    CellQuadrature data;
    data.reference_points = quadrature.get_points();
    data.filter_shapes    = &filter_shapes;
    data.velocity.resize(n_q);
    data.pressure_gradient.resize(n_q);
    data.JxW.resize(n_q);

    std::vector<double>                  local(fluid_fe.n_dofs_per_cell());
    std::array<std::vector<double>, dim> velocity;
    for (auto &v : velocity)
      v.resize(dofs.velocity.size());
    std::vector<double> pressure(dofs.pressure.size());
    for (const auto &cell : fluid_dof_handler.active_cell_iterators())
    {
      if (!cell->is_locally_owned())
        continue;
      const bool owned = gather.gather(cell, fluid_solution, local);
      Assert(owned, dealii::ExcInternalError());
      (void)owned;
      if (with_velocity)
        for (unsigned int a = 0; a < dofs.velocity.size(); ++a)
          for (unsigned int c = 0; c < dim; ++c)
            velocity[c][a] = local[dofs.velocity[a][c]];
      for (unsigned int b = 0; b < dofs.pressure.size(); ++b)
        pressure[b] = local[dofs.pressure[b]];
      if (with_velocity)
        velocity_shapes.reinit(cell, data.reference_points, false);
      pressure_shapes.reinit(cell, data.reference_points, true);
      filter_shapes.reinit(cell, data.reference_points, false);
      for (unsigned int q = 0; q < n_q; ++q)
      {
        data.JxW[q] =
          quadrature.weight(q) * pressure_shapes.jacobian_determinant(q);
        if (with_velocity)
          for (unsigned int c = 0; c < dim; ++c)
            data.velocity[q][c] = velocity_shapes.value_of(velocity[c], q);
        data.pressure_gradient[q] = pressure_shapes.gradient_of(pressure, q);
      }
      data.filter_cell = filter.dof_cell(cell);
      f(typename dealii::Triangulation<dim>::active_cell_iterator(cell), data);
    }
  }


  template <int dim>
  void
  FilteredDrag<dim>::filter_fluid(
    const dealii::DoFHandler<dim>                    &fluid_dof_handler,
    const CellGather<dim>                            &gather,
    const dealii::TrilinosWrappers::MPI::BlockVector &fluid_solution,
    const bool                                        with_velocity,
    const bool                                        with_pressure_gradient,
    const SolidScale                                 &solid_scale)
  {
    if (!with_velocity && !with_pressure_gradient)
      return;
    // (N_j, u) and (N_j, s grad p) in one pass over the cells.
    std::array<typename HelmholtzFilter<dim>::Vector, dim> velocity_rhs,
      pressure_rhs;
    for (unsigned int d = 0; d < dim; ++d)
    {
      if (with_velocity)
        velocity_rhs[d] = filter.make_owned_vector();
      if (with_pressure_gradient)
        pressure_rhs[d] = filter.make_owned_vector();
    }

    const unsigned int n = filter.get_fe().n_dofs_per_cell();
    std::array<dealii::Vector<double>, dim>      local_velocity, local_pressure;
    std::vector<dealii::types::global_dof_index> indices(n);
    for (unsigned int d = 0; d < dim; ++d)
    {
      local_velocity[d].reinit(n);
      local_pressure[d].reinit(n);
    }
    for_each_cell(fluid_dof_handler,
                  gather,
                  fluid_solution,
                  with_velocity,
                  [&](const auto &cell, const CellQuadrature &data)
                  {
                    const std::vector<double> scale =
                      with_pressure_gradient && solid_scale ?
                        solid_scale(cell, data.reference_points) :
                        std::vector<double>();
                    for (unsigned int d = 0; d < dim; ++d)
                    {
                      local_velocity[d] = 0;
                      local_pressure[d] = 0;
                    }
                    for (unsigned int q = 0; q < data.JxW.size(); ++q)
                    {
                      const dealii::Tensor<1, dim> grad_p =
                        scale.empty() ? data.pressure_gradient[q] :
                                        scale[q] * data.pressure_gradient[q];
                      for (unsigned int j = 0; j < n; ++j)
                      {
                        const double weight =
                          data.filter_shapes->value(j, q) * data.JxW[q];
                        if (with_velocity)
                          for (unsigned int d = 0; d < dim; ++d)
                            local_velocity[d](j) +=
                              data.velocity[q][d] * weight;
                        if (with_pressure_gradient)
                          for (unsigned int d = 0; d < dim; ++d)
                            local_pressure[d](j) += grad_p[d] * weight;
                      }
                    }
                    for (unsigned int d = 0; d < dim; ++d)
                    {
                      if (with_velocity)
                        filter.add_cell_contribution(data.filter_cell,
                                                     local_velocity[d],
                                                     indices,
                                                     velocity_rhs[d]);
                      if (with_pressure_gradient)
                        filter.add_cell_contribution(data.filter_cell,
                                                     local_pressure[d],
                                                     indices,
                                                     pressure_rhs[d]);
                    }
                  });
    std::vector<const typename HelmholtzFilter<dim>::Vector *> rhs;
    std::vector<typename HelmholtzFilter<dim>::Vector *>       fields;
    if (with_velocity)
      for (unsigned int d = 0; d < dim; ++d)
      {
        velocity_rhs[d].compress(dealii::VectorOperation::add);
        rhs.push_back(&velocity_rhs[d]);
        fields.push_back(&velocity[d]);
      }
    if (with_pressure_gradient)
      for (unsigned int d = 0; d < dim; ++d)
      {
        pressure_rhs[d].compress(dealii::VectorOperation::add);
        rhs.push_back(&pressure_rhs[d]);
        fields.push_back(&pressure_gradient[d]);
      }
    filter.solve(rhs, fields);
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
    if (against_last)
    {
      const auto last = values_at<1>(cell, reference_points, {{&beta_last}});
      values.last_velocity_drag = last[0];
    }
  }


  template <int dim>
  dealii::Tensor<1, dim>
  FilteredDrag<dim>::force_on_fluid(
    const dealii::DoFHandler<dim>                    &fluid_dof_handler,
    const CellGather<dim>                            &gather,
    const dealii::TrilinosWrappers::MPI::BlockVector &fluid_solution,
    const SolidScale                                 &solid_scale) const
  {
    const unsigned int n = filter.get_fe().n_dofs_per_cell();
    std::vector<dealii::types::global_dof_index> indices(n);
    // The filtered fields' coefficients on the cell: alpha, beta, m.
    std::vector<double>                  local_alpha(n), local_beta(n);
    std::array<std::vector<double>, dim> local_momentum;
    for (auto &m : local_momentum)
      m.resize(n);
    dealii::Tensor<1, dim> force;
    for_each_cell(fluid_dof_handler,
                  gather,
                  fluid_solution,
                  drag_as_field,
                  [&](const auto &cell, const CellQuadrature &data)
                  {
                    data.filter_cell->get_dof_indices(indices);
                    for (unsigned int j = 0; j < n; ++j)
                    {
                      local_alpha[j] = alpha[indices[j]];
                      if (drag_as_field)
                      {
                        local_beta[j] = beta[indices[j]];
                        for (unsigned int d = 0; d < dim; ++d)
                          local_momentum[d][j] = momentum[d][indices[j]];
                      }
                    }
                    const std::vector<double> scale =
                      solid_scale ? solid_scale(cell, data.reference_points) :
                                    std::vector<double>();
                    for (unsigned int q = 0; q < data.JxW.size(); ++q)
                    {
                      double                 a = 0, b = 0;
                      dealii::Tensor<1, dim> m;
                      for (unsigned int j = 0; j < n; ++j)
                      {
                        const double psi = data.filter_shapes->value(j, q);
                        a += local_alpha[j] * psi;
                        if (drag_as_field)
                        {
                          b += local_beta[j] * psi;
                          for (unsigned int d = 0; d < dim; ++d)
                            m[d] += local_momentum[d][j] * psi;
                        }
                      }
                      force -= (scale.empty() ? 1.0 : scale[q]) * a *
                               data.pressure_gradient[q] * data.JxW[q];
                      if (drag_as_field)
                        for (unsigned int d = 0; d < dim; ++d)
                          force[d] -=
                            (b * data.velocity[q][d] - m[d]) * data.JxW[q];
                    }
                  });
    return dealii::Utilities::MPI::sum(
      force, fluid_dof_handler.get_triangulation().get_communicator());
  }


  template class FilteredDrag<2>;
  template class FilteredDrag<3>;
} // namespace ImmersedGrains
