#ifndef immersed_grains_coupling_coupling_h
#define immersed_grains_coupling_coupling_h

#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/timer.h>
#include <deal.II/distributed/tria.h>

#include <immersed_grains/coupling/drag_law.h>
#include <immersed_grains/coupling/filtered_drag.h>
#include <immersed_grains/coupling/self_disturbance.h>
#include <immersed_grains/coupling/solid_fraction.h>
#include <immersed_grains/fluid/mixture_fields.h>

#include <memory>
#include <vector>

namespace ImmersedGrains
{
  template <int dim>
  class FluidSolver;
  template <int dim>
  class Grains;
  template <int dim>
  struct GrainParameters;
  template <int dim>
  struct GrainStepArrays;

  /**
   * The two-way exchange between the averaged fluid and the grains (the
   * seed's hybrid model, doc/theory.md section 3). Per time step:
   *
   *  1. project(): the solid fraction and the solid flux from the grains;
   *  2. prepare_fluid_drag(dt): for each grain the interaction force
   *     without drag, F_i = (m_i - rho V_i) g (- V_i grad p^n with
   *     Implicit coupling = false), the drag coefficient gamma_i of the
   *     chosen law with the lagged slip, and what the fluid sees once the
   *     grain's implicit update is eliminated: the point drag
   *       beta_i = gamma_i m_i / (m_i + dt gamma_i),
   *       v~_i = v_i + dt F_i/m_i + P_i/m_i (last contact impulse),
   *     and with the implicit coupling the grain's share of the pressure
   *     gradient and of the solid flux (FilteredDrag);
   *  3. (the fluid solves with these)
   *  4. set_grain_forces(): the grains' hooks get -rho V_i g - V_i grad p
   *     (new p, filtered like the share the fluid took of it), gamma_i and
   *     the fluid velocity they feel; their implicit update
   *     v' = (m v + dt (m g + F + gamma u)) / (m + dt gamma) then
   *     exchanges the momentum the fluid received (to round-off without
   *     sub-steps; momentum_exchange_error).
   *  5. with Grain sub-steps, where the step would move grains too far,
   *     the grains take several steps through the frozen fluid, each after
   *     set_substep_grain_forces() re-evaluated their interaction force
   *     (gamma_i from the current slip) where they are now.
   *
   * With Two-way = false the fluid sees neither the solid fraction nor the
   * drag (one-way coupling); with Tracers = true the grains take the fluid
   * velocity and nothing else.
   */
  template <int dim>
  class Coupling : public PointDragSource<dim>, public MixtureFields<dim>
  {
  public:
    struct Parameters
    {
      static void
      declare_parameters(dealii::ParameterHandler &prm);
      void
      parse_parameters(dealii::ParameterHandler &prm, const std::string &file);

      std::string  drag_law                  = "Dallavalle-Wen-Yu";
      bool         two_way                   = true;
      bool         tracers                   = false;
      std::string  drag_distribution         = "cell";
      bool         implicit_coupling         = true;
      bool         grain_substeps            = true;
      unsigned int max_grain_substeps        = 1000;
      double       resting_threshold         = 1e-3;
      double       impulse_prediction_weight = 1. / 3;
      bool         repay_drag_mismatch       = true;
      bool         self_correction           = false;
      typename SolidFraction<dim>::Parameters projection;
    };

    Coupling(const Parameters           &parameters,
             const GrainParameters<dim> &grain_parameters,
             const Geometry<dim>        &geometry,
             const dealii::parallel::distributed::Triangulation<dim> &tria,
             double               fluid_density,
             double               fluid_viscosity,
             bool                 fluid_transient,
             bool                 fluid_advection,
             dealii::TimerOutput &timer);

    /** After every mesh change. */
    void
    setup();

    /** Connects the fluid to the projected fields and the point drags. */
    void
    attach(FluidSolver<dim> &fluid) const;

    /** The solid fraction of @p grains and of what is left in the
     *  mixture of those that departed (Grains::departed()), less what the
     *  fluid step @p dt takes out of it (project_departed()). Collective. */
    void
    project(Grains<dim> &grains, double dt = 0);

    /** Whether the fluid needs the fluid fraction's rate of change (the
     *  skew-symmetric advection, Fluid/Advection form): project() then
     *  projects the grains' flux for its divergence also where the
     *  implicit coupling supplies the flux itself. */
    void
    set_fraction_rate(bool needed);

    /**
     * The volume the grains that left through open boundaries
     * (Grains::departed()) take out of the mixture in the fluid step @p dt,
     * min(V_left, rate dt) each, as the fluid's volume sink over the step
     * (SolidFraction::project_sink()): the water that replaces them, at
     * the rate at which each crosses its own diameter, whatever the step.
     * Their solid flux does not cross the open faces (attach()), so
     * without it the mixture would lose their volume unreplaced. Call
     * after project(grains, dt). Collective.
     */
    void
    project_departed(Grains<dim> &grains, double dt);

