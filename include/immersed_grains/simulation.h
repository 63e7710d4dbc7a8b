#ifndef immersed_grains_simulation_h
#define immersed_grains_simulation_h

#include <deal.II/base/conditional_ostream.h>
#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/timer.h>
#include <deal.II/distributed/tria.h>

#include <immersed_grains/coupling/coupling.h>
#include <immersed_grains/divergence_guard.h>
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
#include <limits>
#include <map>
#include <memory>
#include <string>

namespace ImmersedGrains
{
  template <int dim>
  class CoupledStep;
  template <int dim>
  class FluidSolver;
  template <int dim>
  class FieldOutput;
  template <int dim>
  class Grains;
  template <int dim>
  struct GrainStatistics;
  struct GrainStepReport;
  class ProgressLine;
  template <int dim>
  class ParticleOutput;

  /**
   * One run of a scene: owns the mesh, the fluid solver, the grains, the
   * coupling and the output, and strings them together in run(), which
   * reads as the algorithm. It holds no physics of its own. Its members
   * are defined over several files:
   *  - source/simulation/core.cc: parameters, set-up, run() and the time
   *    step;
   *  - source/simulation/mesh.cc: adapting and repartitioning the mesh;
   *  - source/simulation/checkpoint.cc: writing and resuming checkpoints;
   *  - source/simulation/statistics.cc: the statistics row of each step,
   *    timings, the progress line;
   *  - source/scene_regime.cc: regime(), print_check() and the choice of
   *    the drag distribution.
   * The coupled step itself is CoupledStep (source/coupling/coupled_step.cc)
   * and the divergence checks DivergenceGuard (source/divergence_guard.cc).
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
    // --- core.cc ---------------------------------------------------------

    // The newest complete checkpoint to resume from (Checkpoint/Resume),
    // its physics checked against this scene's; empty to start afresh.
    std::string
    resume_point();
    // With @p resumed_step >= 0 the files of the run being resumed are
    // kept up to that step and appended to.
    void
    prepare_output_directory(int resumed_step);
    // From the parameters, or (@p resume_from a checkpoint directory) from
    // a saved state.
    void
    setup(const std::string &resume_from);
    // The output directory, the set-up, the initial row and output, the
    // clocks and the divergence checks' scales.
    void
    start(const std::string &resume_from);
    bool
    finished() const;
    double
    next_time_step() const;
    /** solve_time_step(), taken again with half the step where the fluid
     *  step fails, up to Step retries times with Adaptive time step. */
    void
    solve_time_step_or_retry(double dt);
    void
    solve_time_step(double dt);
    void
    record_contacts(const GrainStepReport &report);
    /** Stops the run (collective), after a last output, where a value is
     *  not finite or a speed outruns what the scene drives
     *  (DivergenceGuard). */
    void
    stop_if_diverging();
    // Stops the run after a last output of the step: "step N (t = T s): "
    // and @p what.
    [[noreturn]] void
    stop_run(const std::string &what);
    // A failure inside run(): rethrown with the step named and, on one
    // rank, a last output of what the step reached.
    [[noreturn]] void
    rethrow_failure(const std::exception &e, bool in_step);
    void
    maybe_write_fields(bool force);
    // The run's last lines: what stopped short, the wall time, timers.
    void
    print_summary();
    /** The grains' gravity less their buoyancy, |g| |1 - rho/rho_p| (rho
     *  the fluid's density, 0 without fluid): their acceleration from
     *  rest before drag acts. */
    double
    buoyant_gravity() const;

    // --- mesh.cc ---------------------------------------------------------

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
    // After a step: how far the fastest grain may have gone since the band
    // was made.
    void
    track_grain_travel();
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

    // --- checkpoint.cc ---------------------------------------------------

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

    // --- statistics.cc ---------------------------------------------------

    // The columns of statistics.csv: the interface's core columns first,
    // in their documented order, then each owner's in turn.
    static std::vector<std::string>
    statistics_columns();

    // Output/Boundary forces, Output/Boundary fluxes and Output/Probes:
    // reads them and adds their columns.
    void
    parse_output_points(dealii::ParameterHandler &prm,
                        const InputLocation      &where);
    // The columns of timings.csv: the phases, each a sum of TimerOutput
    // sections.
    static std::vector<std::string>
    timing_columns();
    // The step's row: what the state measures (grains, fluid, coupling,
    // clouds) beside what the step's solvers reported, written out.
    void
    postprocess(double dt);
    // dofs, fluid and solid volumes, pressure drop.
    void
    set_fluid_statistics();
    void
    set_grain_statistics();
    /** The cloud columns (Cloud analysis), and the break-up time once. */
    void
    set_cloud_statistics();
    /** The progress line, at most every Progress every seconds (a quarter
     *  of a second on a terminal); @p last: the run's last one. */
    void
    print_progress(bool last);
    void
    print_test_row(bool last) const;
    // One row of timings.csv: the wall time of each phase since the last.
    void
    record_timings();

