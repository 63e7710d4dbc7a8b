#ifndef immersed_grains_grains_grains_h
#define immersed_grains_grains_grains_h

#include <deal.II/base/mpi.h>
#include <deal.II/base/timer.h>
#include <deal.II/distributed/tria.h>
#include <deal.II/fe/mapping.h>
#include <deal.II/grid/grid_tools_cache.h>
#include <deal.II/numerics/data_component_interpretation.h>
#include <deal.II/particles/particle_handler.h>

#include <immersed_grains/contact/contact_solver.h>
#include <immersed_grains/grains/distributed_contacts.h>
#include <immersed_grains/grains/grain_parameters.h>
#include <immersed_grains/grains/placement.h>
#include <immersed_grains/mesh/geometry.h>

#include <algorithm>
#include <map>
#include <memory>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

namespace ImmersedGrains
{
  class Statistics;

  /**
   * Where each quantity sits among a particle's properties. Only what the
   * scene needs is stored: velocity and radius always (the mass follows
   * from the one density), the angular velocity only with friction, the
   * fluid force only with a fluid, a fixed flag (1 or 0) only with a
   * Grains/Fixed region (Fixed = true fixes all grains and needs none).
   */
  struct GrainPropertyLayout
  {
    static constexpr unsigned int absent =
      dealii::numbers::invalid_unsigned_int;

    unsigned int velocity          = 0;
    unsigned int radius            = absent;
    unsigned int angular_velocity  = absent;
    unsigned int fluid_force       = absent;
    unsigned int drag_force        = absent;
    unsigned int self_velocity     = absent;
    unsigned int contact_impulse   = absent;
    unsigned int predicted_impulse = absent;
    unsigned int exchange_owed     = absent;
    unsigned int fixed             = absent;
    /** Adaptivity/Band lookahead: the velocity each grain had when the
     *  band was made, and how far it has strayed since from the straight
     *  line along it (a vector). */
    unsigned int path_velocity  = absent;
    unsigned int path_deviation = absent;
    unsigned int n_properties   = 0;

    /** Names and interpretations per component, for particle output. */
    std::vector<std::string> names;
    std::vector<
      dealii::DataComponentInterpretation::DataComponentInterpretation>
      interpretations;
  };

  /** The layout a scene's grains get from its parameters: with a fluid
   *  (@p with_fluid), friction, contacts, a fixed region and straight
   *  paths (@p straight_paths, for a lookahead band). */
  template <int dim>
  GrainPropertyLayout
  make_grain_property_layout(const GrainParameters<dim> &parameters,
                             bool                        with_fluid,
                             bool straight_paths = false);

  /**
   * The arrays of one step, gathered once from the ParticleHandler in its
   * iteration order (owned grains of this rank). The coupling hooks are
   * empty unless a caller fills them between Grains::gather() and
   * Grains::compute_free_velocities(); empty means "off" and costs nothing.
   */
  template <int dim>
  struct GrainStepArrays
  {
    std::vector<dealii::Point<dim>> position;
    std::vector<double>             mass;
    /** Under MPI with contacts: each grain's active cell index, for the
     *  contacts' halo (DistributedContacts::PartitionHalo); else empty. */
    std::vector<unsigned int> cell;
    /** 1 for a fixed grain (never moved, infinite mass), else 0. */
    std::vector<unsigned char> fixed;

    /** velocity: current on gather, free after compute_free_velocities(),
     *  end-of-step after resolve_contacts(). */
    Contact::GrainArrays<dim> contact;

    /** Hook: a force per grain other than gravity [N] (e.g. the fluid's). */
    std::vector<dealii::Tensor<1, dim>> external_force;
    /** Hook: implicit drag beta_i = dD_i/dw [kg/s]; the effective mass is
     *  m_i + dt beta_i (in the contact solver too). */
    std::vector<double> drag_coefficient;
    /** Hook: the velocity the drag pulls towards (fluid velocity at the
     *  grain), with drag_coefficient. */
    std::vector<dealii::Tensor<1, dim>> drag_velocity;

