#include <deal.II/base/quadrature_lib.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/sparsity_tools.h>

#include <immersed_grains/coupling/helmholtz_filter.h>

#include <Amesos.h>
#include <Amesos_BaseSolver.h>
#include <Epetra_LinearProblem.h>
#include <Epetra_Map.h>
#include <Epetra_MultiVector.h>
#include <Epetra_Vector.h>

#include <string>

namespace ImmersedGrains
{
  template <int dim>
  HelmholtzFilter<dim>::HelmholtzFilter(
    const dealii::parallel::distributed::Triangulation<dim> &tria,
    const Geometry<dim>                                     &geometry)
      : triangulation(tria)
      , geometry(geometry)
      , mapping(geometry.mapping())
      , fe(1)
      , dof_handler(tria)
  {
  }


  template <int dim>
  HelmholtzFilter<dim>::~HelmholtzFilter() = default;


  namespace
  {
    // The most unknowns for which one rank factorises the filter's matrix
    // (doc/performance.md). In 2D the factors of this
    // Laplacian-like matrix grow like n log n, and their triangular solves
    // beat the 25-30 Jacobi-CG iterations: the solid fraction's and the
    // interaction force's phases took a third less time on the 2D cloud's
    // 2,145 unknowns and two thirds to five sixths less on 33,000. In 3D
    // they grow like n^(4/3): on the 3D cloud's 4,913 unknowns the solid
    // fraction took twice the CG's time, which the mass-like matrix keeps
    // short there.
    //
    // On several ranks Amesos KLU factorises on the first rank and gathers
    // each right-hand side there, the other ranks waiting, so the limit is
    // a rank's share: below it the two messages of a solve cost less than
    // the conjugate gradients' two reductions per iteration.
    unsigned int
    direct_limit(const int dim, const unsigned int n_ranks)
    {
      return (dim == 2 ? 200000 : 0) / n_ranks;
    }
  } // namespace


