#ifndef immersed_grains_contact_contact_solver_h
#define immersed_grains_contact_contact_solver_h

#include <deal.II/base/tensor.h>

#include <immersed_grains/contact/bucket_grid.h>
#include <immersed_grains/contact/walls.h>

#include <cstdint>
#include <functional>
#include <limits>
#include <utility>
#include <vector>

namespace ImmersedGrains
{
  namespace Contact
  {
    using dealii::Tensor;

    /// Angular velocity: its out-of-plane component in 2D, a vector in 3D.
    template <int dim>
    using AngularVelocity = Tensor<1, (dim == 2 ? 1 : 3)>;

    /**
     * The per-grain arrays of one time step, gathered once from wherever the
     * grains live (ParticleHandler, a test, a ghost exchange). Index i is the
     * same grain in every array and in GrainPair/WallContact.
     */
    template <int dim>
    struct GrainArrays
    {
      /// In: free velocity v + dt F / m_eff. Out (ContactSolver::finish()):
      /// end-of-step velocity.
      std::vector<Tensor<1, dim>> velocity;

      /// Same for the angular velocity; read only when friction > 0.
      std::vector<AngularVelocity<dim>> angular_velocity;

      /// Velocity at the start of the step, the pre-impact velocity of
      /// Newton's law. Read only when restitution > 0; if empty, the free
      /// velocity stands in for it.
      std::vector<Tensor<1, dim>> start_velocity;

      /// 1 / m_eff, with m_eff = m + dt beta under implicit drag; 0 for a
      /// fixed grain.
      std::vector<double> inverse_mass;

      /// 1 / I_eff; read only when friction > 0 (0: no rotation).
      std::vector<double> inverse_inertia;

      std::vector<double> radius;

      /// Persistent grain ids (e.g. particle ids), so that warm starting
      /// survives reordering. If empty, the index is the id.
      std::vector<std::uint64_t> id;

      /// Out (ContactSolver::finish()): the displacement [m] the position
      /// correction adds to x + dt v this step, one per grain; empty when
      /// the step needed none. It moves the grains without giving them
      /// velocity (ContactSolver::begin_position_correction()).
      std::vector<Tensor<1, dim>> position_correction;

      /// Optional sweep key per grain, e.g. the height against gravity:
      /// forward sweeps visit the contacts in increasing key of their
      /// midpoint, backward sweeps in decreasing key (see
      /// ContactSolver::order_rows). If empty, contacts go in rounds by
      /// grain index, the fastest order per update.
      std::vector<double> sweep_key;
    };

    /// How ContactSolver::solve() iterates (doc/contacts.md).
    enum class ContactMethod
    {
      /// Projected Gauss-Seidel: contact after contact, velocities updated
      /// in place.
      gauss_seidel,
      /// Nesterov-accelerated projected gradient descent with adaptive step
      /// and restart (Mazhar, Heyn, Negrut & Tasora, ACM TOG 34(3), 2015),
      /// preconditioned with the contacts' diagonal Delassus blocks.
      apgd
    };

    struct ContactParameters
    {
      ContactMethod method = ContactMethod::gauss_seidel;

      /// Newton coefficient of restitution e in [0, 1].
      double restitution = 0;

      /// Coulomb friction coefficient mu >= 0; 0 switches rotation off.
      double friction = 0;

      /// Rolling friction coefficient mu_r >= 0 (Gauss-Seidel with
      /// friction > 0 only): a contact's torque against the relative
      /// rolling of its two grains is at most mu_r R* p_n, R* = r_i r_j /
      /// (r_i + r_j) for two grains and r_i against a wall. Stands for
      /// what rolls a real grain less than a sphere: its shape and the
      /// contact's finite area (Iwashita & Oda 1998). 0: spheres roll
      /// freely.
      double rolling_friction = 0;

      /// Converged when no impulse changed by more than this times the
      /// largest impulse during the last sweep ...
      double tolerance = 1e-6;

      /// ... and the largest overlap predicted for the end of the step is
      /// below this times the smallest radius in contact.
      double overlap_tolerance = 1e-3;