    /** With a fluid and contacts: each grain's contact impulse [N s], of
     *  the last step on gather(), of this step after resolve_contacts().
     *  The coupling predicts the drag the fluid receives with it, so that a
     *  grain held by contacts does not push the fluid. */
    std::vector<dealii::Tensor<1, dim>> contact_impulse;

    /** With a fluid and contacts: the impulse the fluid was told each grain
     *  would receive, of the last step on gather(); the coupling relaxes it
     *  towards contact_impulse (Coupling/Impulse prediction weight). */
    std::vector<dealii::Tensor<1, dim>> predicted_impulse;

    /** With a fluid: the drag each grain felt over its last step [N], of
     *  the last step on gather(); the coupling estimates the grain's own
     *  disturbance of the fluid from it. */
    std::vector<dealii::Tensor<1, dim>> drag_force;
    /** With a fluid: the grain's own disturbance of the velocity it feels
     *  (Coupling/Self-disturbance correction), of the last step on
     *  gather(); the coupling sets this step's. */
    std::vector<dealii::Tensor<1, dim>> self_velocity;
    /** With a fluid: the drag impulse the grain received and the fluid has
     *  not [N s] (its sub-steps' drags against the one the fluid's step
     *  assumed), of the last step on gather(), which the coupling hands
     *  the fluid this step; the coupling accounts this step's. */
    std::vector<dealii::Tensor<1, dim>> exchange_owed;
  };

  /** Global measures of the grain population (sums/means over ranks). */
  template <int dim>
  struct GrainStatistics
  {
    double                 n_grains     = 0;
    double                 solid_volume = 0;
    dealii::Point<dim>     centroid;
    dealii::Tensor<1, dim> mean_velocity;
    double                 max_speed        = 0;
    double                 kinetic_energy   = 0;
    double                 packing_fraction = 0;
    /** Fixed grains: their number and the mean of their centres (which
     *  never change). */
    double             n_fixed = 0;
    dealii::Point<dim> fixed_centroid;
    /** Grains that left through open faces since the start. */
    double n_removed = 0;
    /** The largest coordinate of any grain's centre, per axis (run-outs,
     *  bed heights; 0 without grains). */
    dealii::Point<dim> max_position;
    /** Per size class (Size distribution = classes, in the order of Class
     *  radii; empty otherwise): the number of grains, the mean of their
     *  centres and of their velocities. */
    std::vector<double>                 class_grains;
    std::vector<dealii::Point<dim>>     class_centroid;
    std::vector<dealii::Tensor<1, dim>> class_mean_velocity;

    /** The statistics columns these fill (doc/output.md); solid_volume
     *  only @p without_fluid (else the coupling's projection). */
    static std::vector<std::string>
    column_names();
    /** The columns of @p n_classes size classes: class<k>_particles,
     *  class<k>_mean_velocity_x, ..., class<k>_centroid_x, ... */
    static std::vector<std::string>
    class_column_names(unsigned int n_classes);
    void
    set_statistics(Statistics &statistics, bool without_fluid) const;
  };

  /**
   * How far the grains have strayed from the straight lines x_0 + v_0 t
   * their velocities pointed along when their paths were last reset (the
   * mesh's lookahead band covers those lines, Adaptivity): the largest
   * |x - x_0 - v_0 t| and the largest |v - v_0| of any grain, after the
   * last move. Global: every rank holds the same values.
   */
  struct StraightPathDrift
  {
    double displacement = 0; // m
    double velocity     = 0; // m/s
  };

  /** What one grain step did (global numbers). */
  struct GrainStepReport
  {
    Contact::SolverResult contacts;
    double                max_contact_force = 0;
    double                alert_distance    = 0;
    unsigned long         removed           = 0; // this step, open faces

    /** Folds the report of a later sub-step of the same step into this
     *  one: iterations and removals add up, the worst of the rest is
     *  kept, the contact count is the last sub-step's. */
    void
    add_substep(const GrainStepReport &later);