    // --- scene_regime.cc -------------------------------------------------

    // Resolves Coupling/Drag distribution = auto from the placed grains
    // and says why in drag_distribution_choice.
    void
    choose_drag_distribution(const std::string &file);

    MPI_Comm     comm;
    std::string  parameter_file;
    std::string  output_directory;
    double       end_time           = 1;
    double       time_step          = 1;
    bool         adaptive_time_step = false;
    double       courant_number     = 0.1;
    double       shortest_cell_edge = 0;
    unsigned int step_retries       = 3;
    // The length of the last step taken (0 before the first, and on
    // resuming): an adaptive step grows by at most twice it.
    double last_step = 0;
    // The last step's length as its statistics row has it (restored on
    // resuming): the fluid repays what it owes the grains at that rate.
    double previous_step = 0;
    // Fluid steps taken again shorter after a failure, since the start.
    unsigned int retries_taken = 0;
    // How far the fastest grain may have travelled since the last
    // adaptation (a sum of the largest speed over each step times the
    // step), and that speed at the start of the step being taken.
    double grain_travel     = 0;
    double step_start_speed = 0;
    // Band lookahead: when the band was last made.
    double band_made_at       = 0;
    bool   warned_band_outrun = false;
    // When the cloud broke up (-1: not yet).
    double breakup_time = -1;

    unsigned int                    write_fields_every      = 0;
    bool                            write_grain_file_at_end = false;
    OutputFormat                    output_format           = OutputFormat::vtu;
    bool                            test_output             = false;
    bool                            quiet                   = false;
    bool                            verbose                 = false;
    double                          progress_interval       = 10;
    double                          start_time              = 0;
    std::vector<std::string>        test_columns;
    unsigned int                    test_every = 1;
    std::vector<TestCheck>          test_checks;
    std::vector<dealii::Point<dim>> pressure_drop_points;
    /** Output/Boundary forces, Boundary fluxes and Probes, with their
     * columns. */
    std::vector<dealii::types::boundary_id> boundary_force_ids;
    std::string                             boundary_force_text;
    std::vector<dealii::types::boundary_id> boundary_contact_force_ids;
    std::string                             boundary_contact_force_text;
    std::vector<dealii::types::boundary_id> boundary_flux_ids;
    // The last row's fluid_volume, for fluid_volume_balance: after a mesh
    // change, the same grains' (and departed grains') on the new mesh (NaN
    // at the start, and after a mesh change without grains).
    double previous_fluid_volume = std::numeric_limits<double>::quiet_NaN();
    std::string                                             boundary_flux_text;
    std::vector<std::pair<std::string, dealii::Point<dim>>> probes;
    std::string                                             probe_text;
    std::string                                             pressure_drop_text;
    unsigned int preconditioner_builds = 0;
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
    DivergenceGuard<dim>                    divergence_guard;
    double                                  largest_grain_radius = 0;
    double                                  mean_grain_radius    = 0;
    unsigned int                            placed_grains        = 0;
    // How many placed grains each touches on average (in 3D counted only
    // where Drag distribution = auto asks): a packing (2 or more) needs a
    // filter of a few diameters; free discs in 2D a wide one.
    double touching_neighbours = 0;
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
    std::unique_ptr<ProgressLine>        progress;
    Statistics                           statistics;
    Statistics                           timings;

    dealii::parallel::distributed::Triangulation<dim> triangulation;
    std::unique_ptr<FluidSolver<dim>>                 fluid;
    std::unique_ptr<FieldOutput<dim>>                 field_output;
    std::unique_ptr<Grains<dim>>                      grains;
    std::unique_ptr<ParticleOutput<dim>>              particle_output;
    std::unique_ptr<Coupling<dim>>                    coupling;
    // Kept across the re-set-up after a checkpoint: its books go on.
    std::unique_ptr<CoupledStep<dim>>   coupled_step;
    std::unique_ptr<Adaptivity<dim>>    adaptivity;
    std::unique_ptr<LoadBalance<dim>>   load_balance;
    std::unique_ptr<Checkpoint>         checkpoint;
    std::unique_ptr<CloudAnalysis<dim>> cloud_analysis;
    // The grains' measures of the last row (its max_speed sets the
    // adaptation's reach; the divergence checks read them).
    std::unique_ptr<GrainStatistics<dim>> grain_statistics;

    double       time = 0;
    unsigned int step = 0;
    double       wall_start;
    double       last_timing_wall;
    // TimerOutput's totals per timings.csv column at the last row.
    std::map<std::string, double> timer_totals;
  };
} // namespace ImmersedGrains

#endif
