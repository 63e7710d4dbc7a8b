#include <deal.II/base/quadrature_lib.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/solver_cg.h>
#include <deal.II/lac/solver_control.h>
#include <deal.II/lac/sparsity_tools.h>
#include <deal.II/lac/trilinos_precondition.h>
#include <deal.II/matrix_free/fe_point_evaluation.h>

#include <immersed_grains/coupling/solid_fraction.h>

namespace ImmersedGrains
{
  template <int dim>
  void
  SolidFraction<dim>::Parameters::declare_parameters(
    dealii::ParameterHandler &prm)
  {
    using namespace dealii::Patterns;
    prm.declare_entry("Solid fraction projection",
                      "consistent",
                      Selection("consistent|lumped"),
                      "Mass matrix of the projection of grain volumes onto "
                      "the Q1 solid fraction (both conserve the volume).");
    prm.declare_entry("Smoothing length",
                      "0",
                      Double(0),
                      "Length l [m] of the Helmholtz filter (M + l^2 K) "
                      "phi_s = b that makes the solid fraction independent of "
                      "the mesh once cells are smaller than grains; 0: none. "
                      "A grain diameter or two is typical.");
    prm.declare_entry("Minimum fluid fraction",
                      "0.3",
                      Double(0.01, 1),
                      "The fluid sees at least this fluid fraction; where the "
                      "grains pack denser the log warns and phi is clamped.");
  }


  template <int dim>
  void
  SolidFraction<dim>::Parameters::parse_parameters(
    dealii::ParameterHandler &prm,
    const std::string &)
  {
    lumped             = prm.get("Solid fraction projection") == "lumped";
    smoothing_length   = prm.get_double("Smoothing length");
    min_fluid_fraction = prm.get_double("Minimum fluid fraction");
  }


  template <int dim>
  SolidFraction<dim>::SolidFraction(
    const Parameters                                        &parameters,
    const Geometry<dim>                                     &geometry,
    const dealii::parallel::distributed::Triangulation<dim> &tria)
      : parameters(parameters)
      , triangulation(tria)
      , geometry(geometry)
      , fe(1)
      , dof_handler(tria)
  {
  }


  template <int dim>
  void
  SolidFraction<dim>::setup()
  {
    const MPI_Comm comm = triangulation.get_communicator();
    dof_handler.distribute_dofs(fe);
    owned = dof_handler.locally_owned_dofs();
    dealii::DoFTools::extract_locally_relevant_dofs(dof_handler, relevant);

    constraints.clear();
    constraints.reinit(relevant);
    dealii::DoFTools::make_hanging_node_constraints(dof_handler, constraints);
    for (unsigned int d = 0; d < dim; ++d)
      if (geometry.is_periodic(d))
        dealii::DoFTools::make_periodicity_constraints(
          dof_handler, 2 * d, 2 * d + 1, d, constraints);
    constraints.close();

    dealii::DynamicSparsityPattern dsp(relevant);
    dealii::DoFTools::make_sparsity_pattern(dof_handler,
                                            dsp,
                                            constraints,
                                            false);
    dealii::SparsityTools::distribute_sparsity_pattern(dsp,
                                                       owned,
                                                       comm,
                                                       relevant);
    matrix.reinit(owned, owned, dsp, comm);

    // M + l^2 K, and the row sums of M for the lumped variant.
    const dealii::QGauss<dim>                    quadrature(2);
    dealii::FEValues<dim>                        fe_values(mapping,
                                    fe,
                                    quadrature,
                                    dealii::update_values |
                                      dealii::update_gradients |
                                      dealii::update_JxW_values);
    const unsigned int                           n = fe.n_dofs_per_cell();
    dealii::FullMatrix<double>                   cell_matrix(n, n);
    dealii::Vector<double>                       cell_lumped(n);
    std::vector<dealii::types::global_dof_index> indices(n);
    dealii::TrilinosWrappers::MPI::Vector        row_sums(owned, comm);
    const double l2 = parameters.smoothing_length * parameters.smoothing_length;
    for (const auto &cell : dof_handler.active_cell_iterators())
      if (cell->is_locally_owned())
      {
        fe_values.reinit(cell);
        cell_matrix = 0;
        cell_lumped = 0;
        for (unsigned int q = 0; q < quadrature.size(); ++q)
          for (unsigned int i = 0; i < n; ++i)
            for (unsigned int j = 0; j < n; ++j)
            {
              const double mass = fe_values.shape_value(i, q) *
                                  fe_values.shape_value(j, q) *
                                  fe_values.JxW(q);
              cell_lumped(i) += mass;
              if (!parameters.lumped)
                cell_matrix(i, j) += mass;
              cell_matrix(i, j) +=
                l2 * (fe_values.shape_grad(i, q) * fe_values.shape_grad(j, q)) *
                fe_values.JxW(q);
            }
        if (parameters.lumped)
          for (unsigned int i = 0; i < n; ++i)
            cell_matrix(i, i) += cell_lumped(i);
        cell->get_dof_indices(indices);
        constraints.distribute_local_to_global(cell_matrix, indices, matrix);
        constraints.distribute_local_to_global(cell_lumped, indices, row_sums);
      }
    matrix.compress(dealii::VectorOperation::add);
    row_sums.compress(dealii::VectorOperation::add);

    lumped_inverse.reinit(owned, comm);
    for (const auto i : owned)
      lumped_inverse[i] = row_sums[i] > 0 ? 1.0 / row_sums[i] : 0.0;
    lumped_inverse.compress(dealii::VectorOperation::insert);

    fraction.reinit(owned, relevant, comm);
    for (auto &f : flux)
      f.reinit(owned, relevant, comm);
  }