      /// Cap on Gauss-Seidel sweeps, or on APGD iterations (each trial step
      /// of the step-size search counts).
      unsigned int max_iterations = 1000;

      /// Start from last step's impulses, matched by grain ids.
      bool warm_start = true;

      /// Gauss-Seidel: a subspace correction
      /// (ContactSolver::subspace_correction()) after every this many
      /// sweeps of a step that has not converged; 0 switches it off.
      unsigned int subspace_interval = 20;

      /// Conjugate-gradient iterations of one subspace correction.
      unsigned int subspace_iterations = 200;
    };

    /**
     * When the Gauss-Seidel iterations run subspace corrections
     * (ContactSolver::subspace_correction()), in ContactSolver::solve() and
     * in a distributed caller alike: after every interval sweeps, and once
     * when the sweeps' test is passed before any has run. A step is solved
     * when the sweeps' test is passed and the last correction found
     * (almost) nothing left to lower (ContactSolver::settled_by(); such a
     * correction only tests and moves nothing).
     *
     * On several ranks (@p confirm_after_corrections) the first passed
     * test is confirmed at once also after corrections that were due: there
     * the copies' glue slows the sweeps, so nearly every step passes only
     * after the first due correction and would sweep on to the next one,
     * up to interval sweeps and their exchanges for a step already solved
     * (two ranks: 24 sweeps per grain sub-step where they took 44 on the
     * million-grain suspension, doc/performance.md). On one rank the same
     * rule would save less (21 sweeps where 29, 11 % of the contacts' time
     * there: the confirming correction's conjugate gradients cost much of
     * what the sweeps saved do) and would move every frictionless scene's
     * path within the tolerance; it is kept as it was.
     */
    struct SubspaceSchedule
    {
      explicit SubspaceSchedule(const unsigned int interval,
                                const bool confirm_after_corrections = false)
          : interval(interval)
          , confirm_after_corrections(confirm_after_corrections)
          , settled(interval == 0)
      {
      }

      /// Whether a correction is due before the next sweep.
      bool
      due(const unsigned int iterations) const
      {
        return interval > 0 && iterations >= last + interval;
      }

      /// Whether the sweeps' test, just passed after @p iterations sweeps,
      /// calls for a correction to confirm it: once per step, before any
      /// correction has run or (confirm_after_corrections) after a sweep
      /// since the last one.
      bool
      confirm(const unsigned int iterations) const
      {
        if (settled || confirmed)
          return false;
        return confirm_after_corrections ? iterations > last : !corrected;
      }

      /// Records a correction after @p iterations sweeps.
      void
      record(const unsigned int iterations, const bool settled_now)
      {
        last      = iterations;
        corrected = true;
        settled   = settled_now;
      }

      /// Records that the next correction confirms a passed test.
      void
      record_confirmation()
      {
        confirmed = true;
      }

      const unsigned int interval;
      const bool         confirm_after_corrections;
      unsigned int       last      = 0;
      bool               corrected = false;
      bool               confirmed = false;
      bool               settled;
    };

    /// Local measures of one Gauss-Seidel sweep (reduce with max over ranks).
    struct SweepResult
    {
      double max_change  = 0;
      double max_impulse = 0;
    };

    /**
     * Local measures of one APGD trial step (ContactSolver::apgd_measure()),
     * to be reduced over ranks: curvature, metric and restart by sum, the
     * others by max.
     */
    struct AcceleratedMeasures
    {
      /// d.N d and d.D d for the step d = p_new - y (step-size test).
      double curvature = 0;
      double metric    = 0;
      /// grad f(y).(p_new - p): > 0 restarts the momentum.
      double restart = 0;
      /// Largest change one projected Jacobi step would make at p_new, and
      /// the largest impulse |p_new|: the residual of the convergence test.
      double max_change  = 0;
      double max_impulse = 0;
      /// Largest overlap predicted at p_new [m], and the same less the
      /// local overlap limit (converged only if <= 0 on every rank).
      double max_overlap    = 0;
      double overlap_excess = -std::numeric_limits<double>::max();
    };

