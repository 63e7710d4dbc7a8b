#include <deal.II/lac/solver_control.h>
#include <deal.II/lac/solver_gmres.h>

#include <immersed_grains/fluid/block_preconditioner.h>
#include <immersed_grains/fluid/coarse_schur_correction.h>
#include <immersed_grains/linear_algebra/ghost_exchange.h>

#include <Epetra_MultiVector.h>
#include <Teuchos_ParameterList.hpp>

#include <memory>

namespace ImmersedGrains
{
  BlockSchurPreconditioner::BlockSchurPreconditioner(
    const dealii::TrilinosWrappers::BlockSparseMatrix &system_matrix,
    const dealii::TrilinosWrappers::SparseMatrix      *pressure_mass,
    const dealii::TrilinosWrappers::SparseMatrix      *pressure_laplace,
    const Settings                                    &settings,
    const CoarseSchurCorrection                       *coarse,
    const ComponentBlock                              *velocity_block)
      : system_matrix(system_matrix)
      , system(system_matrix, velocity_block)
      , settings(settings)
      , pressure_mass(pressure_mass)
      , coarse(coarse)
  {
    if (settings.velocity_ilu)
    {
      // One layer of overlap, as for the AMG's smoother below.
      if (velocity_block != nullptr)
        velocity_ilu.initialize(*velocity_block, 1);
      else
        velocity_ilu.initialize(system_matrix.block(0, 0), 1);
    }
    else
    {
      dealii::TrilinosWrappers::PreconditionAMG::AdditionalData data;
      data.constant_modes        = settings.velocity_constant_modes;
      data.elliptic              = true;
      data.higher_order_elements = true;
      // ILU smoothing: where mass or drag dominates, A is nearly its own
      // smoother and the V-cycle is then almost exact; Chebyshev needed 4x
      // the outer iterations there (doc/benchmarks.md).
      // Also measured with the drag jumping by 1e8 (doc/benchmarks.md):
      // 4 ILU sweeps, Chebyshev, symmetric Gauss-Seidel and aggregation
      // thresholds 0 or 0.1 were all as good or worse. One sweep before
      // and after rather than two: 0-5 % more outer iterations on the
      // preconditioner benchmarks, but each V-cycle costs about half, and
      // the solves took 16-45 % less time (doc/performance.md, the
      // velocity AMG's smoother).
      data.smoother_type         = "ILU";
      data.smoother_sweeps       = 1;
      data.aggregation_threshold = settings.velocity_aggregation_threshold;
      // Each rank's ILU sees one layer of its neighbours' rows: where drag
      // dominates, the drag's own mass-matrix couplings cross the rank
      // boundary, and without the overlap 2 ranks needed 34-51 iterations
      // where 1 needs 16-28 (doc/benchmarks.md, "On two ranks").
      data.smoother_overlap = 1;
      Teuchos::ParameterList              parameters;
      std::unique_ptr<Epetra_MultiVector> constant_modes;
      data.set_parameters(parameters,
                          constant_modes,
                          system_matrix.block(0, 0));
      if (settings.velocity_coarse_gauss_seidel)
      {
        parameters.set("smoother: type", "symmetric Gauss-Seidel");
        parameters.set("smoother: type (level 0)", "ILU");
      }
      // On A even where A = K (x) I_dim: an AMG on K, applied to each
      // component, had the same outer iterations on the 3D cloud and a set-up
      // 40 % cheaper, but its V-cycles (one per component, as ML applies a
      // multi-vector) made the solves 17 % slower, which the preconditioner
      // builds of most scenes do not repay.
      // The finest level's smoother through K where there is one
      // (component_smoothed_amg.h): the 3D cloud's first 0.03 s on two
      // ranks took 2.2 s of preconditioner builds instead of 4.1 s and
      // 2.2 s of solves instead of 2.8 s, with the same V-cycle.
      if (velocity_block != nullptr)
        velocity_amg.initialize(system_matrix.block(0, 0),
                                *velocity_block,
                                parameters,
                                data.smoother_overlap);
      else
        velocity_amg.initialize(system_matrix.block(0, 0), parameters);
    }
    if (pressure_mass != nullptr)
    {
      pressure_mass_ilu.initialize(*pressure_mass);
      use_mass = true;
    }
    if (pressure_laplace != nullptr)
    {
      dealii::TrilinosWrappers::PreconditionAMG::AdditionalData data;
      data.elliptic              = true;
      data.higher_order_elements = false;
      data.smoother_sweeps       = 2;
      data.aggregation_threshold = 0.02;
      pressure_laplace_amg.initialize(*pressure_laplace, data);
      use_laplace = true;
    }
    velocity_tmp.reinit(system_matrix.block(0, 0).locally_owned_range_indices(),
                        system_matrix.get_mpi_communicator());
    velocity_residual.reinit(velocity_tmp);
    velocity_correction.reinit(velocity_tmp);
    pressure_tmp.reinit(system_matrix.block(1, 1).locally_owned_range_indices(),
                        system_matrix.get_mpi_communicator());
    if (settings.pressure_mass_iterations > 1)
    {
      cg_residual.reinit(pressure_tmp);
      cg_preconditioned.reinit(pressure_tmp);
      cg_direction.reinit(pressure_tmp);
      cg_product.reinit(pressure_tmp);
    }
  }