  template <int dim>
  void
  SolidFraction<dim>::solve(const dealii::TrilinosWrappers::MPI::Vector &rhs,
                            dealii::TrilinosWrappers::MPI::Vector &ghosted)
  {
    const MPI_Comm comm = triangulation.get_communicator();
    dealii::TrilinosWrappers::MPI::Vector x(owned, comm);
    if (parameters.lumped && parameters.smoothing_length == 0)
    {
      x = rhs;
      x.scale(lumped_inverse);
    }
    else
    {
      // Tight tolerance: conservation is 1^T r away from exact.
      dealii::SolverControl control(1000, 1e-15 * rhs.l2_norm() + 1e-300);
      dealii::SolverCG<dealii::TrilinosWrappers::MPI::Vector> cg(control);
      dealii::TrilinosWrappers::PreconditionJacobi            jacobi;
      jacobi.initialize(matrix);
      cg.solve(matrix, x, rhs, jacobi);
    }
    constraints.distribute(x);
    ghosted = x;
  }


  template <int dim>
  void
  SolidFraction<dim>::project(
    const std::function<
      void(const typename dealii::Triangulation<dim>::active_cell_iterator &,
           std::vector<GrainSample<dim>> &)> &samples)
  {
    const MPI_Comm comm = triangulation.get_communicator();
    dealii::TrilinosWrappers::MPI::Vector volume_rhs(owned, comm);
    std::array<dealii::TrilinosWrappers::MPI::Vector, dim> flux_rhs;
    for (auto &f : flux_rhs)
      f.reinit(owned, comm);

    const unsigned int                           n = fe.n_dofs_per_cell();
    std::vector<dealii::types::global_dof_index> indices(n);
    std::vector<GrainSample<dim>>                grains;
    dealii::Vector<double>                       cell_volume(n);
    std::array<dealii::Vector<double>, dim>      cell_flux;
    for (auto &c : cell_flux)
      c.reinit(n);

    for (const auto &cell : dof_handler.active_cell_iterators())
      if (cell->is_locally_owned())
      {
        grains.clear();
        samples(cell, grains);
        if (grains.empty())
          continue;
        cell_volume = 0;
        for (auto &c : cell_flux)
          c = 0;
        for (const auto &g : grains)
          for (unsigned int j = 0; j < n; ++j)
          {
            const double N = fe.shape_value(j, g.reference_location);
            cell_volume(j) += g.volume * N;
            for (unsigned int d = 0; d < dim; ++d)
              cell_flux[d](j) += g.volume * g.velocity[d] * N;
          }
        cell->get_dof_indices(indices);
        constraints.distribute_local_to_global(cell_volume,
                                               indices,
                                               volume_rhs);
        for (unsigned int d = 0; d < dim; ++d)
          constraints.distribute_local_to_global(cell_flux[d],
                                                 indices,
                                                 flux_rhs[d]);
      }
    volume_rhs.compress(dealii::VectorOperation::add);
    for (auto &f : flux_rhs)
      f.compress(dealii::VectorOperation::add);

    dealii::TrilinosWrappers::MPI::Vector owned_rhs(owned, comm);
    owned_rhs = volume_rhs;
    solve(owned_rhs, fraction);
    for (unsigned int d = 0; d < dim; ++d)
    {
      owned_rhs = flux_rhs[d];
      solve(owned_rhs, flux[d]);
    }

    unsigned int local_clamped = 0;
    for (const auto i : owned)
      if (1 - fraction[i] < parameters.min_fluid_fraction)
        ++local_clamped;
    clamped = dealii::Utilities::MPI::sum(local_clamped, comm);
  }