    struct SolverResult
    {
      unsigned int iterations = 0;
      bool         converged  = false;
      /// max_change / max_impulse of the last sweep.
      double residual = 0;
      /// Largest overlap predicted for the end of the step, in metres.
      double       max_overlap = 0;
      unsigned int n_contacts  = 0;
      /// Contacts that carry a non-zero normal impulse.
      unsigned int n_active = 0;
    };

    /// Impulses per contact, in the order of the contact list given.
    template <int dim>
    struct ContactImpulses
    {
      /// Normal impulse p_n >= 0 (force = p_n / dt), pushing the partner
      /// along +normal and the grain along -normal.
      std::vector<double> normal;
      /// Tangential impulse on the partner (zero without friction).
      std::vector<Tensor<1, dim>> tangential;
    };

    /**
     * Moreau-Jean non-smooth contact dynamics for rigid discs (dim = 2) and
     * spheres (dim = 3), solved by projected Gauss-Seidel over the contacts
     * (Moreau 1988; Jean 1999). The formulas, with their derivation, are in
     * contact_solver.cc and doc/contacts.md.
     *
     * One step: setup() packs the contacts and grains into contiguous work
     * arrays and warm-starts; sweep() visits every contact once; converged()
     * tests a sweep; finish() writes the velocities back. solve() strings
     * them together. They are separate so that a distributed caller can put
     * its own communication between sweeps:
     *  - each rank lists the contacts it owns and appends ghost grains
     *    (owned elsewhere, touching its own) to GrainArrays;
     *  - after each sweep(), a rank sends the velocity change it has put on
     *    each ghost grain to that grain's owner, which adds the changes up
     *    and returns the new velocity to every rank holding the ghost
     *    (get_velocity()/set_velocity() and the angular versions give the
     *    working velocities);
     *  - SweepResult and predicted_max_overlap() are reduced with max over
     *    all ranks before converged() decides, so all ranks stop together.
     */
    template <int dim>
    class ContactSolver
    {
    public:
      explicit ContactSolver(
        const ContactParameters &parameters = ContactParameters());

      void
      set_parameters(const ContactParameters &parameters);

      const ContactParameters &
      get_parameters() const;

      /**
       * One contact step: grains.velocity (and angular_velocity) go in as
       * free velocities and come out as end-of-step velocities. The
       * impulses are then available from pair_impulses()/wall_impulses().
       * Not converging within max_iterations is reported in the result,
       * never hidden: the caller decides whether to go on.
       */
      SolverResult
      solve(const std::vector<GrainPair<dim>>   &pairs,
            const std::vector<WallContact<dim>> &wall_contacts,
            const std::vector<Tensor<1, dim>>   &wall_velocities,
            GrainArrays<dim>                    &grains,
            const double                         time_step);

      /**
       * Packs one step's problem. @p wall_velocities is indexed by
       * WallContact::wall (Walls::velocities()).
       */
      void
      setup(const std::vector<GrainPair<dim>>   &pairs,
            const std::vector<WallContact<dim>> &wall_contacts,
            const std::vector<Tensor<1, dim>>   &wall_velocities,
            const GrainArrays<dim>              &grains,
            const double                         time_step);

      /// One projected Gauss-Seidel pass over all contacts; passes alternate
      /// between forward and backward order.
      SweepResult
      sweep();

      /**
       * A subspace correction between Gauss-Seidel sweeps (without
       * friction; with friction only in the position correction): on the
       * contacts that carry an impulse, subspace_iterations steps of
       * Jacobi-preconditioned conjugate gradients towards the impulses that
       * would make each of them hold exactly (N_AA d = -(u_n - ubar)_A), then
       * a step along that direction, projected onto p_n >= 0, that lowers
       * the step's quadratic energy (halved until it does). Gauss-Seidel
       * reduces an error by less the smaller its share of N, and a
       * frictionless packing near its isostatic point has many such
       * errors, spread over the grains (doc/contacts.md); conjugate
       * gradients reach them in the square root of the iterations. The
       * sweeps decide which contacts carry an impulse, the correction
       * solves on them.
       *
       * Returns by how much the step lowers f, as a share of 1/2 p.D p
       * on the subspace (D = diag N, so that this is the energy the
       * impulses would carry each alone); 0 where the gradient on the
       * subspace vanishes; where no projected step lowers f, the share the
       * unprojected step would take, so that the test below does not call
       * a step solved for want of a step. f less its minimum is the kinetic
       * energy of the error in the velocities (1/2 e.N e for an impulse error
       * e), which the sweeps' own test does not see where N is small: solve()
       * therefore also asks for a correction that finds a share below the
       * tolerance squared (settled_by()). Such a correction only tests: the
       * step is not taken, as the step is solved to the tolerance. A step
       * taken must be followed by a sweep that passes the sweeps' test. Reads
       * and changes the working velocities, so a distributed caller calls it
       * with the copies glued, and passes @p glue (as for
       * iterate_accelerated()) and
       * @p sum, which must add its values over all ranks in place; every
       * rank must call it together.
       */
      double
      subspace_correction(
        const std::function<void()>                       &glue,
        const std::function<void(double *, unsigned int)> &sum);