    /** @p previous_dt, the last fluid step's length (0 before the first):
     *  what the fluid owes the grains is repaid at most at the rate at
     *  which it arose, a share dt / previous_dt when the step shrinks. */
    void
    prepare_fluid_drag(const Grains<dim>      &grains,
                       const FluidSolver<dim> &fluid,
                       double                  dt,
                       double                  previous_dt = 0);

    /** Call after Grains::gather(), before compute_free_velocities(). */
    void
    set_grain_forces(Grains<dim>            &grains,
                     const FluidSolver<dim> &fluid,
                     double                  dt);

    /** The hooks for a later grain sub-step of the same fluid step: the
     *  interaction force and gamma_i at the grains' current positions and
     *  velocities, in the fluid of this step (call after gather()); @p dt
     *  the sub-step. */
    void
    set_substep_grain_forces(Grains<dim>            &grains,
                             const FluidSolver<dim> &fluid,
                             double                  dt);

    bool
    grain_substeps() const
    {
      return parameters.grain_substeps;
    }

    /** Coupling/Maximum grain sub-steps. */
    unsigned int
    max_grain_substeps() const
    {
      return parameters.max_grain_substeps;
    }

    void
    point_drags(
      const typename dealii::Triangulation<dim>::active_cell_iterator &cell,
      std::vector<PointDrag<dim>> &drags) const override;

    /**
     * MixtureFields: the projected solid fraction and flux, and with
     * Drag distribution = filtered the grains' drag as a field.
     */
    void
    evaluate(
      const typename dealii::Triangulation<dim>::active_cell_iterator &cell,
      const std::vector<dealii::Point<dim>>                           &points,
      const std::vector<dealii::Point<dim>> &reference_points,
      double                                 time,
      MixtureValues<dim>                    &values) const override;

    /**
     * The drag force the grains exert on the fluid over the last fluid
     * step, integrated through the fluid's own fields (global).
     */
    dealii::Tensor<1, dim>
    drag_on_fluid(const Grains<dim>      &grains,
                  const FluidSolver<dim> &fluid) const;

    /**
     * After each grain (sub-)step of length @p substep: the drag force on
     * the grains in its implicit update (global), sum_i beta_i (u_i - v_i)
     * with the velocities after its contacts; and each grain's drag
     * impulse added to what the fluid owes it (GrainStepArrays::
     * exchange_owed, which set_grain_forces() started from minus the
     * impulse the fluid's step assumed).
     */
    dealii::Tensor<1, dim>
    account_drag_on_grains(Grains<dim> &grains, double substep) const;

    /**
     * After a step's last grain (sub-)step: the sum of what the fluid owes
     * the grains (global, N s), after clearing it for grains that touched
     * another or a wall in the step (a contact impulse): their mismatch
     * is mostly the predicted contact impulse's error,
     * which the relaxed prediction (Impulse prediction weight) carries
     * into the following steps; repaid at once as well, it brought back
     * the alternation that the prediction removes (doc/theory.md).
     */
    dealii::Tensor<1, dim>
    settle_exchange_owed(Grains<dim> &grains) const;

    /** Integral of the projected solid fraction. */
    double
    solid_volume() const;

    /** The grains' volume that the last project() saw and that has left
     *  through open boundaries since (@p grains the projected ones),
     *  plus what it held of grains that had left before:
     *  solid_volume() less this is what the grains now are. */
    double
    removed_since_projection(const Grains<dim> &grains) const;

    /** Integral of the fluid fraction the fluid sees (evaluate()). */
    double
    fluid_volume() const;

    /** Largest particle Reynolds number of the last step (global). */
    double
    max_reynolds() const;

    const SolidFraction<dim> &
    solid_fraction() const;

  private:
    const Parameters                                        &parameters;
    const GrainParameters<dim>                              &grain_parameters;
    const dealii::parallel::distributed::Triangulation<dim> &triangulation;
    const double                                             density;
    const double                                             viscosity;
    // Whether the fluid has a time derivative and advection: how a grain's
    // own disturbance builds up (SelfDisturbance).
    const bool           fluid_transient;
    const bool           fluid_advection;
    bool                 fraction_rate = false;
    dealii::TimerOutput &timer;

    std::shared_ptr<SolidFraction<dim>> projection;
    std::unique_ptr<FilteredDrag<dim>>  filtered_drag; // only if chosen
    std::unique_ptr<DragLaw>            drag_law;
    SelfDisturbance<dim>                self_disturbance;

    bool
    drag_as_field() const
    {
      return parameters.drag_distribution == "filtered";
    }

    // The fluid velocity a grain feels: at its centre, the cell mean or
    // the filtered velocity, by Drag distribution.
    std::vector<dealii::Tensor<1, dim>>
    felt_velocity(
      const FluidSolver<dim>                                          &fluid,
      const typename dealii::Triangulation<dim>::active_cell_iterator &cell,
      const std::vector<dealii::Point<dim>> &references) const;

    // SolidFraction::solid_scale() for the filter's loops; empty (1
    // everywhere, nothing evaluated) when no node is clamped.
    typename FilteredDrag<dim>::SolidScale
    solid_scale() const;

