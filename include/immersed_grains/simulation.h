#ifndef immersed_grains_simulation_h
#define immersed_grains_simulation_h

#include <deal.II/base/conditional_ostream.h>
#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/timer.h>
#include <deal.II/distributed/tria.h>

#include <immersed_grains/coupling/coupling.h>
#include <immersed_grains/fluid/fluid_parameters.h>
#include <immersed_grains/grains/cloud_analysis.h>
#include <immersed_grains/grains/grain_parameters.h>
#include <immersed_grains/grains/placement.h>
#include <immersed_grains/io/checkpoint.h>
#include <immersed_grains/io/output_series.h>
#include <immersed_grains/io/run_log.h>
#include <immersed_grains/io/statistics.h>
#include <immersed_grains/io/test_checks.h>
#include <immersed_grains/mesh/adaptivity.h>
#include <immersed_grains/mesh/geometry.h>
#include <immersed_grains/mesh/load_balance.h>
#include <immersed_grains/mesh/size_estimate.h>
#include <immersed_grains/scene_regime.h>

#include <functional>
#include <map>
#include <memory>
#include <string>

namespace ImmersedGrains
{
  template <int dim>
  class FluidSolver;
  template <int dim>
  class FieldOutput;
  template <int dim>
  class Grains;
  struct GrainStepReport;
  template <int dim>
  class ParticleOutput;

  /**
   * One run of a scene: owns the mesh, the fluid solver, the grains and the
   * output, and strings them together in run(). It holds no physics of its
   * own.
   */
  template <int dim>
  class Simulation
  {
  public:
    static void
    declare_parameters(dealii::ParameterHandler &prm);

    /** Parses everything; throws InputError before anything is written. */
    Simulation(dealii::ParameterHandler &prm,
               const std::string        &parameter_file,
               MPI_Comm                  comm);
    ~Simulation();

    void
    run();

    /** The scene's regime: grain and cloud Reynolds numbers, Stokes
     *  number, dt over the grains' relaxation time, cell over grain and
     *  over filter sizes, what is on and off, and warnings
     *  (source/scene_regime.cc). */
    SceneRegime
    regime() const;

    /** --check: the scene parsed, placed and estimated without writing
     *  anything; prints its size and regime on @p out (rank 0). */
    void
    print_check(std::ostream &out) const;

  private:
    // Resolves Coupling/Drag distribution = auto from the placed grains
    // (source/scene_regime.cc) and says why in drag_distribution_choice.
    void
    choose_drag_distribution(const std::string &file);
    // With @p resumed_step >= 0 the files of the run being resumed are
    // kept up to that step and appended to.
    void
    prepare_output_directory(int resumed_step);
    // From the parameters, or (@p resume_from a checkpoint directory) from
    // a saved state.
    void
    setup(const std::string &resume_from);
    void
    maybe_write_checkpoint();
    void
    write_checkpoint();
    // Time, step, counters, statistics and output records (rank 0 writes).
    void
    save_state(const std::string &directory) const;
    void
    load_state(const std::string &directory);
    // One line naming what decides the layout of the saved state (fluid on
    // or off, the grains' properties), written with each checkpoint; a
    // resume with other physics stops with an input error.
    std::string
    saved_physics_description() const;
    // Whether some choice of the settings that decide the saved layout
    // (Fluid/Enabled, Grains/Enabled, contacts, friction, a fixed region,
    // straight paths) gives @p saved: if none does, another version of
    // the code wrote it.
    bool
    physics_reachable(const std::string &saved) const;
    void
    check_saved_physics(const std::string &directory) const;
    // Refines and coarsens the mesh by the Adaptivity criteria and moves
    // every state onto it; false if nothing changed.
    bool
    adapt_mesh();
    // Moves every state across @p change of the mesh (refinement or
    // repartitioning).
    void
    change_mesh(const std::function<void()> &change);
    // Adapts the mesh when due, else repartitions it when the ranks' loads
    // are uneven.
    void
    maybe_adapt_mesh();
    /** Whether adaptations follow the grains' travel (Adaptivity/Every
     *  steps = auto with the grain band). */
    bool
    tracks_grain_travel() const;
    /** Whether the grains follow their straight paths for a lookahead band
     *  (Adaptivity/Band lookahead). */
    bool
    follows_straight_paths() const;
    void
    update_shortest_cell_edge();
    double
    next_time_step() const;
    void
    solve_time_step(double dt);
    GrainStepReport
    solve_coupled_time_step(double dt, unsigned int &fluid_iterations);
    void
    record_grain_step(const GrainStepReport &report);
    void
    postprocess(double dt, unsigned int fluid_iterations);
    void
    set_grain_statistics();
    /** The cloud columns (Cloud analysis), and the break-up time once. */
    void
    set_cloud_statistics();
    void
    maybe_write_fields(bool force);
    /** Stops the run (collective) where the fluid's solution or a grain's
     *  velocity or position is NaN or Inf: the step, the field and where,
     *  after a last output. */
    void
    stop_if_not_finite();
    /** solve_time_step(), taken again with half the step where the fluid
     *  step fails, up to Step retries times with Adaptive time step. */
    void
    solve_time_step_or_retry(double dt);
    /** Stops the run (collective), as stop_if_not_finite(), where a fluid
     *  or grain speed exceeds Divergence speed factor times the fastest
     *  motion the scene drives (driven_speed()): an exploding run that
     *  has not reached NaN yet, whose steps may have shrunk to nothing. */
    void
    stop_if_speeding();
    /** The fastest motion the scene's data drive (collective): free fall
     *  across the box along gravity, the grains' initial speeds and what
     *  FluidSolver::driven_speed() counts for the fluid. */
    double
    driven_speed() const;