      /// Largest -(g + dt u_n) over the contacts, with the current
      /// velocities and the gap g of the current phase: while solving for
      /// the velocities, the overlap the step adds to what it started with
      /// (g = max(gap, 0)); while correcting positions, the overlap the
      /// step leaves. converged() holds it to half the overlap limit in the
      /// first case, to the limit in the second.
      double
      predicted_max_overlap() const;

      /**
       * After setup(): the velocity iterations, then, where the step would
       * leave an overlap beyond overlap_limit(), the position correction
       * (begin_position_correction()). @p iterate runs one phase's
       * iterations (sweeps with converged(), or iterate_accelerated(), with
       * the caller's communication) and returns its result with the
       * predicted overlap; @p on_any_rank turns this rank's "a correction
       * is needed" into the answer of all ranks, so that all correct or
       * none. Returns the two phases added up. Call finish() afterwards.
       */
      SolverResult
      iterate_phases(const std::function<SolverResult()> &iterate,
                     const std::function<bool(bool)>     &on_any_rank);

      /// The largest overlap a step may leave, in metres:
      /// ContactParameters::overlap_tolerance times the smallest radius in
      /// contact.
      double
      overlap_limit() const;

      bool
      converged(const SweepResult &sweep, const double max_overlap) const;

      /// Whether a subspace_correction() that lowered f by @p energy_share
      /// (its result) leaves the step solved: below the tolerance squared,
      /// the share that the sweeps' test allows one impulse.
      bool
      settled_by(const double energy_share) const;

      /**
       * The APGD iterations (ContactMethod::apgd) after setup(): each
       * trial step updates the working velocities locally, then @p glue
       * must make all copies of a grain agree (a no-op in serial), and
       * @p reduce must reduce the AcceleratedMeasures over all ranks (sums
       * and maxima as documented there). All ranks take the
       * same decisions and stop together. Call finish() afterwards.
       */
      SolverResult
      iterate_accelerated(
        const std::function<void()>                      &glue,
        const std::function<void(AcceleratedMeasures &)> &reduce);

      /// Writes the working velocities into @p grains, fills the impulse
      /// lists and keeps the impulses for the next warm start.
      void
      finish(GrainArrays<dim> &grains);

      /// The impulses kept for the next warm start, one contact a line,
      /// exactly (hexadecimal floating point).
      void
      save_warm_start(std::ostream &out) const;

      /// Adds such lines to the kept impulses (a key found twice keeps
      /// the first).
      void
      load_warm_start(std::istream &in);

      const ContactImpulses<dim> &
      pair_impulses() const;

      const ContactImpulses<dim> &
      wall_impulses() const;

      /// Working velocities between setup() and finish().
      Tensor<1, dim>
      get_velocity(const unsigned int grain) const;

      void
      set_velocity(const unsigned int grain, const Tensor<1, dim> &velocity);

      AngularVelocity<dim>
      get_angular_velocity(const unsigned int grain) const;

      void
      set_angular_velocity(const unsigned int          grain,
                           const AngularVelocity<dim> &angular_velocity);

    private:
      static constexpr unsigned int spin_dim = (dim == 2 ? 1 : 3);

