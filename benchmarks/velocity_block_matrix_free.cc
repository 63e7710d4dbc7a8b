// Evaluates a matrix-free path for the fluid's velocity block
// (doc/performance.md "A matrix-free velocity block"): the same operator
//
//   A u = (c u, v) + (nu grad u, grad v),   c = rho a0/dt + beta(x),
//
// on Q2 vector fields in the unit box with walls, solved by CG to a
// relative residual of 1e-6 with
//   - the matrix-based path of the fluid solver: a Trilinos matrix and an
//     ML AMG with the fluid preconditioner's settings (ILU smoothing, two
//     sweeps, aggregation threshold 0.02, one constant mode per component);
//   - a matrix-free operator (deal.II MatrixFree, sum factorisation) with
//     geometric multigrid: Chebyshev smoothing of degree 5 on the diagonal,
//     the coarse level by Chebyshev iteration, float on the levels.
// beta is a drag ball (radius 1/4, centre of the box) as in a cloud. It
// prints set-up, solve and one operator application of each, and their
// memory. Uniform meshes only: the production meshes are adaptive, which
// the matrix-free path would handle with hanging-node constraints.
//
// Usage: velocity_block_matrix_free DIM LEVEL [C [BETA [NU]]]
//   defaults C = 1, BETA = 1e4, NU = 1 (viscous number nu/(c h^2) >> 1,
//   the glycerine clouds' regime; doc/performance.md has the table).

#include <deal.II/base/function.h>
#include <deal.II/base/quadrature_lib.h>
#include <deal.II/base/timer.h>
#include <deal.II/distributed/tria.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_q.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/fe/mapping_q1.h>
#include <deal.II/grid/grid_generator.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/diagonal_matrix.h>
#include <deal.II/lac/la_parallel_vector.h>
#include <deal.II/lac/precondition.h>
#include <deal.II/lac/solver_cg.h>
#include <deal.II/lac/trilinos_precondition.h>
#include <deal.II/lac/trilinos_sparse_matrix.h>
#include <deal.II/lac/trilinos_sparsity_pattern.h>
#include <deal.II/lac/trilinos_vector.h>
#include <deal.II/matrix_free/fe_evaluation.h>
#include <deal.II/matrix_free/matrix_free.h>
#include <deal.II/matrix_free/operators.h>
#include <deal.II/matrix_free/tools.h>
#include <deal.II/multigrid/mg_coarse.h>
#include <deal.II/multigrid/mg_constrained_dofs.h>
#include <deal.II/multigrid/mg_matrix.h>
#include <deal.II/multigrid/mg_smoother.h>
#include <deal.II/multigrid/mg_tools.h>
#include <deal.II/multigrid/mg_transfer_matrix_free.h>
#include <deal.II/multigrid/multigrid.h>
#include <deal.II/numerics/vector_tools.h>

#include <iomanip>
#include <iostream>

using namespace dealii;

namespace
{
  constexpr unsigned int degree = 2;

  // The coefficients of A at a point.
  template <int dim>
  struct Coefficients
  {
    double reaction_clear = 1, drag = 1e4, viscosity = 1;

    template <typename Number>
    Number
    reaction(const Point<dim, Number> &p) const
    {
      Number value;
      for (unsigned int lane = 0; lane < Number::size(); ++lane)
      {
        Point<dim> x;
        for (unsigned int d = 0; d < dim; ++d)
          x[d] = p[d][lane];
        value[lane] = reaction(x);
      }
      return value;
    }

    double
    reaction(const Point<dim> &x) const
    {
      double r2 = 0;
      for (unsigned int d = 0; d < dim; ++d)
        r2 += (x[d] - 0.5) * (x[d] - 0.5);
      return reaction_clear + (r2 < 0.25 * 0.25 ? drag : 0.0);
    }
  };