    /** The grains' gravity less their buoyancy, |g| |1 - rho/rho_p| (rho
     *  the fluid's density, 0 without fluid): their acceleration from
     *  rest before drag acts. */
    double
    buoyant_gravity() const;
    // Calls @p visit(cell centre, whether a velocity, value) for the fluid
    // DoFs of each owned cell, in turn, until it returns true (the
    // searches behind the messages above; failure paths only).
    void
    visit_fluid_values(
      const std::function<bool(const dealii::Point<dim> &, bool, double)>
        &visit) const;
    // Stops the run after a last output of the step: "step N (t = T s): "
    // and @p what.
    [[noreturn]] void
    stop_run(const std::string &what);
    /** The progress line, at most every Progress every seconds (a quarter
     *  of a second on a terminal); @p last: the run's last one. */
    void
    print_progress(bool last);
    void
    print_test_row(bool last) const;
    // One row of timings.csv: the wall time of each phase since the last.
    void
    record_timings();

    MPI_Comm     comm;
    std::string  parameter_file;
    std::string  output_directory;
    double       end_time                = 1;
    double       time_step               = 1;
    bool         adaptive_time_step      = false;
    double       courant_number          = 0.1;
    double       shortest_cell_edge      = 0;
    double       divergence_speed_factor = 100;
    double       initial_grain_speed     = 0;
    unsigned int step_retries            = 3;
    // The length of the last step taken (0 before the first, and on
    // resuming): an adaptive step grows by at most twice it.
    double last_step = 0;
    // How far the fastest grain may have travelled since the last
    // adaptation (a sum of the largest speed over each step times the
    // step), and that speed at the start of the step being taken.
    double grain_travel     = 0;
    double step_start_speed = 0;
    // Band lookahead: when the band was last made.
    double band_made_at       = 0;
    bool   warned_band_outrun = false;
    // The largest speed over the driven speed so far, and that speed then.
    double largest_speed_ratio = 0;
    double driven_at_largest   = 0;

    unsigned int                    write_fields_every = 0;
    OutputFormat                    output_format      = OutputFormat::vtu;
    bool                            test_output        = false;
    bool                            quiet              = false;
    bool                            verbose            = false;
    double                          progress_interval  = 10;
    double                          last_progress_wall = 0;
    double                          start_time         = 0;
    std::vector<std::string>        test_columns;
    unsigned int                    test_every = 1;
    std::vector<TestCheck>          test_checks;
    std::vector<dealii::Point<dim>> pressure_drop_points;
    std::string                     pressure_drop_text;
    unsigned int                    clamped_nodes_before  = 0;
    unsigned int                    preconditioner_builds = 0;
    // The drag impulses the phases exchanged since the run (or resume)
    // began: their sum, which the fluid still owes where the books
    // balance, and the grains' total (momentum_exchange_drift).
    dealii::Tensor<1, dim> exchange_imbalance;
    double                 exchanged_impulse = 0;
    // Steps whose contact solve stopped at Contacts/Max iterations.
    unsigned int capped_contact_steps = 0;

    Geometry<dim>                           geometry;
    FluidParameters<dim>                    fluid_parameters;
    GrainParameters<dim>                    grain_parameters;
    typename Coupling<dim>::Parameters      coupling_parameters;
    typename Adaptivity<dim>::Parameters    adaptivity_parameters;
    typename LoadBalance<dim>::Parameters   load_balance_parameters;
    Checkpoint::Parameters                  checkpoint_parameters;
    typename CloudAnalysis<dim>::Parameters cloud_parameters;
    double                                  largest_grain_radius = 0;
    double                                  mean_grain_radius    = 0;
    unsigned int                            placed_grains        = 0;
    // Why Drag distribution = auto became what it is; empty if it was set.
    std::string drag_distribution_choice;
    // Placed while parsing, so that bad placements fail before any output.
    std::vector<GrainSeed<dim>> grain_seeds;
    SizeEstimate                size_estimate;
    double                      available_memory = 0;

    RunLog                               log;
    dealii::ConditionalOStream           pcout;
    dealii::ConditionalOStream           pdetail;
    std::unique_ptr<dealii::TimerOutput> timer;
    Statistics                           statistics;
    Statistics                           timings;

    dealii::parallel::distributed::Triangulation<dim> triangulation;
    std::unique_ptr<FluidSolver<dim>>                 fluid;
    std::unique_ptr<FieldOutput<dim>>                 field_output;
    std::unique_ptr<Grains<dim>>                      grains;
    std::unique_ptr<ParticleOutput<dim>>              particle_output;
    std::unique_ptr<Coupling<dim>>                    coupling;
    std::unique_ptr<Adaptivity<dim>>                  adaptivity;
    std::unique_ptr<LoadBalance<dim>>                 load_balance;
    std::unique_ptr<Checkpoint>                       checkpoint;
    std::unique_ptr<CloudAnalysis<dim>>               cloud_analysis;

    double       time = 0;
    unsigned int step = 0;
    double       wall_start;
    double       last_timing_wall;
    // TimerOutput's totals per timings.csv column at the last row.
    std::map<std::string, double> timer_totals;
  };
} // namespace ImmersedGrains

#endif