      // Work arrays laid out for the sweep: what one contact update reads
      // sits together, what only friction needs sits apart.
      struct GrainSlot
      {
        double velocity[dim];
        double inverse_mass;
      };

      struct SpinSlot
      {
        double angular_velocity[spin_dim];
        double inverse_inertia;
      };

      struct Row
      {
        unsigned int i; // grain
        unsigned int j; // partner: a grain, or a wall slot after the grains
        double       normal[dim];
        double       target;    // lower bound of u_n after the step
        double       inverse_w; // 1 / (normal Delassus entry)
        double       p_n;
      };

      struct FrictionRow
      {
        double p_t[dim];
        double inverse_w_t; // 1 / (tangential Delassus entry)
        double radius_i;
        double radius_j;
      };

      // Rolling friction: the angular impulse on grain j (on i: its
      // negative), tangential in 3D.
      struct RollingRow
      {
        double p_r[spin_dim];
        double inverse_w_r;      // 1 / (1 / I_i + 1 / I_j)
        double limit;            // mu_r R*: |p_r| <= limit p_n
        double inverse_r_rolled; // 1 / R*: p_r / R* is a force's impulse
      };

      using Key = std::pair<std::uint64_t, std::uint64_t>;

      struct CachedImpulse
      {
        Key            key;
        double         p_n;
        Tensor<1, dim> p_t;
        double         p_r[spin_dim]; // rolling; zero without it
      };

      ContactParameters parameters;
      double            dt;
      unsigned int      n_grains;
      unsigned int      n_pairs;
      bool              forward;
      double            smallest_radius;

      std::vector<GrainSlot>   grains;
      std::vector<SpinSlot>    spins;
      std::vector<Row>         rows;
      std::vector<FrictionRow> friction_rows;
      std::vector<RollingRow>  rolling_rows;
      std::vector<double>      gaps;       // of the current phase
      std::vector<double>      start_gaps; // at the start of the step

      // The velocity solution kept while the positions are corrected.
      bool                   correcting = false;
      std::vector<GrainSlot> solved_grains;
      std::vector<double>    solved_p_n;
      std::vector<Key>       keys;     // warm-start key of each row
      std::vector<double>    key_sign; // -1 where the key swapped the pair

      std::vector<CachedImpulse> cache;

      // APGD state per contact, c = 1 (normal) or dim (impulse vector
      // p_n n + p_t) values per contact: the previous iterate, the trial,
      // and the relative (contact point) velocities of the accepted, the
      // previous and the trial iterate. The accepted impulses are those of
      // rows/friction_rows; the velocities of the accepted iterate are
      // kept in accepted_grains/accepted_spins to undo a rejected trial.
      std::vector<double>    p_old, p_new, u, u_old, u_new;
      std::vector<GrainSlot> accepted_grains;
      std::vector<SpinSlot>  accepted_spins;
      double                 lipschitz = 1; // L: the step is 1/L
      double                 theta     = 1;
      double                 momentum  = 0; // beta: y = p + beta (p - p_old)

      // Grain i's slot in the work arrays (grains, spins), slot_of[i];
      // the identity where empty. Walls keep theirs after the grains.
      std::vector<unsigned int> slot_of;

      unsigned int
      slot(const unsigned int grain) const
      {
        return grain < slot_of.size() ? slot_of[grain] : grain;
      }

      /// The grains' slots in the order the sorted rows first read them
      /// (after order_rows()).
      void
      order_slots(const std::vector<GrainPair<dim>>   &pairs,
                  const std::vector<WallContact<dim>> &wall_contacts);

      // Contact m of the lists given to setup() (pairs, then walls) is row
      // row_of_input[m] of the work arrays, which are in sweep order.
      std::vector<unsigned int>                    row_of_input;
      std::vector<unsigned int>                    rank_count;
      std::vector<unsigned int>                    round_start;
      std::vector<std::pair<double, unsigned int>> keyed_rows;

      ContactImpulses<dim> pair_results;
      ContactImpulses<dim> wall_results;

