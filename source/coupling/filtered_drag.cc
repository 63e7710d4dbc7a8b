#include <deal.II/base/quadrature_lib.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/matrix_free/fe_point_evaluation.h>

#include <immersed_grains/coupling/filtered_drag.h>

namespace ImmersedGrains
{
  template <int dim>
  FilteredDrag<dim>::FilteredDrag(
    const dealii::parallel::distributed::Triangulation<dim> &tria,
    const Geometry<dim>                                     &geometry,
    const double                                             length)
      : filter(tria, geometry)
      , length(length)
  {
  }


  template <int dim>
  void
  FilteredDrag<dim>::setup()
  {
    // Lumped: an M-matrix, so beta_h >= 0 wherever grains are.
    filter.setup(true, length);
    beta = filter.make_ghosted_vector();
    for (unsigned int d = 0; d < dim; ++d)
    {
      momentum[d] = filter.make_ghosted_vector();
      velocity[d] = filter.make_ghosted_vector();
    }
  }


  template <int dim>
  void
  FilteredDrag<dim>::spread(
    const std::function<
      void(const typename dealii::Triangulation<dim>::active_cell_iterator &,
           std::vector<PointDrag<dim>> &)> &drags)
  {
    auto beta_rhs = filter.make_owned_vector();
    std::array<typename HelmholtzFilter<dim>::Vector, dim> momentum_rhs;
    for (auto &m : momentum_rhs)
      m = filter.make_owned_vector();

    const auto                                  &fe = filter.get_fe();
    const unsigned int                           n  = fe.n_dofs_per_cell();
    std::vector<dealii::types::global_dof_index> indices(n);
    std::vector<PointDrag<dim>>                  cell_drags;
    dealii::Vector<double>                       cell_beta(n);
    std::array<dealii::Vector<double>, dim>      cell_momentum;
    for (auto &m : cell_momentum)
      m.reinit(n);

    for (const auto &cell : filter.get_dof_handler().active_cell_iterators())
      if (cell->is_locally_owned())
      {
        cell_drags.clear();
        drags(cell, cell_drags);
        if (cell_drags.empty())
          continue;
        cell_beta = 0;
        for (auto &m : cell_momentum)
          m = 0;
        for (const auto &drag : cell_drags)
          for (unsigned int j = 0; j < n; ++j)
          {
            const double N = fe.shape_value(j, drag.reference_location);
            cell_beta(j) += drag.beta * N;
            for (unsigned int d = 0; d < dim; ++d)
              cell_momentum[d](j) += drag.beta * drag.velocity[d] * N;
          }
        filter.add_cell_contribution(cell, cell_beta, indices, beta_rhs);
        for (unsigned int d = 0; d < dim; ++d)
          filter.add_cell_contribution(cell,
                                       cell_momentum[d],
                                       indices,
                                       momentum_rhs[d]);
      }
    beta_rhs.compress(dealii::VectorOperation::add);
    for (auto &m : momentum_rhs)
      m.compress(dealii::VectorOperation::add);

    filter.solve(beta_rhs, beta);
    for (unsigned int d = 0; d < dim; ++d)
      filter.solve(momentum_rhs[d], momentum[d]);
  }


