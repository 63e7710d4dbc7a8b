#include <deal.II/dofs/dof_tools.h>
#include <deal.II/lac/solver_control.h>
#include <deal.II/lac/solver_gmres.h>
#include <deal.II/lac/trilinos_index_access.h>
#include <deal.II/lac/trilinos_solver.h>
#include <deal.II/lac/trilinos_sparse_matrix.h>
#include <deal.II/lac/trilinos_sparsity_pattern.h>
#include <deal.II/lac/trilinos_vector.h>

#include <immersed_grains/fluid/block_preconditioner.h>
#include <immersed_grains/fluid/coarse_schur_correction.h>
#include <immersed_grains/fluid/fluid_solver.h>
#include <immersed_grains/fluid/trilinos_rows.h>

#include <cmath>
#include <limits>

#include <algorithm>
#include <cstdlib>
#include <sstream>

namespace ImmersedGrains
{


  template <int dim>
  void
  FluidSolver<dim>::build_preconditioner()
  {
    dealii::TimerOutput::Scope scope(timer, "fluid: preconditioner");
    rebuild_requested      = false;
    built_mass_coefficient = mass_coefficient();
    ++builds;

    // ILU or AMG for the velocity block: where mass and drag dominate its
    // viscous and advective parts on the scale of the velocity nodes, A is
    // nearly diagonal, and one ILU sweep, a few matrix-vector products'
    // cost, replaces two V-cycles of ILU-smoothed AMG. Lethe's
    // sedimentation scene (viscous number 2e-3): 8 instead of 6 outer
    // iterations, 25 instead of 200 ms each. The drag-jump benchmark at 2D
    // level 7: the ILU's FGMRES time is a quarter to a third of the AMG's
    // up to a viscous number of 0.7 (9-19 iterations), about the same at
    // 7 (55 iterations), three times the AMG's at 66 (191). The default
    // threshold 1 keeps the ILU within 30 iterations there; Lethe's scene
    // on a 20 x 100 x 20 mesh, whose advection raises the number to 0.36,
    // took 20 s per step with the AMG and 7-8 s with the ILU
    // (doc/performance.md).
    using Choice        = typename FluidParameters<dim>::VelocityPreconditioner;
    const bool previous = velocity_ilu;
    velocity_ilu =
      parameters.velocity_preconditioner == Choice::ilu ||
      (parameters.velocity_preconditioner == Choice::automatic &&
       velocity_viscous_number < parameters.velocity_ilu_threshold);
    if (builds == 1 || previous != velocity_ilu)
      pcout << "  fluid: velocity block preconditioned by "
            << (velocity_ilu ? "ILU" : "AMG") << " (viscous number "
            << velocity_viscous_number << ")" << std::endl;

    BlockSchurPreconditioner::Settings settings;
    settings.velocity_ilu     = velocity_ilu;
    settings.velocity_cycles  = velocity_ilu ? parameters.velocity_ilu_sweeps :
                                               parameters.velocity_amg_cycles;
    settings.inner_iterations = parameters.velocity_inner_iterations;
    settings.inner_tolerance  = parameters.velocity_inner_tolerance;
    settings.pressure_mass_iterations = parameters.pressure_mass_iterations;
    settings.pressure_mass_tolerance  = parameters.pressure_mass_tolerance;
    settings.velocity_aggregation_threshold = dim == 2 ? 0.05 : 0.02;
    // In 2D the coarse levels are light and ILU smooths them better (the
    // preconditioner benchmark: 1154 instead of 1130 iterations, 7 % more
    // time).
    settings.velocity_coarse_gauss_seidel = dim == 3;
    const dealii::FEValuesExtractors::Vector velocities(0);
    dealii::DoFTools::extract_constant_modes(dof_handler,
                                             fe.component_mask(velocities),
                                             settings.velocity_constant_modes);
    // ML is given the near null space but not that the DoFs come in
    // groups of dim. Where the components do not couple, every aggregate
    // lies in one component, on which dim - 1 of the component-wise
    // constant modes vanish, and ML still keeps a coarse DoF for each: the
    // coarse levels were dim times larger than their one mode per
    // aggregate (3D: operator complexity 1.37 instead of 1.05). One mode,
    // the constant on every component, gives each aggregate the mode it
    // has: the same aggregates, the preconditioner benchmark's builds
    // 20-40 % and its solves 12-40 % cheaper for 0.8 % more iterations
    // (doc/performance.md). A rank without DoFs gets no
    // modes from extract_constant_modes.
    if (!velocity_components_coupled() &&
        !settings.velocity_constant_modes.empty())
    {
      std::vector<bool> any_component(
        settings.velocity_constant_modes.front().size(), false);
      for (const auto &mode : settings.velocity_constant_modes)
        for (unsigned int i = 0; i < mode.size(); ++i)
          any_component[i] = any_component[i] || mode[i];
      settings.velocity_constant_modes = {any_component};
    }

    // The two-level correction: its coarse space once per mesh, its
    // operators with every preconditioner.
    if (parameters.coarse_correction && !coarse_schur)
    {
      const int coarse_level = coarse_correction_level();
      if (coarse_level >= 0)
      {
        coarse_schur =
          std::make_unique<CoarseSchurCorrection>(dof_handler,
                                                  update_constraints,
                                                  geometry,
                                                  coarse_level,
                                                  owned_partitioning,
                                                  mpi_communicator);
        pcout << "  fluid: two-level preconditioner, the box's coarse mesh "
                 "refined "
              << coarse_level << " times (" << coarse_schur->n_dofs()
              << " coarse DoFs)" << std::endl;
      }
    }
    if (coarse_schur)
    {
      // The share of mass and drag in A's diagonal (with its floor, at
      // most 0.3 of the viscous part) sorts the fine velocities between
      // the coarse space's viscous and drag parts (doc/adaptivity.md).
      const auto                           &A = system_matrix.block(0, 0);
      dealii::TrilinosWrappers::MPI::Vector drag_share(owned_partitioning[0],
                                                       mpi_communicator);
      for (const auto i : owned_partitioning[0])
        drag_share[i] =
          reaction_diagonal.block(0)[i] / std::abs(A.diag_element(i));
      drag_share.compress(dealii::VectorOperation::insert);
      coarse_schur->build(system_matrix, drag_share, pressure_has_null_space());
    }
    // Steady flow without drag in a box at least twice as long as wide:
    // the pressure modes that vary slowly along it are those of Poiseuille
    // flow between its walls, a Darcy law of permeability ~ W^2 that the
    // mass term misses (its inf-sup constant falls like the inverse aspect
    // ratio). The floor's Darcy term, at a quarter of its coefficient,
    // catches them: a 1 x 8 column 38-46 -> 27-32 outer iterations, a
    // 1 x 1/8 slab 22-33 -> 16-31 (2D and 3D, levels 1-5; doc/adaptivity.md).
    // In a cube it only adds error (2D level 6: 21 -> 30), hence the gate.
    const bool long_modes =
      !parameters.time_derivative && !schur_has_drag &&
      geometry.longest_side() >= 2 * geometry.shortest_side();
    const bool mass_term =
      parameters.schur_approximation != SchurApproximation::pressure_laplace;
    const bool laplace_term =
      parameters.schur_approximation != SchurApproximation::pressure_mass &&
      (parameters.time_derivative || schur_has_drag || long_modes);
    if (laplace_term)
    {
      // S_c = B diag(c M)^{-1} B^T: the Schur complement where A is
      // dominated by its mass and drag part c M, whatever the jumps in c
      // (= phi rho a0/dt + beta); a Darcy-like operator on the pressure.
      // Where c vanishes (viscous regions of a steady problem) the term
      // must vanish from S~^{-1}: a floor on c, assembled into
      // reaction_diagonal (schur_floor_factor in fluid_assembly.cc), keeps
      // the inverse finite while making S_c large there. Constrained
      // velocities (empty B^T rows) have none and keep a hundredth of A's
      // diagonal, only so that the inverse exists.
      const auto                           &A = system_matrix.block(0, 0);
      dealii::TrilinosWrappers::MPI::Vector inverse_diagonal(
        owned_partitioning[0], mpi_communicator);
      const double floor_scale = long_modes ? 0.25 : 1.0; // c is the floor
      for (const auto i : owned_partitioning[0])
      {
        const double c = floor_scale * reaction_diagonal.block(0)[i];
        inverse_diagonal[i] =
          1.0 / (c > 0 ? c : 1e-2 * std::abs(A.diag_element(i)));
      }
      inverse_diagonal.compress(dealii::VectorOperation::insert);
      dealii::TrilinosWrappers::SparseMatrix product;
      system_matrix.block(1, 0).mmult(product,
                                      system_matrix.block(0, 1),
                                      inverse_diagonal);

      // Pressure DoFs constrained by hanging nodes or periodicity have
      // empty rows in the product; AMG needs a diagonal everywhere. So the
      // matrix handed on has the product's pattern plus the diagonal (built
      // once per mesh), empty rows get the mean diagonal, and without an
      // open face every diagonal entry grows by a millionth of itself,
      // which removes the constant null space for AMG's coarse solve. The
      // shift must be relative: S_c's diagonal spans the contrast of c
      // (10^10 and more between clear fluid and a packed bed), and a
      // millionth of the mean diagonal swamped the rows of the drag
      // region, where S_c^{-1} then lost its Darcy term
      // (doc/benchmarks.md: 186 instead of 33 iterations).
      if (schur_diagonal_matrix.m() != product.m())
      {
        dealii::TrilinosWrappers::SparsityPattern pattern(owned_partitioning[1],
                                                          owned_partitioning[1],
                                                          mpi_communicator);
        for (const auto i : owned_partitioning[1])
          pattern.add(i, i);
        for_each_owned_row(product.trilinos_matrix(),
                           [&](const auto row, const auto &columns, auto) {
                             pattern.add_entries(row,
                                                 columns.begin(),
                                                 columns.end());
                           });
        pattern.compress();
        schur_diagonal_matrix.reinit(pattern);
      }
      schur_diagonal_matrix = 0;
      double       mean     = 0;
      unsigned int n        = 0;
      for_each_owned_row(
        product.trilinos_matrix(),
        [&](const auto row, const auto &columns, const double *values)
        {
          schur_diagonal_matrix.set(
            row, columns.size(), columns.data(), values, false);
          for (unsigned int k = 0; k < columns.size(); ++k)
            if (columns[k] == row && values[k] != 0)
            {
              mean += values[k];
              ++n;
            }
        });
      schur_diagonal_matrix.compress(dealii::VectorOperation::insert);
      // The pressure block -C (the grains' pressure mobility, zero without
      // grains) belongs to the Schur complement C + B A^-1 B^T; its pattern
      // lies within the product's.
      std::vector<double> negated;
      for_each_owned_row(
        system_matrix.block(1, 1).trilinos_matrix(),
        [&](const auto row, const auto &columns, const double *values)
        {
          negated.assign(values, values + columns.size());
          for (double &value : negated)
            value = -value;
          schur_diagonal_matrix.add(
            row, columns.size(), columns.data(), negated.data(), true);
        });
      schur_diagonal_matrix.compress(dealii::VectorOperation::add);
      mean = dealii::Utilities::MPI::sum(mean, mpi_communicator) /
             std::max(1u, dealii::Utilities::MPI::sum(n, mpi_communicator));
      const double shift = pressure_has_null_space() ? 1e-6 : 0.0;
      for (const auto i : owned_partitioning[1])
      {
        const double d = schur_diagonal_matrix.diag_element(i);
        schur_diagonal_matrix.set(i, i, d == 0 ? mean : d * (1 + shift));
      }
      schur_diagonal_matrix.compress(dealii::VectorOperation::insert);
    }
    preconditioner = std::make_unique<BlockSchurPreconditioner>(
      system_matrix,
      (mass_term || !laplace_term) ? &pressure_mass_matrix.block(1, 1) :
                                     nullptr,
      laplace_term ? &schur_diagonal_matrix : nullptr,
      settings,
      coarse_schur.get(),
      velocity_block.get());
  }