      // Subspace correction (source/contact/subspace_correction.cc): the
      // rows of the subspace, and per row the gradient u_n - ubar, the
      // conjugate-gradient vectors and the impulses before the step.
      std::vector<unsigned int> subspace_rows;
      std::vector<double>       subspace_inverse_w, subspace_gradient,
        subspace_solution, subspace_residual, subspace_search, subspace_image,
        subspace_p_n;
      std::vector<GrainSlot> subspace_velocities;

      // The subspace's rows packed for the conjugate gradients, which read
      // them twice in each of their iterations.
      struct SubspaceRow
      {
        unsigned int i;
        unsigned int j;
        double       normal[dim];
      };
      std::vector<SubspaceRow> subspace_geometry;
      // For each grain slot, the subspace rows that touch it, in their
      // order: 2 q for row q's grain i, 2 q + 1 for its partner j, from
      // subspace_incidence_start[g] on.
      std::vector<unsigned int> subspace_incidence_start, subspace_incidence,
        subspace_incidence_next;

      /// N d on the subspace: the working velocities are set to M^-1 H d
      /// alone, glued, read back as u_n, and restored. Returns this rank's
      /// d.(N d), summed in the rows' order.
      double
      apply_delassus(const std::vector<double>   &d,
                     std::vector<double>         &image,
                     const std::function<void()> &glue);

      /// u_n = (v_j - v_i).n with the working velocities.
      double
      normal_velocity(const Row &row) const;

      /// Largest -(from[k] + dt u_n) over the rows with a free grain.
      double
      max_overlap_from(const std::vector<double> &from) const;

      /// What predicted_max_overlap() may reach for converged(): half the
      /// limit while solving for the velocities, the limit while
      /// correcting positions.
      double
      allowed_overlap() const;

      /// Largest overlap the step would leave without a position
      /// correction, -(gap + dt u_n) with the gaps at the start of the step
      /// and the current velocities.
      double
      end_of_step_overlap() const;

      /**
       * After the velocity iterations, when end_of_step_overlap() exceeds
       * overlap_limit() on some rank (iterate_phases()): keeps the velocities
       * and impulses found, and poses the position correction, the same contact
       * problem for pseudo-velocities z (all zero to begin with, no friction)
       * that bring every overlap down to half the limit, dt z_n >= -(gap + dt
       * u_n) - overlap_limit() / 2. iterate_phases() iterates again exactly as
       * for the velocities; finish() then returns dt z as
       * GrainArrays::position_correction and the velocities of the first
       * solve. The correction moves grains without giving them velocity, so
       * a solve's error never comes back as a push that separates grains:
       * removing overlaps through the velocities instead feeds every
       * step's error back twice over, and a pile whose slowest modes the
       * solver damps by less than half per step never comes to rest
       * (doc/contacts.md, "Coming to rest").
       */
      void
      begin_position_correction();

      /// Friction acts in the velocity solve only.
      bool
      with_friction() const;

      /// So does rolling friction.
      bool
      with_rolling() const;

      void
      order_rows(const std::vector<GrainPair<dim>>   &pairs,
                 const std::vector<WallContact<dim>> &wall_contacts,
                 const std::vector<double>           &sweep_key);

      void
      set_row(const unsigned int      k,
              const unsigned int      i,
              const unsigned int      j,
              const Tensor<1, dim>   &normal,
              const double            gap,
              const GrainArrays<dim> &grain_arrays);

      void
      warm_start();

      /// Starts row @p k's rolling impulse from the kept one, @p cached_p_r
      /// (on the key's second grain).
      void
      warm_start_rolling(const unsigned int k, const double *cached_p_r);

      void
      apply_impulse(const unsigned int k,
                    const double       dp_n,
                    const double      *dp_t);

      template <bool with_friction, bool with_rolling>
      SweepResult
      sweep_rows();

      // APGD (source/contact/accelerated_solver.cc).
      template <bool with_friction>
      void
      apgd_start();

      template <bool with_friction>
      void
      apgd_trial();

      template <bool with_friction>
      AcceleratedMeasures
      apgd_measure();

      bool
      apgd_accept(const AcceleratedMeasures &global);

      template <bool with_friction>
      void
      contact_velocity(const unsigned int k, double *out) const;
    };
  } // namespace Contact
} // namespace ImmersedGrains

#endif