    /// What the drag law needs of a grain of @p radius, at the fluid
    /// fraction @p fluid_fraction (read as Closure porosity in 2D says),
    /// among grains of Sauter mean diameter @p mean_diameter (0: its own).
    DragInput
    drag_input(double                        radius,
               double                        fluid_fraction,
               const dealii::Tensor<1, dim> &slip,
               double                        mean_diameter) const;

    /// The fluid fraction a free grain's drag law reads, without its own
    /// share of the solid fraction, and its own disturbance of the velocity
    /// it feels after a step @p dt: @p last_self relaxed towards the
    /// self-mobility times the force its @p last_drag put on the fluid
    /// (SelfDisturbance), or kept with @p dt = 0 (a later sub-step: the
    /// fluid is frozen); unchanged and zero without the correction, for
    /// fixed grains and for grains held by contacts.
    std::pair<double, dealii::Tensor<1, dim>>
    undisturbed(
      const typename dealii::Triangulation<dim>::active_cell_iterator &cell,
      const dealii::Point<dim>     &reference,
      double                        radius,
      double                        felt_fraction,
      const dealii::Tensor<1, dim> &slip,
      const GrainStepArrays<dim>   &arrays,
      unsigned int                  i,
      double                        dt,
      bool                          free) const;

    /// One grain's drag, the one evaluation of the law that the fluid's
    /// implicit drag (prepare_fluid_drag()) and the grains' later sub-steps
    /// (set_hooks()) share: gamma_i at the slip of grain @p i against the
    /// velocity it feels, @p felt, and the fluid fraction it feels, both
    /// without its own disturbance where the correction is on
    /// (undisturbed()); whether its contacts hold it, with the drag mass
    /// m + dt gamma of a step @p dt; its disturbance relaxed over @p dt, or
    /// kept where @p frozen (a later sub-step in the same fluid).
    struct GrainDrag
    {
      double                 gamma    = 0;
      double                 reynolds = 0;
      dealii::Tensor<1, dim> self;
      bool                   held = false;
    };
    GrainDrag
    grain_drag(
      const typename dealii::Triangulation<dim>::active_cell_iterator &cell,
      const dealii::Point<dim>     &reference,
      const GrainStepArrays<dim>   &arrays,
      unsigned int                  i,
      double                        felt_fraction,
      const dealii::Tensor<1, dim> &felt,
      double                        mean_diameter,
      double                        dt,
      bool                          frozen) const;

    /// Whether grain @p i is held by its contacts: it kept at most
    /// Resting threshold of the velocity its last contact impulse removed
    /// from its @p drag_mass (m + dt gamma).
    bool
    held(const GrainStepArrays<dim> &arrays,
         unsigned int                i,
         double                      drag_mass) const;

    /// The grains' hooks: @p as_predicted for the first (or only) grain
    /// step, with gamma and the force the fluid's prediction used.
    void
    set_hooks(Grains<dim>            &grains,
              const FluidSolver<dim> &fluid,
              double                  dt,
              bool                    as_predicted);

    // Per grain, in the ParticleHandler's iteration order (Grains' arrays).

    std::vector<dealii::Tensor<1, dim>> lagged_force; // without m g
    std::vector<double>                 gamma;
    // The grain's own disturbance of the velocity it feels (undisturbed()).
    std::vector<dealii::Tensor<1, dim>> self_velocity;
    // The size of the last cell undisturbed() measured: grains come cell by
    // cell, and measuring a cell per grain was a tenth of the grains' drag
    // (reset by setup() when the mesh changes).
    mutable unsigned int sized_cell   = dealii::numbers::invalid_unsigned_int;
    mutable double       sized_cell_h = 0;
    // The contact impulse the fluid is told each grain will receive
    // (prepare_fluid_drag()).
    std::vector<dealii::Tensor<1, dim>> predicted_impulse;
    // The drag the fluid's step assumed for each grain, beta (u - v) +
    // alpha grad p, with u the velocity it feels and v this
    // (prepare_fluid_drag()), before the repayment of what it owed and
    // without the predicted contact impulse (the prediction's to repay).
    std::vector<double>                 assumed_beta;
    std::vector<double>                 assumed_pressure_weight;
    std::vector<dealii::Tensor<1, dim>> assumed_velocity;
    // The share of what it owed that the fluid's step repays.
    double repaid_share = 1;
    // Grains::removed_volume() when project() ran.
    double removed_volume_at_projection = 0;
    // What the last project() held of departed grains (all ranks).
    double departed_in_projection = 0;
    // Per active cell: the point drags of its grains.
    std::vector<std::vector<PointDrag<dim>>> cell_drags;

    double reynolds_max = 0;
    // Sum over free grains of beta_i times the velocity they felt when the
    // fluid step was prepared: with the filtered drag's deferred correction
    // their spread drags leave it out and the fluid takes it back as
    // (beta_n, u^n), the same to round-off (drag_on_fluid()).
    dealii::Tensor<1, dim> felt_drag_sum;
    // Whether the filtered velocity is that of the fluid's current solution.
    bool filtered_velocity_current = false;
  };
} // namespace ImmersedGrains

#endif