  namespace
  {
    // Copies a block matrix whose blocks are contiguous ranges of the global
    // DoF numbering into one matrix, for a sparse direct solver. Row
    // @p pinned (if valid) becomes the identity row: the zero pressure
    // block has no stored diagonal to overwrite afterwards.
    void
    copy_to_monolithic(
      const dealii::TrilinosWrappers::BlockSparseMatrix &blocks,
      dealii::TrilinosWrappers::SparseMatrix            &matrix,
      const dealii::types::global_dof_index              pinned)
    {
      dealii::types::global_dof_index offsets[2] = {0, blocks.block(0, 0).m()};
      for (unsigned int bi = 0; bi < 2; ++bi)
        for (unsigned int bj = 0; bj < 2; ++bj)
        {
          const auto &block = blocks.block(bi, bj);
          for (const auto row : block.locally_owned_range_indices())
          {
            if (row + offsets[bi] == pinned)
              continue;
            for (auto entry = block.begin(row); entry != block.end(row);
                 ++entry)
              if (entry->value() != 0)
                matrix.set(row + offsets[bi],
                           entry->column() + offsets[bj],
                           entry->value());
          }
        }
      if (pinned != dealii::numbers::invalid_dof_index &&
          matrix.locally_owned_range_indices().is_element(pinned))
        matrix.set(pinned, pinned, 1.0);
      matrix.compress(dealii::VectorOperation::insert);
    }
  } // namespace