  void
  BlockSchurPreconditioner::vmult(VectorType &dst, const VectorType &src) const
  {
    if (coarse != nullptr)
    {
      // Two levels: the coarse saddle point system first, then the block
      // preconditioner on the residual it leaves (a multiplicative
      // correction; applied after instead, or on both sides, it took as
      // many or more outer iterations, doc/adaptivity.md).
      if (coarse_correction.n_blocks() == 0)
      {
        coarse_correction.reinit(src);
        coarse_residual.reinit(src);
      }
      coarse->vmult(coarse_correction, src);
      system.vmult(coarse_residual, coarse_correction);
      coarse_residual.sadd(-1.0, 1.0, src);
      apply_block(dst, coarse_residual);
      dst += coarse_correction;
      return;
    }
    apply_block(dst, src);
  }


  void
  BlockSchurPreconditioner::apply_block(VectorType       &dst,
                                        const VectorType &src) const
  {
    // Pressure: -S~^{-1} g.
    dst.block(1) = 0;
    if (use_mass)
      solve_pressure_mass(dst.block(1), src.block(1));
    if (use_laplace)
    {
      pressure_laplace_amg.vmult(pressure_tmp, src.block(1));
      dst.block(1) += pressure_tmp;
    }
    dst.block(1) *= -1.0;

    // Velocity: A~^{-1} (f - B^T p), AMG cycles as a stationary iteration.
    system_matrix.block(0, 1).vmult(velocity_residual, dst.block(1));
    velocity_residual.sadd(-1.0, 1.0, src.block(0));
    solve_velocity(dst.block(0), velocity_residual);
  }


