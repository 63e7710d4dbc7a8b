#include <immersed_grains/coupling/coupled_step.h>
#include <immersed_grains/coupling/coupling.h>
#include <immersed_grains/io/statistics.h>

#include <sstream>

namespace ImmersedGrains
{
  template <int dim>
  CoupledStep<dim>::CoupledStep(dealii::ConditionalOStream &pcout,
                                const bool                  sphere_packing_hint)
      : pcout(pcout)
      , sphere_packing_hint(sphere_packing_hint)
  {
  }


  template <int dim>
  CoupledStepReport<dim>
  CoupledStep<dim>::advance(Coupling<dim>     &coupling,
                            FluidSolver<dim>  &fluid,
                            Grains<dim>       &grains,
                            const double       time,
                            const double       dt,
                            const double       previous_dt,
                            const bool         first_step,
                            const unsigned int step)
  {
    CoupledStepReport<dim> report;
    grains.gather();
    // Grains that the last steps sped up beyond what one fluid step can
    // follow (the sub-steps below keep each within an eighth of the
    // smallest radius): the step fails before anything has changed, so
    // that it can be taken again shorter, as a fluid step that fails.
    if (coupling.grain_substeps())
    {
      const unsigned int needed = grains.substeps(dt);
      if (needed > coupling.max_grain_substeps())
      {
        std::ostringstream message;
        message << "the grains would need " << needed
                << " grain sub-steps in this fluid step of " << dt
                << " s, over Coupling/Maximum grain sub-steps = "
                << coupling.max_grain_substeps()
                << ": their speeds have outgrown the step (a coupling grown "
                   "unstable at a step too long, doc/stability.md). A "
                   "shorter Time step, or Adaptive time step = true, which "
                   "takes such a step again with half its length.";
        throw FluidStepFailure(message.str());
      }
    }
    coupling.project(grains, dt);
    // Grains packed beyond 1 - Minimum fluid fraction: the fluid sees the
    // minimum there. Said when it starts, counted every step.
    report.clamped_nodes = coupling.solid_fraction().n_clamped();
    if (report.clamped_nodes > 0 && clamped_before == 0)
    {
      pcout << "  warning: step " << step << ": the grains pack beyond "
            << "the bound of Coupling/Minimum fluid fraction at "
            << report.clamped_nodes
            << " solid-fraction node(s); the fluid sees the bound there "
            << "(column clamped_fluid_fraction_nodes)\n";
      if (dim == 2 && !sphere_packing_hint)
        pcout << "  (discs pack to area fractions up to 0.91: for a "
              << "packed 2D bed set Coupling/Closure porosity in 2D = "
              << "sphere packing, doc/theory.md)\n";
    }
    clamped_before = report.clamped_nodes;

    // (Collective: decided by the layout, which every rank shares, not by
    // this rank's grains.)
    if (first_step &&
        grains.layout().contact_impulse != GrainPropertyLayout::absent)
    {
      // No contact impulse is known yet: a contact solve in the initial
      // fluid predicts the first, so that grains resting on each other at
      // the start are held from the first step (prepare_fluid_drag()), and
      // starts the relaxed prediction there.
      coupling.set_substep_grain_forces(grains, fluid, dt);
      grains.compute_free_velocities(dt);
      grains.resolve_contacts(dt);
      auto &arrays             = grains.step_arrays();
      arrays.predicted_impulse = arrays.contact_impulse;
      auto &c                  = arrays.contact;
      c.velocity               = c.start_velocity;
    }
    coupling.project_departed(grains, dt);
    coupling.prepare_fluid_drag(grains, fluid, dt, previous_dt);
    report.fluid = fluid.solve_time_step(time + dt, dt);
    // What this step took out of the mixture (a step that failed above
    // is taken again with all of it).
    grains.drain_departed(dt);
    coupling.set_grain_forces(grains, fluid, dt);
    grains.compute_free_velocities(dt);
    // Grains that this step would move too far take equal sub-steps
    // through its fluid; the first with the force the fluid's implicit
    // update assumed.
    report.substeps      = coupling.grain_substeps() ? grains.substeps(dt) : 1;
    const double substep = dt / report.substeps;
    if (report.substeps > 1)
      grains.compute_free_velocities(substep);
    report.grains = grains.resolve_contacts(substep);
    // Newton's third law between the phases: the drag the fluid receives
    // over the step, integrated through its own fields, against the drag
    // the grains' implicit updates received, summed over the sub-steps
    // (with more than one, the later ones re-evaluate the drag the fluid's
    // prediction assumed; the difference is owed to the fluid, and repaid
    // in the next step unless Coupling/Repay drag mismatch = false).
    const dealii::Tensor<1, dim> on_fluid =
      coupling.drag_on_fluid(grains, fluid);
    dealii::Tensor<1, dim> on_grains =
      coupling.account_drag_on_grains(grains, substep);
    dealii::Tensor<1, dim> owed;
    if (report.substeps == 1)
      owed = coupling.settle_exchange_owed(grains);
    report.grains.removed = grains.move_and_scatter(substep);
    for (unsigned int k = 1; k < report.substeps; ++k)
    {
      grains.gather();
      coupling.set_substep_grain_forces(grains, fluid, substep);
      grains.compute_free_velocities(substep);
      GrainStepReport later = grains.resolve_contacts(substep, true);
      on_grains += coupling.account_drag_on_grains(grains, substep);
      if (k + 1 == report.substeps)
        owed = coupling.settle_exchange_owed(grains);
      later.removed = grains.move_and_scatter(substep);
      report.grains.add_substep(later);
    }

    // The step's mean drag on the grains, and the books.
    on_grains /= report.substeps;
    report.drag_on_grains  = on_grains.norm();
    const double exchanged = dt * on_grains.norm();
    if (exchanged > 0)
    {
      report.exchange_error = (on_fluid + on_grains).norm() / on_grains.norm();
      report.exchange_owed  = owed.norm() / exchanged;
    }
    exchange.imbalance += dt * (on_fluid + on_grains);
    exchange.impulse += exchanged;
    if (exchange.impulse > 0)
      report.exchange_drift =
        (exchange.imbalance - owed).norm() / exchange.impulse;
    return report;
  }


  template <int dim>
  std::vector<std::string>
  CoupledStep<dim>::column_names()
  {
    return {"drag_force_on_grains",
            "momentum_exchange_error",
            "grain_substeps",
            "clamped_fluid_fraction_nodes",
            "momentum_exchange_owed",
            "momentum_exchange_drift"};
  }


  template <int dim>
  void
  CoupledStep<dim>::set_statistics(const CoupledStepReport<dim> &report,
                                   Statistics                   &statistics)
  {
    statistics.set("drag_force_on_grains", report.drag_on_grains);
    statistics.set("momentum_exchange_error", report.exchange_error);
    statistics.set("grain_substeps", report.substeps);
    statistics.set("clamped_fluid_fraction_nodes", report.clamped_nodes);
    statistics.set("momentum_exchange_owed", report.exchange_owed);
    statistics.set("momentum_exchange_drift", report.exchange_drift);
  }


  template class CoupledStep<2>;
  template class CoupledStep<3>;
} // namespace ImmersedGrains