  template <int dim>
  double
  SolidFraction<dim>::integral() const
  {
    const dealii::QGauss<dim> quadrature(2);
    dealii::FEValues<dim>     fe_values(mapping,
                                    fe,
                                    quadrature,
                                    dealii::update_values |
                                      dealii::update_JxW_values);
    std::vector<double>       values(quadrature.size());
    double                    sum = 0;
    for (const auto &cell : dof_handler.active_cell_iterators())
      if (cell->is_locally_owned())
      {
        fe_values.reinit(cell);
        fe_values.get_function_values(fraction, values);
        for (unsigned int q = 0; q < quadrature.size(); ++q)
          sum += values[q] * fe_values.JxW(q);
      }
    return dealii::Utilities::MPI::sum(sum, triangulation.get_communicator());
  }


  template <int dim>
  unsigned int
  SolidFraction<dim>::n_clamped() const
  {
    return clamped;
  }


  template <int dim>
  void
  SolidFraction<dim>::evaluate(
    const typename dealii::Triangulation<dim>::active_cell_iterator &tria_cell,
    const std::vector<dealii::Point<dim>> &,
    const std::vector<dealii::Point<dim>> &reference_points,
    const double,
    MixtureValues<dim> &values) const
  {
    const unsigned int n_points = reference_points.size();
    values.resize(n_points);
    const typename dealii::DoFHandler<dim>::active_cell_iterator cell(
      &triangulation, tria_cell->level(), tria_cell->index(), &dof_handler);

    const unsigned int                           n = fe.n_dofs_per_cell();
    std::vector<dealii::types::global_dof_index> indices(n);
    cell->get_dof_indices(indices);
    std::vector<double> local(n);

    // Values and gradients of Q1 fields at arbitrary points of the cell.
    dealii::FEPointEvaluation<1, dim> evaluator(
      mapping, fe, dealii::update_values | dealii::update_gradients);
    evaluator.reinit(
      tria_cell, dealii::ArrayView<const dealii::Point<dim>>(reference_points));

    auto evaluate_field = [&](const dealii::TrilinosWrappers::MPI::Vector &v)
    {
      for (unsigned int i = 0; i < n; ++i)
        local[i] = v[indices[i]];
      evaluator.evaluate(dealii::ArrayView<const double>(local),
                         dealii::EvaluationFlags::values |
                           dealii::EvaluationFlags::gradients);
    };

    evaluate_field(fraction);
    for (unsigned int q = 0; q < n_points; ++q)
    {
      const double phi = 1 - evaluator.get_value(q);
      // Clamped where grains pack beyond the physical range: the gradient
      // of the clamped field is then zero.
      if (phi < parameters.min_fluid_fraction)
      {
        values.fluid_fraction[q]          = parameters.min_fluid_fraction;
        values.fluid_fraction_gradient[q] = 0;
      }
      else
      {
        values.fluid_fraction[q]          = std::min(phi, 1.0);
        values.fluid_fraction_gradient[q] = -evaluator.get_gradient(q);
      }
      values.drag_coefficient[q] = 0;
      values.mass_source[q]      = 0;
    }
    std::vector<double> solid(n_points);
    for (unsigned int q = 0; q < n_points; ++q)
      solid[q] = 1 - values.fluid_fraction[q];
    for (unsigned int d = 0; d < dim; ++d)
    {
      evaluate_field(flux[d]);
      for (unsigned int q = 0; q < n_points; ++q)
      {
        values.solid_flux[q][d] = evaluator.get_value(q);
        values.grain_velocity[q][d] =
          solid[q] > 1e-12 ? evaluator.get_value(q) / solid[q] : 0.0;
      }
    }
  }


  template <int dim>
  const dealii::DoFHandler<dim> &
  SolidFraction<dim>::get_dof_handler() const
  {
    return dof_handler;
  }


  template <int dim>
  const dealii::TrilinosWrappers::MPI::Vector &
  SolidFraction<dim>::solid_fraction() const
  {
    return fraction;
  }


  template class SolidFraction<2>;
  template class SolidFraction<3>;
} // namespace ImmersedGrains