  template <int dim>
  unsigned int
  FluidSolver<dim>::solve_linear_system(const double absolute_tolerance,
                                        const bool   fresh_preconditioner)
  {
    if (parameters.direct_solver)
    {
      dealii::TimerOutput::Scope scope(timer, "fluid: direct solve");
      const dealii::IndexSet     owned = dof_handler.locally_owned_dofs();
      // Rows are filled by insertion: fine for the small problems this
      // path is meant for.
      dealii::TrilinosWrappers::SparseMatrix matrix(
        owned, owned, mpi_communicator, 30 * (dim + 1) * (dim == 3 ? 3 : 1));
      const dealii::types::global_dof_index n_u = system_matrix.block(0, 0).m();
      // A singular (pure-Neumann pressure) system has one zero pivot; pin
      // one pressure DoF of the update, the mean is fixed afterwards.
      const dealii::types::global_dof_index pinned =
        pressure_has_null_space() ? n_u : dealii::numbers::invalid_dof_index;
      copy_to_monolithic(system_matrix, matrix, pinned);
      dealii::TrilinosWrappers::MPI::Vector x(owned, mpi_communicator),
        b(owned, mpi_communicator);
      for (unsigned int bi = 0; bi < 2; ++bi)
        for (const auto i : owned_partitioning[bi])
          b[i + (bi == 0 ? 0 : n_u)] =
            (i + (bi == 0 ? 0 : n_u) == pinned) ? 0.0 : system_rhs.block(bi)[i];
      b.compress(dealii::VectorOperation::insert);

      dealii::SolverControl                  control(1, 0);
      dealii::TrilinosWrappers::SolverDirect solver(control);
      solver.solve(matrix, x, b);
      for (unsigned int bi = 0; bi < 2; ++bi)
        for (const auto i : owned_partitioning[bi])
          newton_update.block(bi)[i] = x[i + (bi == 0 ? 0 : n_u)];
      newton_update.compress(dealii::VectorOperation::insert);
      return 1;
    }

    if (fresh_preconditioner)
      build_preconditioner();
    // Relative to this system's right-hand side, but no tighter than the
    // nonlinear iteration needs: late Picard/Newton corrections are tiny.
    // Tighter where the velocity-error check found the velocities slow
    // against what the right-hand side drives (below).
    const double tolerance =
      velocity_tolerance_factor *
      std::max(parameters.linear_tolerance * system_rhs.l2_norm(),
               absolute_tolerance);
    // A kept preconditioner that needs three times the iterations that
    // would ask for a rebuild no longer fits: stop there and rebuild now
    // rather than run to Max iterations first (a collapsing packing spent
    // 500 iterations on a step that the rebuilt one solved in 13-19,
    // doc/performance.md).
    const unsigned int budget =
      fresh_preconditioner || parameters.preconditioner_rebuild_ratio == 0 ?
        parameters.max_linear_iterations :
        std::min<unsigned int>(
          parameters.max_linear_iterations,
          std::max(30.0,
                   3 * (parameters.preconditioner_rebuild_ratio *
                          iterations_after_rebuild +
                        3)));
    const SaddlePointOperator system(system_matrix, velocity_block.get());
    dealii::SolverControl     control(budget, tolerance);
    dealii::SolverFGMRES<VectorType> solver(
      control,
      krylov_vectors,
      typename dealii::SolverFGMRES<VectorType>::AdditionalData(100));
    unsigned int failed_iterations = 0;
    try
    {
      dealii::TimerOutput::Scope scope(timer, "fluid: solve");
      newton_update = 0;
      solver.solve(system, newton_update, system_rhs, *preconditioner);
    }
    catch (const dealii::SolverControl::NoConvergence &e)
    {
      AssertThrow(std::isfinite(e.last_residual),
                  dealii::ExcMessage(
                    "Fluid: the linear system is not finite (FGMRES residual "
                    "NaN or Inf in iteration " +
                    std::to_string(e.last_step) +
                    "): the state it was assembled from diverged, or a "
                    "forcing or boundary value is not finite."));
      if (fresh_preconditioner)
        AssertThrow(false,
                    dealii::ExcMessage(
                      "Fluid: FGMRES did not converge in " +
                      std::to_string(e.last_step) + " iterations (residual " +
                      [&]
                      {
                        std::ostringstream r;
                        r << e.last_residual;
                        return r.str();
                      }() +
                      ", Fluid/Linear solver/Max iterations = " +
                      std::to_string(parameters.max_linear_iterations) + ")."));
      // A kept preconditioner that no longer fits: build a fresh one (its
      // matrices were not assembled this time) and solve again.
      failed_iterations = e.last_step;
      assemble_system(true);
      return failed_iterations + solve_linear_system(absolute_tolerance, true);
    }

    // The residual bounds the velocity error only relative to the velocity
    // the right-hand side drives; where the flow is far slower (a packed
    // suspension barely settling), estimate the error itself, e = P^-1 r,
    // and go on while it is large against the velocity. The estimate costs
    // a preconditioner application, a fifth of a typical solve: it runs
    // after each rebuild and every tenth solve, and the tolerance it
    // settles on serves the solves in between.
    unsigned int iterations = control.last_step();
    if (parameters.velocity_error_tolerance > 0 &&
        (fresh_preconditioner || ++solves_since_velocity_check >= 10))
    {
      solves_since_velocity_check = 0;
      dealii::TimerOutput::Scope scope(timer, "fluid: solve");
      VectorType residual(newton_update), estimate(newton_update),
        velocity(newton_update);
      double target = tolerance, reached = tolerance;
      for (unsigned int round = 0; round < 3; ++round)
      {
        system.vmult(residual, newton_update);
        residual.sadd(-1.0, 1.0, system_rhs);
        preconditioner->vmult(estimate, residual);
        ghost_exchange.to_owned(solution, velocity);
        velocity.block(0).add(1.0, newton_update.block(0));
        const double error = estimate.block(0).linfty_norm();
        const double scale = velocity.block(0).linfty_norm();
        if (scale == 0 || error <= parameters.velocity_error_tolerance * scale)
        {
          // Well within: let later solves loosen towards Tolerance.
          if (round == 0 &&
              error <= 0.1 * parameters.velocity_error_tolerance * scale)
            velocity_tolerance_factor =
              std::min(1.0, 10 * velocity_tolerance_factor);
          break;
        }
        // Not below round-off: 1e-14 of the right-hand side.
        const double floor = 1e-14 * system_rhs.l2_norm();
        if (target <= floor)
          break;
        target =
          std::max(floor,
                   target *
                     std::clamp(0.5 * parameters.velocity_error_tolerance *
                                  scale / error,
                                1e-3,
                                0.5));
        dealii::SolverControl tighter(parameters.max_linear_iterations, target);
        dealii::SolverFGMRES<VectorType> on(
          tighter,
          krylov_vectors,
          typename dealii::SolverFGMRES<VectorType>::AdditionalData(100));
        try
        {
          on.solve(system, newton_update, system_rhs, *preconditioner);
          iterations += tighter.last_step();
          reached = target;
        }
        catch (const dealii::SolverControl::NoConvergence &e)
        {
          // Round-off: the update is as good as this solver makes it.
          iterations += e.last_step;
          break;
        }
      }
      // At most 10^4 below Tolerance for the solves that follow.
      velocity_tolerance_factor =
        std::max(1e-4, velocity_tolerance_factor * reached / tolerance);
    }

    // A solve right after a rebuild sets the yardstick; one with a kept
    // preconditioner that takes clearly longer asks for a rebuild.
    if (fresh_preconditioner)
      iterations_after_rebuild = control.last_step();
    else if (control.last_step() > parameters.preconditioner_rebuild_ratio *
                                       iterations_after_rebuild +
                                     3)
      rebuild_requested = true;
    return iterations;
  }


  template <int dim>
  int
  FluidSolver<dim>::coarse_correction_level() const
  {
    // Coarser than the mesh's coarsest cells (else the coarse space would
    // be as large as the fine one), and small enough for a direct solve.
    int coarsest = std::numeric_limits<int>::max();
    for (const auto &cell : triangulation.active_cell_iterators())
      if (cell->is_locally_owned())
        coarsest = std::min(coarsest, cell->level());
    coarsest = -dealii::Utilities::MPI::max(-coarsest, mpi_communicator);
    int level =
      std::min<int>(parameters.coarse_correction_refinement, coarsest - 1);
    const std::size_t cells = geometry.n_coarse_cells();
    while (level >= 0 && (cells << (dim * level)) > (dim == 2 ? 4096u : 512u))
      --level;
    return level;
  }


  template void
  FluidSolver<2>::build_preconditioner();
  template void
  FluidSolver<3>::build_preconditioner();
  template int
  FluidSolver<2>::coarse_correction_level() const;
  template int
  FluidSolver<3>::coarse_correction_level() const;
  template unsigned int
  FluidSolver<2>::solve_linear_system(double, bool);
  template unsigned int
  FluidSolver<3>::solve_linear_system(double, bool);
} // namespace ImmersedGrains