  // A on one level (or the active mesh), its coefficients stored per cell
  // batch and quadrature point.
  template <int dim, typename number>
  class VelocityOperator
      : public MatrixFreeOperators::
          Base<dim, LinearAlgebra::distributed::Vector<number>>
  {
  public:
    using VectorType = LinearAlgebra::distributed::Vector<number>;
    using Evaluation = FEEvaluation<dim, degree, degree + 1, dim, number>;

    void
    set_coefficients(const Coefficients<dim> &coefficients)
    {
      const unsigned int n_batches = this->data->n_cell_batches();
      Evaluation         phi(*this->data);
      reaction.reinit(n_batches, phi.n_q_points);
      viscosity = coefficients.viscosity;
      for (unsigned int cell = 0; cell < n_batches; ++cell)
      {
        phi.reinit(cell);
        for (const unsigned int q : phi.quadrature_point_indices())
          reaction(cell, q) = coefficients.reaction(phi.quadrature_point(q));
      }
    }

    void
    compute_diagonal() override
    {
      this->inverse_diagonal_entries =
        std::make_shared<DiagonalMatrix<VectorType>>();
      VectorType &diagonal = this->inverse_diagonal_entries->get_vector();
      this->data->initialize_dof_vector(diagonal);
      MatrixFreeTools::compute_diagonal(*this->data,
                                        diagonal,
                                        &VelocityOperator::local_cell,
                                        this);
      for (auto &value : diagonal)
        value = std::abs(value) > 1e-300 ? number(1) / value : number(1);
    }

  private:
    void
    apply_add(VectorType &dst, const VectorType &src) const override
    {
      this->data->cell_loop(&VelocityOperator::local_apply, this, dst, src);
    }

    void
    local_apply(const MatrixFree<dim, number>               &data,
                VectorType                                  &dst,
                const VectorType                            &src,
                const std::pair<unsigned int, unsigned int> &cells) const
    {
      Evaluation phi(data);
      for (unsigned int cell = cells.first; cell < cells.second; ++cell)
      {
        phi.reinit(cell);
        phi.read_dof_values(src);
        local_cell(phi);
        phi.distribute_local_to_global(dst);
      }
    }

    // c u against v and nu grad u against grad v at each point.
    void
    local_cell(Evaluation &phi) const
    {
      phi.evaluate(EvaluationFlags::values | EvaluationFlags::gradients);
      const unsigned int cell = phi.get_current_cell_index();
      for (const unsigned int q : phi.quadrature_point_indices())
      {
        phi.submit_value(reaction(cell, q) * phi.get_value(q), q);
        phi.submit_gradient(viscosity * phi.get_gradient(q), q);
      }
      phi.integrate(EvaluationFlags::values | EvaluationFlags::gradients);
    }

    Table<2, VectorizedArray<number>> reaction;
    number                            viscosity = 1;
  };