  void
  BlockSchurPreconditioner::solve_velocity(
    dealii::TrilinosWrappers::MPI::Vector       &dst,
    const dealii::TrilinosWrappers::MPI::Vector &src) const
  {
    // A as an operator (its component block where it has one).
    struct VelocityOperator
    {
      const SaddlePointOperator &system;
      void
      vmult(dealii::TrilinosWrappers::MPI::Vector       &dst,
            const dealii::TrilinosWrappers::MPI::Vector &src) const
      {
        system.vmult_velocity(dst, src);
      }
    } const A{system};
    if (settings.inner_iterations > 0)
    {
      // A Krylov method accelerates the AMG where a few modes converge
      // slowly (drag jumping by orders of magnitude); FGMRES outside
      // accepts the resulting variable preconditioner. A fixed iteration
      // count rather than a loose tolerance: the residual's l2 norm is
      // dominated by the rows of the high-drag region, so a loose relative
      // tolerance (10^-2, tried with CG) stopped before the viscous region
      // was solved at all.
      dealii::ReductionControl control(
        settings.inner_iterations, 0, settings.inner_tolerance, false, false);
      dst = 0;
      try
      {
        // GMRES even where A is symmetric: the V-cycle with ILU smoothing
        // is not symmetric enough for CG, which stalled in some of the
        // drag-jump cases (doc/benchmarks.md).
        dealii::SolverGMRES<dealii::TrilinosWrappers::MPI::Vector> gmres(
          control,
          dealii::SolverGMRES<dealii::TrilinosWrappers::MPI::Vector>::
            AdditionalData(settings.inner_iterations + 1));
        gmres.solve(A, dst, src, velocity_preconditioner());
      }
      catch (const dealii::SolverControl::NoConvergence &)
      {
        // The iterate is still a good preconditioner; FGMRES decides.
      }
      return;
    }

    // A stationary iteration with the V-cycle or the ILU.
    const auto &preconditioner = velocity_preconditioner();
    preconditioner.vmult(dst, src);
    for (unsigned int cycle = 1; cycle < settings.velocity_cycles; ++cycle)
    {
      A.vmult(velocity_tmp, dst);
      velocity_tmp.sadd(-1.0, 1.0, src);
      preconditioner.vmult(velocity_correction, velocity_tmp);
      dst += velocity_correction;
    }
  }


  const dealii::TrilinosWrappers::PreconditionBase &
  BlockSchurPreconditioner::velocity_preconditioner() const
  {
    if (settings.velocity_ilu)
      return velocity_ilu;
    return velocity_amg;
  }


  void
  BlockSchurPreconditioner::solve_pressure_mass(
    dealii::TrilinosWrappers::MPI::Vector       &dst,
    const dealii::TrilinosWrappers::MPI::Vector &src) const
  {
    if (settings.pressure_mass_iterations <= 1)
    {
      pressure_mass_ilu.vmult(dst, src);
      return;
    }
    // On one rank, ILU(0) of the mass matrix is as good as its exact
    // inverse here; on several it is block-Jacobi, and the outer count rose
    // from 24 to 36 (2D level 7, steady Stokes, doc/benchmarks.md). A few CG
    // iterations make M_w^{-1} nearly exact on any partition for the price
    // of a few pressure-sized products; FGMRES outside accepts the
    // resulting variable preconditioner. They stop at a relative residual
    // below which the outer count no longer changes, so that where the ILU
    // alone is that accurate (one rank: 10^-5..10^-4) one iteration is
    // done. Written out rather than dealii::SolverCG, whose temporary
    // vectors cost more than the iteration on pressure spaces of a few
    // thousand DoFs (the 2D cloud's step: 1.5 ms of 33).
    const auto  &M    = *pressure_mass;
    auto        &r    = cg_residual;
    auto        &z    = cg_preconditioned;
    auto        &p    = cg_direction;
    auto        &Mp   = cg_product;
    const double stop = settings.pressure_mass_tolerance * src.l2_norm();
    dst               = 0;
    // A copy without deal.II's comparison of the two vectors' maps (a
    // reduction over the ranks at each of these inner solves).
    GhostExchange::copy(src, r);
    pressure_mass_ilu.vmult(z, r);
    p              = z;
    double r_dot_z = r * z;
    for (unsigned int k = 0; k < settings.pressure_mass_iterations; ++k)
    {
      M.vmult(Mp, p);
      const double p_Mp = p * Mp;
      if (!(p_Mp > 0))
        break; // src = 0, or round-off at the solution
      const double alpha = r_dot_z / p_Mp;
      dst.add(alpha, p);
      r.add(-alpha, Mp);
      if (r.l2_norm() <= stop || k + 1 == settings.pressure_mass_iterations)
        break;
      pressure_mass_ilu.vmult(z, r);
      const double r_dot_z_new = r * z;
      p.sadd(r_dot_z_new / r_dot_z, 1.0, z);
      r_dot_z = r_dot_z_new;
    }
  }
} // namespace ImmersedGrains