  template <int dim>
  void
  FilteredDrag<dim>::filter_velocity(
    const dealii::DoFHandler<dim>                    &fluid_dof_handler,
    const dealii::TrilinosWrappers::MPI::BlockVector &fluid_solution)
  {
    std::array<typename HelmholtzFilter<dim>::Vector, dim> rhs;
    for (auto &r : rhs)
      r = filter.make_owned_vector();

    // Q1 x Q2 is integrated exactly by the fluid's own Gauss rule.
    const auto               &fluid_fe = fluid_dof_handler.get_fe();
    const dealii::QGauss<dim> quadrature(fluid_fe.degree + 1);
    dealii::FEValues<dim>     fluid_values(filter.get_mapping(),
                                       fluid_fe,
                                       quadrature,
                                       dealii::update_values |
                                         dealii::update_JxW_values);
    dealii::FEValues<dim>     filter_values(filter.get_mapping(),
                                        filter.get_fe(),
                                        quadrature,
                                        dealii::update_values);
    const dealii::FEValuesExtractors::Vector velocities(0);
    std::vector<dealii::Tensor<1, dim>>      u(quadrature.size());
    const unsigned int n = filter.get_fe().n_dofs_per_cell();
    std::array<dealii::Vector<double>, dim>      local;
    std::vector<dealii::types::global_dof_index> indices(n);
    for (auto &l : local)
      l.reinit(n);

    for (const auto &cell : fluid_dof_handler.active_cell_iterators())
      if (cell->is_locally_owned())
      {
        fluid_values.reinit(cell);
        const auto filter_cell = filter.dof_cell(cell);
        filter_values.reinit(filter_cell);
        fluid_values[velocities].get_function_values(fluid_solution, u);
        for (auto &l : local)
          l = 0;
        for (unsigned int q = 0; q < quadrature.size(); ++q)
          for (unsigned int j = 0; j < n; ++j)
          {
            const double weight =
              filter_values.shape_value(j, q) * fluid_values.JxW(q);
            for (unsigned int d = 0; d < dim; ++d)
              local[d](j) += u[q][d] * weight;
          }
        for (unsigned int d = 0; d < dim; ++d)
          filter.add_cell_contribution(filter_cell, local[d], indices, rhs[d]);
      }
    for (unsigned int d = 0; d < dim; ++d)
    {
      rhs[d].compress(dealii::VectorOperation::add);
      filter.solve(rhs[d], velocity[d]);
    }
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
    dealii::FEPointEvaluation<1, dim> evaluator(filter.get_mapping(),
                                                filter.get_fe(),
                                                dealii::update_values);
    evaluator.reinit(
      tria_cell, dealii::ArrayView<const dealii::Point<dim>>(reference_points));
    std::vector<double>                       local(n);
    std::array<std::vector<double>, n_fields> result;
    for (std::size_t f = 0; f < n_fields; ++f)
    {
      for (unsigned int i = 0; i < n; ++i)
        local[i] = (*fields[f])[indices[i]];
      evaluator.evaluate(dealii::ArrayView<const double>(local),
                         dealii::EvaluationFlags::values);
      result[f].resize(reference_points.size());
      for (unsigned int q = 0; q < reference_points.size(); ++q)
        result[f][q] = evaluator.get_value(q);
    }
    return result;
  }


  template <int dim>
  std::vector<dealii::Tensor<1, dim>>
  FilteredDrag<dim>::filtered_velocity(
    const typename dealii::Triangulation<dim>::active_cell_iterator &cell,
    const std::vector<dealii::Point<dim>> &reference_points) const
  {
    std::array<const typename HelmholtzFilter<dim>::Vector *, dim> fields;
    for (unsigned int d = 0; d < dim; ++d)
      fields[d] = &velocity[d];
    const auto values = values_at(cell, reference_points, fields);
    std::vector<dealii::Tensor<1, dim>> result(reference_points.size());
    for (unsigned int q = 0; q < result.size(); ++q)
      for (unsigned int d = 0; d < dim; ++d)
        result[q][d] = values[d][q];
    return result;
  }


  template <int dim>
  void
  FilteredDrag<dim>::evaluate(
    const typename dealii::Triangulation<dim>::active_cell_iterator &cell,
    const std::vector<dealii::Point<dim>> &reference_points,
    MixtureValues<dim>                    &values) const
  {
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
    const dealii::TrilinosWrappers::MPI::BlockVector &fluid_solution) const
  {
    const auto               &fluid_fe = fluid_dof_handler.get_fe();
    const dealii::QGauss<dim> quadrature(fluid_fe.degree + 1);
    dealii::FEValues<dim>     fluid_values(filter.get_mapping(),
                                       fluid_fe,
                                       quadrature,
                                       dealii::update_values |
                                         dealii::update_JxW_values);
    dealii::FEValues<dim>     filter_values(filter.get_mapping(),
                                        filter.get_fe(),
                                        quadrature,
                                        dealii::update_values);
    const dealii::FEValuesExtractors::Vector velocities(0);
    std::vector<dealii::Tensor<1, dim>>      u(quadrature.size());
    std::vector<double>                      b(quadrature.size());
    std::array<std::vector<double>, dim>     m;
    for (auto &v : m)
      v.resize(quadrature.size());
    dealii::Tensor<1, dim> force;
    for (const auto &cell : fluid_dof_handler.active_cell_iterators())
      if (cell->is_locally_owned())
      {
        fluid_values.reinit(cell);
        filter_values.reinit(filter.dof_cell(cell));
        fluid_values[velocities].get_function_values(fluid_solution, u);
        filter_values.get_function_values(beta, b);
        for (unsigned int d = 0; d < dim; ++d)
          filter_values.get_function_values(momentum[d], m[d]);
        for (unsigned int q = 0; q < quadrature.size(); ++q)
          for (unsigned int d = 0; d < dim; ++d)
            force[d] -= (b[q] * u[q][d] - m[d][q]) * fluid_values.JxW(q);
      }
    return dealii::Utilities::MPI::sum(
      force, fluid_dof_handler.get_triangulation().get_communicator());
  }


  template class FilteredDrag<2>;
  template class FilteredDrag<3>;
} // namespace ImmersedGrains