    /** The statistics columns of a step's contacts (doc/output.md). */
    static std::vector<std::string>
    column_names();
    void
    set_statistics(Statistics &statistics) const;
  };

  /** A grain that left through an open boundary, where it last was
   *  inside the mesh (Grains::departed()). */
  template <int dim>
  struct DepartedGrain
  {
    typename dealii::Triangulation<dim>::active_cell_iterator cell;
    dealii::Point<dim> reference; // in cell
    double             volume;    // what is left of it in the mixture
    double             rate;      // at which it leaves: V |v| / (2 r)
    double             diameter;

    /** The volume that leaves the mixture over a step @p dt: the rate's
     *  share, or what is left of the grain. */
    double
    drained(const double dt) const
    {
      return std::min(volume, rate * dt);
    }
  };

  /**
   * The grain population on a Particles::ParticleHandler and its dry
   * dynamics: gravity, external forces and (hooks for) implicit drag, then
   * non-smooth contacts, then the position update. A step is
   *
   *   gather() -> [coupling fills hooks] -> compute_free_velocities(dt)
   *   -> resolve_contacts(dt) -> move_and_scatter(dt)
   *
   * and advance(dt) runs all of it. Grains leaving through open faces are
   * removed and counted; periodic faces wrap.
   */
  template <int dim>
  class Grains
  {
  public:
    /** @p straight_paths: each grain follows its deviation from a
     *  straight path (straight_path_drift()). */
    Grains(const GrainParameters<dim>                              &parameters,
           const Geometry<dim>                                     &geometry,
           const dealii::parallel::distributed::Triangulation<dim> &tria,
           bool                                                     with_fluid,
           dealii::TimerOutput                                     &timer,
           bool straight_paths = false);

    /** Inserts the initial grains (the same list on every rank); grain k
     *  gets particle id k. */
    void
    initialize(const std::vector<GrainSeed<dim>> &seeds);

    /** Recomputes the ranks' bounding boxes and the shortest cell edge
     *  after the mesh changed. */
    void
    update_partition();

    /** Largest step <= max_step in which no grain moves more than the Max
     *  displacement fraction of the smallest radius, nor more than half the
     *  shortest cell edge, so that the ParticleHandler (under MPI: the
     *  ghost layer of one cell) can follow every grain (collective). */
    double
    stable_time_step(double max_step) const;

    /** The largest grain speed (collective). */
    double
    max_speed() const;

    /** The shortest cell edge of the mesh the grains live on. */
    double
    shortest_cell_edge() const
    {
      return min_cell_size;
    }

    GrainStepReport
    advance(double dt);

    void
    gather();

    /** From the velocities gathered at the start of the step (so it may
     *  be called again with a shorter dt). */
    void
    compute_free_velocities(double dt);

    /** How many equal sub-steps the step @p dt needs so that no grain
     *  moves more than the Max displacement fraction of the smallest
     *  radius, nor more than half the shortest cell edge, in one, judged
     *  by the larger of each grain's start and free velocity (call after
     *  compute_free_velocities(dt); collective). */
    unsigned int
    substeps(double dt) const;

    /** Solves the contacts; the impulse each grain received is stored
     *  (contact_impulse), or added to what earlier sub-steps of the same
     *  step stored if @p add_to_step_impulse. */
    GrainStepReport
    resolve_contacts(double dt, bool add_to_step_impulse = false);

    /** x += dt v, removes/wraps, writes back and sorts into cells (with
     *  straight paths: adds the step to each grain's deviation, and
     *  updates straight_path_drift()). Returns the number of grains
     *  removed on all ranks. */
    unsigned long
    move_and_scatter(double dt);

    /** With straight paths: each grain's path starts anew where it is,
     *  along its velocity now. */
    void
    reset_straight_paths();

    /** With straight paths: since the last reset_straight_paths(). (A
     *  resumed run sets what it saved.) */
    StraightPathDrift &
    straight_path_drift()
    {
      return drift;
    }

    GrainStepArrays<dim> &
    step_arrays();