  template <int dim>
  void
  run(const unsigned int level, const Coefficients<dim> &coefficients)
  {
    parallel::distributed::Triangulation<dim> triangulation(
      MPI_COMM_WORLD,
      Triangulation<dim>::limit_level_difference_at_vertices,
      parallel::distributed::Triangulation<dim>::construct_multigrid_hierarchy);
    GridGenerator::hyper_cube(triangulation);
    triangulation.refine_global(level);
    const FESystem<dim> fe(FE_Q<dim>(degree), dim);
    DoFHandler<dim>     dof_handler(triangulation);
    dof_handler.distribute_dofs(fe);
    dof_handler.distribute_mg_dofs();
    const MappingQ1<dim> mapping;
    const QGauss<dim>    quadrature(degree + 1);

    AffineConstraints<double> constraints;
    VectorTools::interpolate_boundary_values(
      mapping, dof_handler, 0, Functions::ZeroFunction<dim>(dim), constraints);
    constraints.close();

    const double h = 1.0 / (1u << level) / degree;
    std::cout << dim << "D level " << level << ", " << dof_handler.n_dofs()
              << " DoFs, viscous number nu/(c h^2) = "
              << coefficients.viscosity / (coefficients.reaction_clear * h * h)
              << " (clear), "
              << coefficients.viscosity /
                   ((coefficients.reaction_clear + coefficients.drag) * h * h)
              << " (drag ball)" << std::endl;
    Timer timer;

    // --- The matrix-based path: assemble A (each component only with
    // itself, as the fluid solver's sparsity), AMG as in the fluid solver.
    TrilinosWrappers::SparseMatrix matrix;
    TrilinosWrappers::MPI::Vector  rhs(dof_handler.locally_owned_dofs(),
                                      MPI_COMM_WORLD);
    {
      Table<2, DoFTools::Coupling> coupling(dim, dim);
      for (unsigned int c = 0; c < dim; ++c)
        for (unsigned int d = 0; d < dim; ++d)
          coupling[c][d] = c == d ? DoFTools::always : DoFTools::none;
      TrilinosWrappers::SparsityPattern pattern(
        dof_handler.locally_owned_dofs(), MPI_COMM_WORLD);
      DoFTools::make_sparsity_pattern(
        dof_handler, coupling, pattern, constraints, false);
      pattern.compress();
      matrix.reinit(pattern);
      FEValues<dim>                        fe_values(mapping,
                              fe,
                              quadrature,
                              update_values | update_gradients |
                                update_quadrature_points | update_JxW_values);
      const unsigned int                   n = fe.n_dofs_per_cell();
      FullMatrix<double>                   cell_matrix(n, n);
      Vector<double>                       cell_rhs(n);
      std::vector<types::global_dof_index> indices(n);
      for (const auto &cell : dof_handler.active_cell_iterators())
      {
        fe_values.reinit(cell);
        cell_matrix = 0;
        cell_rhs    = 0;
        for (const unsigned int q : fe_values.quadrature_point_indices())
        {
          const double c = coefficients.reaction(fe_values.quadrature_point(q));
          for (unsigned int i = 0; i < n; ++i)
          {
            const unsigned int ci = fe.system_to_component_index(i).first;
            cell_rhs(i) += fe_values.shape_value(i, q) * fe_values.JxW(q);
            for (unsigned int j = 0; j < n; ++j)
              if (fe.system_to_component_index(j).first == ci)
                cell_matrix(i, j) +=
                  (c * fe_values.shape_value(i, q) *
                     fe_values.shape_value(j, q) +
                   coefficients.viscosity * fe_values.shape_grad(i, q) *
                     fe_values.shape_grad(j, q)) *
                  fe_values.JxW(q);
          }
        }
        cell->get_dof_indices(indices);
        constraints.distribute_local_to_global(
          cell_matrix, cell_rhs, indices, matrix, rhs);
      }
      matrix.compress(VectorOperation::add);
      rhs.compress(VectorOperation::add);
    }

    timer.restart();
    TrilinosWrappers::PreconditionAMG                 amg;
    TrilinosWrappers::PreconditionAMG::AdditionalData amg_data;
    std::vector<std::vector<bool>>                    constant_modes;
    DoFTools::extract_constant_modes(dof_handler,
                                     ComponentMask(dim, true),
                                     constant_modes);
    amg_data.constant_modes        = constant_modes;
    amg_data.elliptic              = true;
    amg_data.higher_order_elements = true;
    amg_data.smoother_type         = "ILU";
    amg_data.smoother_sweeps       = 2;
    amg_data.aggregation_threshold = 0.02;
    amg.initialize(matrix, amg_data);
    const double amg_setup = timer.wall_time();

    TrilinosWrappers::MPI::Vector x(rhs);
    x = 0;
    SolverControl control(2000, 1e-6 * rhs.l2_norm());
    timer.restart();
    SolverCG<TrilinosWrappers::MPI::Vector>(control).solve(matrix, x, rhs, amg);
    const double       amg_solve      = timer.wall_time();
    const unsigned int amg_iterations = control.last_step();

    TrilinosWrappers::MPI::Vector y(rhs);
    timer.restart();
    for (unsigned int k = 0; k < 20; ++k)
      matrix.vmult(y, x);
    const double matrix_vmult = timer.wall_time() / 20;

    // --- The matrix-free path.
    timer.restart();
    using LevelOperator  = VelocityOperator<dim, float>;
    using LevelVector    = LinearAlgebra::distributed::Vector<float>;
    using ActiveOperator = VelocityOperator<dim, double>;
    using ActiveVector   = LinearAlgebra::distributed::Vector<double>;

    ActiveOperator active;
    {
      typename MatrixFree<dim, double>::AdditionalData data;
      data.tasks_parallel_scheme =
        MatrixFree<dim, double>::AdditionalData::none;
      data.mapping_update_flags = update_values | update_gradients |
                                  update_JxW_values | update_quadrature_points;
      auto storage = std::make_shared<MatrixFree<dim, double>>();
      storage->reinit(
        mapping, dof_handler, constraints, QGauss<1>(degree + 1), data);
      active.initialize(storage);
      active.set_coefficients(coefficients);
    }

    MGConstrainedDoFs mg_constrained_dofs;
    mg_constrained_dofs.initialize(dof_handler);
    mg_constrained_dofs.make_zero_boundary_constraints(dof_handler, {0});
    const unsigned int           n_levels = triangulation.n_global_levels();
    MGLevelObject<LevelOperator> levels(0, n_levels - 1);
    for (unsigned int l = 0; l < n_levels; ++l)
    {
      IndexSet relevant;
      DoFTools::extract_locally_relevant_level_dofs(dof_handler, l, relevant);
      AffineConstraints<double> level_constraints;
      level_constraints.reinit(relevant);
      level_constraints.add_lines(mg_constrained_dofs.get_boundary_indices(l));
      level_constraints.close();
      typename MatrixFree<dim, float>::AdditionalData data;
      data.tasks_parallel_scheme = MatrixFree<dim, float>::AdditionalData::none;
      data.mapping_update_flags  = update_values | update_gradients |
                                  update_JxW_values | update_quadrature_points;
      data.mg_level = l;
      auto storage  = std::make_shared<MatrixFree<dim, float>>();
      storage->reinit(
        mapping, dof_handler, level_constraints, QGauss<1>(degree + 1), data);
      levels[l].initialize(storage, mg_constrained_dofs, l);
      levels[l].set_coefficients(coefficients);
      levels[l].compute_diagonal();
    }
    MGTransferMatrixFree<dim, float> transfer(mg_constrained_dofs);
    transfer.build(dof_handler);

    using Smoother = PreconditionChebyshev<LevelOperator, LevelVector>;
    mg::SmootherRelaxation<Smoother, LevelVector>    smoother;
    MGLevelObject<typename Smoother::AdditionalData> smoother_data(0,
                                                                   n_levels -
                                                                     1);
    for (unsigned int l = 0; l < n_levels; ++l)
    {
      if (l > 0)
      {
        smoother_data[l].smoothing_range     = 15.;
        smoother_data[l].degree              = 5;
        smoother_data[l].eig_cg_n_iterations = 10;
      }
      else
      {
        // The coarse level solved by the Chebyshev iteration itself.
        smoother_data[0].smoothing_range     = 1e-3;
        smoother_data[0].degree              = numbers::invalid_unsigned_int;
        smoother_data[0].eig_cg_n_iterations = levels[0].m();
      }
      smoother_data[l].preconditioner = levels[l].get_matrix_diagonal_inverse();
    }
    smoother.initialize(levels, smoother_data);
    const double mf_geometry_setup = timer.wall_time();

    // What a new time step would redo when only the coefficients change:
    // the coefficients at the quadrature points, the diagonals and the
    // smoothers' eigenvalue estimates (the geometry above stays).
    timer.restart();
    active.set_coefficients(coefficients);
    for (unsigned int l = 0; l < n_levels; ++l)
    {
      levels[l].set_coefficients(coefficients);
      levels[l].compute_diagonal();
      smoother_data[l].preconditioner = levels[l].get_matrix_diagonal_inverse();
    }
    smoother.initialize(levels, smoother_data);
    const double mf_coefficient_setup = timer.wall_time();
    timer.restart();
    MGCoarseGridApplySmoother<LevelVector> coarse;
    coarse.initialize(smoother);
    mg::Matrix<LevelVector> mg_matrix(levels);
    MGLevelObject<MatrixFreeOperators::MGInterfaceOperator<LevelOperator>>
      interface(0, n_levels - 1);
    for (unsigned int l = 0; l < n_levels; ++l)
      interface[l].initialize(levels[l]);
    mg::Matrix<LevelVector> mg_interface(interface);
    Multigrid<LevelVector>  mg(mg_matrix, coarse, transfer, smoother, smoother);
    mg.set_edge_matrices(mg_interface, mg_interface);
    PreconditionMG<dim, LevelVector, MGTransferMatrixFree<dim, float>> gmg(
      dof_handler, mg, transfer);
    const double mf_setup = mf_geometry_setup + timer.wall_time();

    ActiveVector mf_rhs, mf_x;
    active.initialize_dof_vector(mf_rhs);
    active.initialize_dof_vector(mf_x);
    for (const auto i : dof_handler.locally_owned_dofs())
      mf_rhs(i) = rhs(i);
    SolverControl mf_control(2000, 1e-6 * mf_rhs.l2_norm());
    timer.restart();
    SolverCG<ActiveVector>(mf_control).solve(active, mf_x, mf_rhs, gmg);
    const double       mf_solve      = timer.wall_time();
    const unsigned int mf_iterations = mf_control.last_step();
    constraints.distribute(mf_x);

    ActiveVector mf_y(mf_x);
    timer.restart();
    for (unsigned int k = 0; k < 20; ++k)
      active.vmult(mf_y, mf_x);
    const double mf_vmult = timer.wall_time() / 20;

    // The two solutions agree to the solver tolerance.
    double difference = 0, norm = 0;
    for (const auto i : dof_handler.locally_owned_dofs())
    {
      difference = std::max(difference, std::abs(mf_x(i) - x(i)));
      norm       = std::max(norm, std::abs(x(i)));
    }

    std::size_t mf_memory = active.memory_consumption() +
                            active.get_matrix_free()->memory_consumption();
    for (unsigned int l = 0; l < n_levels; ++l)
      mf_memory += levels[l].memory_consumption() +
                   levels[l].get_matrix_free()->memory_consumption();

    std::cout << std::setprecision(3) << "  matrix + AMG:        set-up "
              << amg_setup << " s, " << amg_iterations << " CG iterations in "
              << amg_solve << " s, vmult " << 1e3 * matrix_vmult
              << " ms, matrix " << matrix.memory_consumption() / 1048576.
              << " MiB\n"
              << "  matrix-free + GMG:   set-up " << mf_setup
              << " s (per step when only coefficients change: "
              << mf_coefficient_setup << " s), " << mf_iterations
              << " CG iterations in " << mf_solve << " s, vmult "
              << 1e3 * mf_vmult << " ms, operators " << mf_memory / 1048576.
              << " MiB\n"
              << "  max |u_mf - u_amg| / max |u_amg| = " << difference / norm
              << std::endl;
  }
} // namespace


int
main(int argc, char **argv)
{
  Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  if (argc < 3)
  {
    std::cerr << "usage: velocity_block_matrix_free DIM LEVEL [C [BETA [NU]]]"
              << std::endl;
    return 1;
  }
  const unsigned int dim   = std::stoi(argv[1]);
  const unsigned int level = std::stoi(argv[2]);
  const auto         set   = [&](auto &coefficients)
  {
    if (argc > 3)
      coefficients.reaction_clear = std::stod(argv[3]);
    if (argc > 4)
      coefficients.drag = std::stod(argv[4]);
    if (argc > 5)
      coefficients.viscosity = std::stod(argv[5]);
  };
  if (dim == 2)
  {
    Coefficients<2> coefficients;
    set(coefficients);
    run<2>(level, coefficients);
  }
  else
  {
    Coefficients<3> coefficients;
    set(coefficients);
    run<3>(level, coefficients);
  }
  return 0;
}