  template <int dim>
  void
  HelmholtzFilter<dim>::setup(const bool   lumped,
                              const double length,
                              const bool   with_mass_matrix)
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
          dof_handler,
          geometry.periodic_boundary_ids(d).first,
          geometry.periodic_boundary_ids(d).second,
          d,
          constraints);
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
    owned_template.reinit(owned, comm);
    ghosted_template.reinit(owned, relevant, comm);
    ghost_exchange.reinit(owned_template, ghosted_template);
    if (with_mass_matrix)
      mass_matrix.reinit(owned, owned, dsp, comm);
    else
      mass_matrix.clear();

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
    dealii::FullMatrix<double>                   cell_mass(n, n);
    dealii::Vector<double>                       cell_lumped(n);
    std::vector<dealii::types::global_dof_index> indices(n);
    Vector                                       row_sums(owned, comm);
    // Written on ghost DoFs too, then summed onto their owners.
    Vector raw_integrals;
    raw_integrals.reinit(owned, relevant, comm, true);
    const double l2 = length * length;
    for (const auto &cell : dof_handler.active_cell_iterators())
      if (cell->is_locally_owned())
      {
        fe_values.reinit(cell);
        cell_matrix = 0;
        cell_mass   = 0;
        cell_lumped = 0;
        for (unsigned int q = 0; q < quadrature.size(); ++q)
          for (unsigned int i = 0; i < n; ++i)
            for (unsigned int j = 0; j < n; ++j)
            {
              const double mass = fe_values.shape_value(i, q) *
                                  fe_values.shape_value(j, q) *
                                  fe_values.JxW(q);
              cell_lumped(i) += mass;
              cell_mass(i, j) += mass;
              if (!lumped)
                cell_matrix(i, j) += mass;
              cell_matrix(i, j) +=
                l2 * (fe_values.shape_grad(i, q) * fe_values.shape_grad(j, q)) *
                fe_values.JxW(q);
            }
        if (lumped)
          for (unsigned int i = 0; i < n; ++i)
            cell_matrix(i, i) += cell_lumped(i);
        cell->get_dof_indices(indices);
        constraints.distribute_local_to_global(cell_matrix, indices, matrix);
        if (with_mass_matrix)
          constraints.distribute_local_to_global(cell_mass,
                                                 indices,
                                                 mass_matrix);
        constraints.distribute_local_to_global(cell_lumped, indices, row_sums);
        for (unsigned int i = 0; i < n; ++i)
          raw_integrals(indices[i]) += cell_lumped(i);
      }
    matrix.compress(dealii::VectorOperation::add);
    if (with_mass_matrix)
      mass_matrix.compress(dealii::VectorOperation::add);
    row_sums.compress(dealii::VectorOperation::add);
    raw_integrals.compress(dealii::VectorOperation::add);
    weights.reinit(owned, comm);
    weights = raw_integrals;

    lumped_inverse.reinit(owned, comm);
    for (const auto i : owned)
      lumped_inverse[i] = row_sums[i] > 0 ? 1.0 / row_sums[i] : 0.0;
    lumped_inverse.compress(dealii::VectorOperation::insert);
    diagonal = lumped && length == 0;

    direct_solver.reset();
    direct_problem.reset();
    if (diagonal)
      return;
    if (dof_handler.n_dofs() <=
        direct_limit(dim, dealii::Utilities::MPI::n_mpi_processes(comm)))
    {
      direct_problem = std::make_unique<Epetra_LinearProblem>();
      direct_problem->SetOperator(
        const_cast<Epetra_CrsMatrix *>(&matrix.trilinos_matrix()));
      Amesos factory;
      direct_solver.reset(factory.Create("Amesos_Klu", *direct_problem));
      AssertThrow(direct_solver != nullptr,
                  dealii::ExcMessage("Trilinos was built without Amesos KLU"));
      AssertThrow(direct_solver->SymbolicFactorization() == 0 &&
                    direct_solver->NumericFactorization() == 0,
                  dealii::ExcMessage(
                    "the Helmholtz filter's matrix could not be factorised"));
    }
    else
    {
      // The conjugate gradients' Jacobi preconditioner.
      diagonal_inverse.reinit(owned, comm);
      for (const auto i : owned)
      {
        const double a      = matrix.diag_element(i);
        diagonal_inverse[i] = a != 0 ? 1.0 / a : 1.0;
      }
      diagonal_inverse.compress(dealii::VectorOperation::insert);
    }
  }


  template <int dim>
  typename HelmholtzFilter<dim>::Vector
  HelmholtzFilter<dim>::make_owned_vector() const
  {
    return owned_template;
  }


  template <int dim>
  typename HelmholtzFilter<dim>::Vector
  HelmholtzFilter<dim>::make_ghosted_vector() const
  {
    return ghosted_template;
  }


  template <int dim>
  void
  HelmholtzFilter<dim>::add_cell_contribution(
    const typename dealii::DoFHandler<dim>::active_cell_iterator &cell,
    const dealii::Vector<double>                                 &local,
    std::vector<dealii::types::global_dof_index>                 &indices,
    Vector                                                       &rhs) const
  {
    indices.resize(fe.n_dofs_per_cell());
    cell->get_dof_indices(indices);
    constraints.distribute_local_to_global(local, indices, rhs);
  }


  template <int dim>
  void
  HelmholtzFilter<dim>::mass_product(const Vector &f, Vector &rhs) const
  {
    // The condensed matrix acts on the unconstrained values (its
    // constrained columns are empty); its constrained rows hold only a
    // diagonal, and their entries of a right-hand side are zero.
    Assert(mass_matrix.m() > 0,
           dealii::ExcMessage("setup() without the mass matrix"));
    Vector owned_values = owned_template;
    ghost_exchange.to_owned(f, owned_values);
    mass_matrix.vmult(rhs, owned_values);
    constraints.set_zero(rhs);
  }


  template <int dim>
  void
  HelmholtzFilter<dim>::solve(const Vector &rhs, Vector &ghosted) const
  {
    solve(std::vector<const Vector *>{&rhs}, std::vector<Vector *>{&ghosted});
  }


  template <int dim>
  void
  HelmholtzFilter<dim>::solve(const std::vector<const Vector *> &rhs,
                              const std::vector<Vector *>       &ghosted) const
  {
    AssertDimension(rhs.size(), ghosted.size());
    const unsigned int  n = rhs.size();
    std::vector<Vector> x(n, owned_template);
    if (diagonal)
      for (unsigned int c = 0; c < n; ++c)
      {
        x[c] = *rhs[c];
        x[c].scale(lumped_inverse);
      }
    else if (direct_solver)
    {
      // Contiguous columns: KLU solves in place on one rank and needs a
      // constant stride.
      const Epetra_Map  &map = matrix.trilinos_matrix().RowMap();
      Epetra_MultiVector X(map, n, false), B(map, n, false);
      for (unsigned int c = 0; c < n; ++c)
        *B(c) = *rhs[c]->trilinos_vector()(0);
      direct_problem->SetLHS(&X);
      direct_problem->SetRHS(&B);
      const int status = direct_solver->Solve();
      AssertThrow(status == 0,
                  dealii::ExcMessage(
                    "the Helmholtz filter's triangular solves failed (Amesos "
                    "KLU status " +
                    std::to_string(status) + ")"));
      for (unsigned int c = 0; c < n; ++c)
        *x[c].trilinos_vector()(0) = *X(c);
      direct_problem->SetLHS(nullptr);
      direct_problem->SetRHS(nullptr);
    }
    else
    {
      // Jacobi-preconditioned conjugate gradients, column by column but in
      // lockstep on Epetra multivectors. A tight tolerance: conservation
      // is 1^T r away from exact, and the adjoint filter's momentum
      // balance as far.
      const Epetra_Map     &map = matrix.trilinos_matrix().RowMap();
      std::vector<double *> x_columns(n);
      for (unsigned int c = 0; c < n; ++c)
        x_columns[c] = x[c].trilinos_vector()[0];
      Epetra_MultiVector X(View, map, x_columns.data(), n);
      Epetra_MultiVector R(map, n, false), Z(map, n, false), P(map, n, false),
        AP(map, n, false);
      for (unsigned int c = 0; c < n; ++c)
        *R(c) = *rhs[c]->trilinos_vector()(0);
      std::vector<double> stop(n), norm(n), r_dot_z(n), r_dot_z_new(n),
        p_dot_ap(n);
      R.Norm2(norm.data());
      for (unsigned int c = 0; c < n; ++c)
        stop[c] = 1e-15 * norm[c] + 1e-300;
      std::vector<bool> active(n);
      unsigned int      n_active = 0;
      for (unsigned int c = 0; c < n; ++c)
      {
        active[c] = norm[c] > stop[c];
        n_active += active[c];
      }
      const Epetra_MultiVector &D = diagonal_inverse.trilinos_vector();
      Z.Multiply(1.0, D, R, 0.0);
      P = Z;
      R.Dot(Z, r_dot_z.data());
      const unsigned int max_iterations = 1000;
      for (unsigned int k = 0; k < max_iterations && n_active > 0; ++k)
      {
        matrix.trilinos_matrix().Multiply(false, P, AP);
        P.Dot(AP, p_dot_ap.data());
        for (unsigned int c = 0; c < n; ++c)
          if (active[c])
          {
            const double alpha = r_dot_z[c] / p_dot_ap[c];
            X(c)->Update(alpha, *P(c), 1.0);
            R(c)->Update(-alpha, *AP(c), 1.0);
          }
        R.Norm2(norm.data());
        for (unsigned int c = 0; c < n; ++c)
          if (active[c] && norm[c] <= stop[c])
          {
            active[c] = false;
            --n_active;
          }
        if (n_active == 0)
          break;
        AssertThrow(k + 1 < max_iterations,
                    dealii::ExcMessage("The Helmholtz filter's conjugate "
                                       "gradients did not converge in " +
                                       std::to_string(max_iterations) +
                                       " iterations."));
        Z.Multiply(1.0, D, R, 0.0);
        R.Dot(Z, r_dot_z_new.data());
        for (unsigned int c = 0; c < n; ++c)
          if (active[c])
          {
            P(c)->Update(1.0, *Z(c), r_dot_z_new[c] / r_dot_z[c]);
            r_dot_z[c] = r_dot_z_new[c];
          }
      }
    }
    for (unsigned int c = 0; c < n; ++c)
    {
      ghost_exchange.distribute(constraints, x[c], *ghosted[c]);
    }
  }


  template <int dim>
  typename dealii::DoFHandler<dim>::active_cell_iterator
  HelmholtzFilter<dim>::dof_cell(
    const typename dealii::Triangulation<dim>::active_cell_iterator &cell) const
  {
    return typename dealii::DoFHandler<dim>::active_cell_iterator(
      &triangulation, cell->level(), cell->index(), &dof_handler);
  }


  template <int dim>
  double
  HelmholtzFilter<dim>::integral(const Vector &f) const
  {
    Vector owned_values = owned_template;
    ghost_exchange.to_owned(f, owned_values);
    return weights * owned_values; // summed over ranks
  }


  template <int dim>
  const typename HelmholtzFilter<dim>::Vector &
  HelmholtzFilter<dim>::shape_integrals() const
  {
    return weights;
  }


  template <int dim>
  const dealii::DoFHandler<dim> &
  HelmholtzFilter<dim>::get_dof_handler() const
  {
    return dof_handler;
  }


  template <int dim>
  const dealii::FE_Q<dim> &
  HelmholtzFilter<dim>::get_fe() const
  {
    return fe;
  }


  template <int dim>
  std::array<double, dealii::GeometryInfo<dim>::vertices_per_cell>
  HelmholtzFilter<dim>::shape_values(const dealii::Point<dim> &x)
  {
    // FE_Q(1)'s function j is the product over the axes of 1 - x_d (bit d
    // of j clear) or x_d (set), each Lagrange factor evaluated as deal.II
    // does, (x_d - 1) (-1) and (x_d - 0) 1, and multiplied in axis order.
    std::array<double, dealii::GeometryInfo<dim>::vertices_per_cell> values;
    for (unsigned int j = 0; j < values.size(); ++j)
    {
      double value = 1.;
      for (unsigned int d = 0; d < dim; ++d)
        value *= ((j >> d) & 1) ? x[d] : -(x[d] - 1.);
      values[j] = value;
    }
    return values;
  }


  template <int dim>
  const dealii::Mapping<dim> &
  HelmholtzFilter<dim>::get_mapping() const
  {
    return mapping;
  }


  template <int dim>
  const dealii::IndexSet &
  HelmholtzFilter<dim>::locally_owned_dofs() const
  {
    return owned;
  }


  template class HelmholtzFilter<2>;
  template class HelmholtzFilter<3>;
} // namespace ImmersedGrains