    const GrainStepArrays<dim> &
    step_arrays() const;

    GrainStatistics<dim>
    compute_statistics() const;

    const dealii::Particles::ParticleHandler<dim> &
    particle_handler() const;

    /** Before the triangulation changes (its flags final): every grain
     *  with all its properties is attached to its cell. */
    void
    prepare_for_mesh_change();

    /** After it changed: the grains back in their (new) cells, the ranks'
     *  boxes and the shortest cell edge anew (collective). */
    void
    finish_mesh_change();

    /** Before the triangulation is saved: every grain attached to it. */
    void
    prepare_for_serialization();

    /** After a saved triangulation was loaded: the grains back, instead
     *  of initialize() (collective). */
    void
    deserialize();

    /** The contact solver's warm-start impulses (empty without contacts):
     *  this rank's into @p out; @p in may hold several ranks' lines. */
    void
    save_contact_memory(std::ostream &out) const;
    void
    load_contact_memory(std::istream &in);

    const GrainPropertyLayout &
    layout() const;

    /** Contacts solved on this rank in the last step. */
    std::vector<ContactForce>
    contact_forces() const;

    /** The contact solves since the start and how many of them searched
     *  for grain-grain pairs anew (the others kept the neighbour list);
     *  the largest count over the ranks (collective). */
    std::pair<unsigned long, unsigned long>
    neighbour_searches() const;

    /** From now on, each step sums the impulse its contacts (all its
     *  sub-steps) give each boundary, for boundary_contact_forces(). */
    void
    record_boundary_contact_forces();

    /** The force the grains' contacts exerted on each boundary of @p ids
     *  over the last step: the impulse summed over its sub-steps divided
     *  by its length (zero where the grains met that boundary nowhere;
     *  collective). */
    std::vector<dealii::Tensor<1, dim>>
    boundary_contact_forces(
      const std::vector<dealii::types::boundary_id> &ids) const;

    /** The grains that left through open boundaries since the start. */
    unsigned long
    n_removed() const;

    /** Sets that count (a resumed run's). */
    void
    set_removed(unsigned long n);

    /** The volume of the grains that left through open boundaries since
     *  this object was made (not kept across a restart): differences of
     *  it tell what left between two instants. */
    double
    removed_volume() const;

    /**
     * The grains that left through open boundaries and whose volume has
     * not yet left the mixture (the coupling takes it out over the time
     * each takes to cross its own diameter: Coupling::project_departed()),
     * each in the locally owned cell it was last in. After a mesh change they
     * are found again in the new cells (collective then: a grain may now lie in
     * another rank's cell, and is listed there).
     */
    const std::vector<DepartedGrain<dim>> &
    departed();

    /** Empties that list. */
    void
    forget_departed();

    /** Takes min(volume, rate dt) from each departed grain's volume, and
     *  drops those that have left whole. */
    void
    drain_departed(double dt);

    /** That list for a checkpoint: this rank's grains, a line each (the
     *  position where each was last inside, and its volume). */
    void
    save_departed(std::ostream &out) const;

    /** Adds the grains of @p in (one or more ranks' lines); collective
     *  (call on every rank, with an empty stream where there is nothing
     *  to read): departed() finds their cells. */
    void
    load_departed(std::istream &in);

    double
    mass(double radius) const;

    /** Whether @p particle is fixed (Grains/Fixed, or placed in the
     *  Fixed region). */
    bool
    is_fixed(const dealii::Particles::ParticleAccessor<dim> &particle) const;

  private:
    /// @p x in the reference coordinates of @p cell; a point beyond any
    /// cell's where the mapping cannot invert (far outside a skewed cell).
    dealii::Point<dim>
    reference_point(
      const typename dealii::Triangulation<dim>::active_cell_iterator &cell,
      const dealii::Point<dim>                                        &x) const;

    /// The longest step in which no grain at speed up to @p v_max moves
    /// more than the Max displacement fraction of @p r_min or half the
    /// shortest cell edge.
    double
    longest_step(double v_max, double r_min) const;

