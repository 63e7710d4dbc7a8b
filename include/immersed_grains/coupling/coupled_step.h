#ifndef immersed_grains_coupling_coupled_step_h
#define immersed_grains_coupling_coupled_step_h

#include <deal.II/base/conditional_ostream.h>
#include <deal.II/base/tensor.h>

#include <immersed_grains/fluid/fluid_solver.h>
#include <immersed_grains/grains/grains.h>

#include <string>
#include <vector>

namespace ImmersedGrains
{
  template <int dim>
  class Coupling;
  class Statistics;

  /** What one coupled step did (global figures), for the statistics. */
  template <int dim>
  struct CoupledStepReport
  {
    GrainStepReport                           grains;
    typename FluidSolver<dim>::StepStatistics fluid;
    unsigned int                              substeps = 1;
    // Solid-fraction nodes where the grains pack beyond the bound of
    // Coupling/Minimum fluid fraction.
    unsigned int clamped_nodes = 0;
    // The step's mean drag on the grains, N.
    double drag_on_grains = 0;
    // |drag on the fluid + drag on the grains| over the latter; what the
    // fluid owes the grains over the step's exchange; the books since the
    // run (or resume) began (doc/output.md).
    double exchange_error = 0;
    double exchange_owed  = 0;
    double exchange_drift = 0;
  };

  /**
   * One fluid step of the seed's splitting, with the grains' sub-steps:
   *
   *   grains -> solid fraction -> drag the fluid sees (implicit) -> fluid
   *   -> interaction force on each grain -> grain velocities with implicit
   *   drag -> contacts with the drag-augmented mass -> positions,
   *
   * the last four repeated as sub-steps through the frozen fluid where a
   * step would move grains too far (Coupling/Grain sub-steps). It keeps the
   * books of the momentum the two phases exchange (Newton's third law
   * between them) across steps: they are part of a checkpoint.
   */
  template <int dim>
  class CoupledStep
  {
  public:
    /** @p pcout: where the once-per-run warnings go; @p sphere_packing_hint:
     *  whether a warning about packed grains names Closure porosity in 2D. */
    CoupledStep(dealii::ConditionalOStream &pcout, bool sphere_packing_hint);

    /** Advances fluid and grains from @p time by @p dt. @p previous_dt: the
     *  last fluid step's length (0 before the first), the rate at which the
     *  fluid repays what it owes; @p first_step: no contact impulse is known
     *  yet and one is predicted in the initial fluid. @p step names the step
     *  in warnings. */
    CoupledStepReport<dim>
    advance(Coupling<dim>    &coupling,
            FluidSolver<dim> &fluid,
            Grains<dim>      &grains,
            double            time,
            double            dt,
            double            previous_dt,
            bool              first_step,
            unsigned int      step);

    /** The statistics columns a coupled step fills, and their values. */
    static std::vector<std::string>
    column_names();
    static void
    set_statistics(const CoupledStepReport<dim> &report,
                   Statistics                   &statistics);

    /** The drag impulses the phases exchanged since the run (or resume)
     *  began: the grains' total, and the sum of both, which the fluid
     *  still owes where the books balance. Part of a checkpoint. */
    struct ExchangeBooks
    {
      double                 impulse = 0;
      dealii::Tensor<1, dim> imbalance;
    };
    ExchangeBooks &
    books()
    {
      return exchange;
    }
    /** The clamped count of the last step (a warning is said when it
     *  becomes positive). Part of a checkpoint. */
    unsigned int &
    clamped_nodes_before()
    {
      return clamped_before;
    }

  private:
    dealii::ConditionalOStream &pcout;
    const bool                  sphere_packing_hint;
    ExchangeBooks               exchange;
    unsigned int                clamped_before = 0;
  };
} // namespace ImmersedGrains

#endif