    const GrainParameters<dim>                              &parameters;
    const Geometry<dim>                                     &geometry;
    const dealii::parallel::distributed::Triangulation<dim> &triangulation;
    MPI_Comm                                                 comm;
    dealii::TimerOutput                                     &timer;

    GrainPropertyLayout                     properties;
    const dealii::Mapping<dim>             &mapping; // Geometry::mapping()
    dealii::Particles::ParticleHandler<dim> particles;
    /// Cells around each vertex, for rescue_lost_grain() (built on first
    /// use, rebuilt when the mesh changes).
    dealii::GridTools::Cache<dim>                      vertex_cache;
    std::unique_ptr<DistributedContacts<dim>>          contacts;
    std::vector<std::vector<dealii::BoundingBox<dim>>> rank_boxes;
    /// Shortest edge of any active cell (update_partition()): the
    /// ParticleHandler finds a grain again only within the cells around
    /// its old one, which under MPI are owned or ghost cells.
    double min_cell_size = 0;

    GrainStepArrays<dim>            arrays;
    unsigned long                   removed_total        = 0;
    double                          removed_volume_total = 0;
    std::vector<DepartedGrain<dim>> departed_grains;
    // Since the last mesh change, departed_grains hold real positions in
    // their reference field and no cell: departed() finds their cells.
    bool              departed_need_cells = false;
    StraightPathDrift drift;
    // The step's impulse on each boundary, and the time it was summed over
    // (record_boundary_contact_forces()).
    bool record_boundary_impulses = false;
    std::map<dealii::types::boundary_id, dealii::Tensor<1, dim>>
           step_boundary_impulse;
    double step_boundary_time = 0;

    /** The other ranks' cells near each owned cell (update_partition()). */
    typename DistributedContacts<dim>::PartitionHalo
    make_contact_halo() const;

    /** A grain taken out of the ParticleHandler, to be put back into
     *  @p cell as it was. */
    struct StoredGrain
    {
      typename dealii::Triangulation<dim>::active_cell_iterator cell;
      dealii::Point<dim>                                        location;
      dealii::Point<dim>                                        reference;
      dealii::types::particle_index                             id;
      std::vector<double>                                       properties;
    };
    /// Grains deal.II's sort dropped although they lie in their old cell
    /// up to round-off (see rescue_lost_grain()).
    std::vector<StoredGrain> rescued;

    /** particle_lost signal: deal.II 9.4 decides "inside a cell" without
     *  tolerance, so a grain exactly on a face or vertex whose reference
     *  coordinates come out a rounding error outside every adjacent cell
     *  is dropped. Such a grain is kept for reinsertion into the owned
     *  cell around the old one's vertices that it lies in up to 1e-8 in
     *  reference coordinates (clamped into it); one that really left is
     *  not, and move_and_scatter() reports it. */
    void
    rescue_lost_grain(
      const typename dealii::Particles::ParticleHandler<dim>::particle_iterator
                                                                      &particle,
      const typename dealii::Triangulation<dim>::active_cell_iterator &cell);

    /** Among the locally owned cells that share a vertex with @p cell,
     *  the one whose reference coordinates of @p x are closest to the unit
     *  cell: that cell, the coordinates and their distance from the unit
     *  cell (0 inside; infinite where no such cell is owned). */
    std::tuple<typename dealii::Triangulation<dim>::active_cell_iterator,
               dealii::Point<dim>,
               double>
    closest_owned_cell_around(
      const typename dealii::Triangulation<dim>::active_cell_iterator &cell,
      const dealii::Point<dim>                                        &x) const;

    /** The departed grains as real positions, their cells to be found
     *  again by departed() (before the mesh changes, or when more are
     *  read from a checkpoint). */
    void
    keep_departed_as_positions();

    /** Puts @p grains back into the ParticleHandler (local, no sort). */
    void
    reinsert(const std::vector<StoredGrain> &grains);
  };
} // namespace ImmersedGrains

#endif
