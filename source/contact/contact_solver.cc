#include <deal.II/base/exceptions.h>

#include <immersed_grains/contact/contact_solver.h>

#include "row_kinematics.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <sstream>
#include <string>

// The scheme (Moreau 1988, "Unilateral contact and dry friction in finite
// freedom dynamics", CISM Courses 302; Jean 1999, "The non-smooth contact
// dynamics method", CMAME 177, 235-257), implicit in the velocity
// (theta = 1):
//
//   v^{n+1} = v_free + M_eff^{-1} sum_a H_a p_a,   x^{n+1} = x^n + dt v^{n+1},
//
// with v_free = v^n + dt F / m_eff from the caller and p_a the impulse of
// contact a over the step (mean force p_a / dt).
//
// Normal law. u_n = (v_j - v_i).n is the relative normal velocity (positive
// when separating), g the gap at the start of the step. The gap at the end of
// the step is g + dt u_n^+ (to the order of the position update), so
// non-penetration at the end of the step reads u_n^+ >= -g/dt: Signorini's
// condition at velocity level with the gap term of Jean 1999. An open contact
// may close exactly within the step, and an overlap left by earlier steps is
// removed within one step instead of drifting. Newton's impact law (Moreau
// 1988; Jean 1999) asks u_n^+ >= -e u_n^-, with u_n^- the pre-impact
// velocity, taken at the start of the step. Together, per contact,
//
//   0 <= p_n  _|_  u_n^+ - ubar_n >= 0,
//   ubar_n = max(-g/dt, -e u_n^-)   if the contact impacts during the step,
//   ubar_n = -g/dt                  otherwise.
//
// A contact impacts when (i) it closes within the free step,
// g + dt u_n^free < 0, so that pairs merely inside the alert distance do not
// bounce from afar, and (ii) it approaches faster than the free step alone
// makes it, u_n^- < -|u_n^free - u_n^-|. (ii) tells impacts from lasting
// contacts: the approach speed a resting contact gains from the applied
// forces within one step is no impact, and treating it as one makes a ball
// under gravity chatter with ever smaller bounces instead of coming to rest
// in finite time. The threshold vanishes with dt, where Newton's law holds
// for every impact. ubar_n is fixed at setup, so the problem stays a linear
// complementarity problem for which Gauss-Seidel converges.
//
// Friction: Coulomb's law |p_t| <= mu p_n, u_t^+ = 0 while |p_t| < mu p_n,
// else p_t = -mu p_n u_t^+ / |u_t^+| (Jean 1999). With the contact point at
// x_i + r_i n on grain i and x_j - r_j n on grain j,
//
//   u = v_j - v_i - (r_i w_i + r_j w_j) x n,
//
// and an impulse P on j (-P on i) changes it by W P with
//
//   W = w_n n(x)n + w_t (1 - n(x)n),  w_n = 1/m_i + 1/m_j,
//   w_t = w_n + r_i^2 / I_i + r_j^2 / I_j,
//
// since rotation acts only tangentially ((n x t) x n = t for t _|_ n). W is
// diagonal in (normal, tangent plane) and isotropic in the plane, so the
// exact solution of the one-contact problem is a projection (Alart & Curnier
// 1991, CMAME 92, 353-375):
//
//   p_n <- max(0, p_n + (ubar_n - u_n) / w_n),
//   p_t <- proj_{|q| <= mu p_n} (p_t - u_t / w_t).
//
// Projected Gauss-Seidel applies this contact by contact with the
// velocities updated in place (Jean 1999, "NLGS").

namespace ImmersedGrains
{
  namespace Contact
  {
    namespace
    {
      // Wall keys live above every grain id in the second key component.
      constexpr std::uint64_t wall_key_bit = std::uint64_t(1) << 63;
    } // namespace



    template <int dim>
    ContactSolver<dim>::ContactSolver(const ContactParameters &parameters)
        : dt(0)
        , n_grains(0)
        , n_pairs(0)
        , forward(true)
        , smallest_radius(0)
    {
      set_parameters(parameters);
    }



    template <int dim>
    void
    ContactSolver<dim>::set_parameters(const ContactParameters &p)
    {
      AssertThrow(p.restitution >= 0 && p.restitution <= 1,
                  dealii::ExcMessage(
                    "ContactSolver: the restitution must lie in [0, 1]."));
      AssertThrow(p.friction >= 0,
                  dealii::ExcMessage(
                    "ContactSolver: the friction coefficient must not be "
                    "negative."));
      AssertThrow(p.rolling_friction == 0 ||
                    (p.rolling_friction > 0 && p.friction > 0 &&
                     p.method == ContactMethod::gauss_seidel),
                  dealii::ExcMessage(
                    "ContactSolver: rolling friction needs friction and the "
                    "Gauss-Seidel method."));
      AssertThrow(p.tolerance > 0 && p.overlap_tolerance > 0,
                  dealii::ExcMessage(
                    "ContactSolver: the tolerances must be positive."));
      AssertThrow(p.max_iterations > 0,
                  dealii::ExcMessage(
                    "ContactSolver: at least one iteration is needed."));
      parameters = p;
    }



    template <int dim>
    const ContactParameters &
    ContactSolver<dim>::get_parameters() const
    {
      return parameters;
    }



    template <int dim>
    SolverResult
    ContactSolver<dim>::solve(
      const std::vector<GrainPair<dim>>   &pairs,
      const std::vector<WallContact<dim>> &wall_contacts,
      const std::vector<Tensor<1, dim>>   &wall_velocities,
      GrainArrays<dim>                    &grain_arrays,
      const double                         time_step)
    {
      setup(pairs, wall_contacts, wall_velocities, grain_arrays, time_step);

      // One phase: the velocities, or the position correction.
      const auto iterate = [this]()
      {
        if (parameters.method == ContactMethod::apgd)
          return iterate_accelerated([]() {}, [](AcceleratedMeasures &) {});
        SolverResult result;
        if (rows.empty())
          result.converged = true;
        // The overlap is only worth a pass over the contacts once the
        // impulses have settled.
        double           overlap = 0;
        SubspaceSchedule schedule(parameters.subspace_interval);
        const auto       correct = [&]()
        {
          schedule.record(result.iterations,
                          settled_by(subspace_correction(
                            []() {}, [](double *, unsigned int) {})));
        };
        while (!result.converged &&
               result.iterations < parameters.max_iterations)
        {
          if (schedule.due(result.iterations))
            correct();
          const SweepResult s = sweep();
          ++result.iterations;
          result.residual =
            (s.max_impulse > 0 ? s.max_change / s.max_impulse : 0.);
          if (s.max_change <= parameters.tolerance * s.max_impulse)
          {
            if (schedule.confirm(result.iterations))
            {
              schedule.record_confirmation();
              correct();
              if (!schedule.settled)
                continue;
            }
            if (schedule.settled)
            {
              overlap          = predicted_max_overlap();
              result.converged = converged(s, overlap);
            }
          }
        }
        result.max_overlap =
          (result.converged ? overlap : predicted_max_overlap());
        return result;
      };

      SolverResult result =
        iterate_phases(iterate, [](const bool needed) { return needed; });
      result.n_contacts = rows.size();

      finish(grain_arrays);
      for (const Row &row : rows)
        result.n_active += (row.p_n > 0);
      return result;
    }



    template <int dim>
    SolverResult
    ContactSolver<dim>::iterate_phases(
      const std::function<SolverResult()> &iterate,
      const std::function<bool(bool)>     &on_any_rank)
    {
      SolverResult result = iterate();
      result.max_overlap  = end_of_step_overlap();
      if (on_any_rank(result.max_overlap > overlap_limit()))
      {
        begin_position_correction();
        const SolverResult correction = iterate();
        result.iterations += correction.iterations;
        result.converged   = result.converged && correction.converged;
        result.residual    = std::max(result.residual, correction.residual);
        result.max_overlap = correction.max_overlap;
      }
      return result;
    }



    template <int dim>
    void
    ContactSolver<dim>::setup(
      const std::vector<GrainPair<dim>>   &pairs,
      const std::vector<WallContact<dim>> &wall_contacts,
      const std::vector<Tensor<1, dim>>   &wall_velocities,
      const GrainArrays<dim>              &grain_arrays,
      const double                         time_step)
    {
      const unsigned int n        = grain_arrays.velocity.size();
      const bool         friction = (parameters.friction > 0);
      AssertThrow(time_step > 0,
                  dealii::ExcMessage(
                    "ContactSolver: the time step must be positive."));
      AssertThrow(grain_arrays.inverse_mass.size() == n &&
                    grain_arrays.radius.size() == n,
                  dealii::ExcMessage("ContactSolver: GrainArrays need one "
                                     "inverse mass and radius per velocity."));
      AssertThrow(!friction || (grain_arrays.angular_velocity.size() == n &&
                                grain_arrays.inverse_inertia.size() == n),
                  dealii::ExcMessage(
                    "ContactSolver: with friction, GrainArrays need one "
                    "angular velocity and inverse inertia per grain."));
      AssertThrow(grain_arrays.start_velocity.empty() ||
                    grain_arrays.start_velocity.size() == n,
                  dealii::ExcMessage(
                    "ContactSolver: start_velocity must be empty or have "
                    "one entry per grain."));
      AssertThrow(grain_arrays.id.empty() || grain_arrays.id.size() == n,
                  dealii::ExcMessage(
                    "ContactSolver: id must be empty or have one entry per "
                    "grain."));

      dt       = time_step;
      n_grains = n;
      n_pairs  = pairs.size();
      forward  = true;

      const unsigned int n_rows = pairs.size() + wall_contacts.size();
      order_rows(pairs, wall_contacts, grain_arrays.sweep_key);
      order_slots(pairs, wall_contacts);

      // Walls are grains of zero inverse mass after the real ones, so that
      // one loop without branches serves both kinds of contact.
      const unsigned int n_walls = wall_velocities.size();
      grains.resize(n + n_walls);
      for (unsigned int i = 0; i < n; ++i)
      {
        GrainSlot &g = grains[slot(i)];
        for (unsigned int d = 0; d < dim; ++d)
          g.velocity[d] = grain_arrays.velocity[i][d];
        g.inverse_mass = grain_arrays.inverse_mass[i];
      }
      for (unsigned int w = 0; w < n_walls; ++w)
      {
        for (unsigned int d = 0; d < dim; ++d)
          grains[n + w].velocity[d] = wall_velocities[w][d];
        grains[n + w].inverse_mass = 0;
      }
      spins.clear();
      if (friction)
      {
        spins.resize(n + n_walls, SpinSlot{{}, 0.});
        for (unsigned int i = 0; i < n; ++i)
        {
          SpinSlot &s = spins[slot(i)];
          for (unsigned int d = 0; d < spin_dim; ++d)
            s.angular_velocity[d] = grain_arrays.angular_velocity[i][d];
          s.inverse_inertia = grain_arrays.inverse_inertia[i];
        }
      }

      rows.resize(n_rows);
      gaps.resize(n_rows);
      start_gaps.resize(n_rows);
      correcting = false;
      keys.resize(n_rows);
      key_sign.resize(n_rows);
      friction_rows.resize(friction ? n_rows : 0);
      rolling_rows.resize(friction && parameters.rolling_friction > 0 ? n_rows :
                                                                        0);
      smallest_radius = (n_rows > 0 ? std::numeric_limits<double>::max() : 0.);

      const auto id = [&](const unsigned int i) -> std::uint64_t
      { return grain_arrays.id.empty() ? i : grain_arrays.id[i]; };
      for (unsigned int m = 0; m < pairs.size(); ++m)
      {
        const GrainPair<dim> &pair = pairs[m];
        AssertThrow(pair.first < n && pair.second < n &&
                      pair.first != pair.second,
                    dealii::ExcMessage(
                      "ContactSolver: a pair names a grain that does not "
                      "exist, or the same grain twice."));
        const unsigned int k = row_of_input[m];
        set_row(
          k, pair.first, pair.second, pair.normal, pair.gap, grain_arrays);
        const std::uint64_t a = id(pair.first), b = id(pair.second);
        keys[k]     = Key(std::min(a, b), std::max(a, b));
        key_sign[k] = (a < b ? 1. : -1.);
      }
      for (unsigned int m = 0; m < wall_contacts.size(); ++m)
      {
        const WallContact<dim> &contact = wall_contacts[m];
        AssertThrow(contact.grain < n && contact.wall < n_walls,
                    dealii::ExcMessage(
                      "ContactSolver: a wall contact names a grain or a "
                      "wall that does not exist."));
        const unsigned int k = row_of_input[pairs.size() + m];
        set_row(k,
                contact.grain,
                n + contact.wall,
                contact.normal,
                contact.gap,
                grain_arrays);
        keys[k]     = Key(id(contact.grain), wall_key_bit | contact.wall);
        key_sign[k] = 1.;
      }

      if (parameters.warm_start)
        warm_start();
    }



    template <int dim>
    void
    ContactSolver<dim>::set_row(const unsigned int      k,
                                const unsigned int      i,
                                const unsigned int      j,
                                const Tensor<1, dim>   &normal,
                                const double            gap,
                                const GrainArrays<dim> &grain_arrays)
    {
      Row &row = rows[k];
      row.i    = slot(i);
      row.j    = slot(j);
      row.p_n  = 0;
      for (unsigned int d = 0; d < dim; ++d)
        row.normal[d] = normal[d];

      const GrainSlot &a   = grains[row.i];
      const GrainSlot &b   = grains[row.j];
      const double     w_n = a.inverse_mass + b.inverse_mass;
      row.inverse_w        = (w_n > 0 ? 1. / w_n : 0.);

      // The work arrays hold the free velocities until warm_start().
      double u_free = 0;
      for (unsigned int d = 0; d < dim; ++d)
        u_free += (b.velocity[d] - a.velocity[d]) * normal[d];
      double u_start = u_free;
      if (!grain_arrays.start_velocity.empty())
      {
        // A wall's velocity is the same at the start and after the free
        // step.
        const Tensor<1, dim> v_j =
          (j < n_grains ? grain_arrays.start_velocity[j] :
                          Tensor<1, dim>(b.velocity));
        u_start = (v_j - grain_arrays.start_velocity[i]) * normal;
      }

      const double e = parameters.restitution;
      // An overlap left by earlier steps is not pushed apart here: the
      // velocities only keep it from deepening (begin_position_correction()
      // removes it without giving the grains speed).
      const double allowed_gap = std::max(gap, 0.);
      const double closing     = -allowed_gap / dt;
      const bool   closes      = (u_free < closing);
      const bool   fast_enough = (u_start < -std::abs(u_free - u_start));
      const bool   impacts     = (e > 0 && closes && fast_enough);
      row.target    = (impacts ? std::max(closing, -e * u_start) : closing);
      gaps[k]       = allowed_gap;
      start_gaps[k] = gap;

      const double r_i = grain_arrays.radius[i];
      const double r_j = (j < n_grains ? grain_arrays.radius[j] : 0.);
      smallest_radius  = std::min(smallest_radius, r_i);
      if (j < n_grains)
        smallest_radius = std::min(smallest_radius, r_j);

      if (parameters.friction > 0)
      {
        FrictionRow f{};
        f.radius_i       = r_i;
        f.radius_j       = r_j;
        const double w_t = w_n + r_i * r_i * spins[row.i].inverse_inertia +
                           r_j * r_j * spins[row.j].inverse_inertia;
        f.inverse_w_t    = (w_t > 0 ? 1. / w_t : 0.);
        friction_rows[k] = f;
      }
      if (!rolling_rows.empty())
      {
        RollingRow   r{};
        const double w_r =
          spins[row.i].inverse_inertia + spins[row.j].inverse_inertia;
        r.inverse_w_r = (w_r > 0 ? 1. / w_r : 0.);
        // A wall rolls under a grain like a grain of infinite radius.
        const double rolled = (r_j > 0 ? r_i * r_j / (r_i + r_j) : r_i);
        r.limit             = parameters.rolling_friction * rolled;
        r.inverse_r_rolled  = 1. / rolled;
        rolling_rows[k]     = r;
      }
    }



    template <int dim>
    void
    ContactSolver<dim>::order_rows(
      const std::vector<GrainPair<dim>>   &pairs,
      const std::vector<WallContact<dim>> &wall_contacts,
      const std::vector<double>           &sweep_key)
    {
      const unsigned int n_rows = pairs.size() + wall_contacts.size();
      const auto         grain  = [&](const unsigned int m)
      {
        return (m < pairs.size() ? pairs[m].first :
                                   wall_contacts[m - pairs.size()].grain);
      };
      row_of_input.resize(n_rows);
      for (unsigned int m = 0; m < n_rows; ++m)
        AssertThrow(grain(m) < n_grains,
                    dealii::ExcMessage(
                      "ContactSolver: a contact names a grain that does "
                      "not exist."));

      keyed_rows.clear();
      if (sweep_key.empty())
      {
        // Consecutive updates of the same grain form a chain of dependent
        // loads and stores that the processor cannot overlap. Taking first
        // the first contact of every grain, then the second of every grain,
        // and so on, puts different grains next to each other (a cheap
        // colouring) and keeps the grains in index order within each
        // round; this halves the time per contact update on a dense
        // packing.
        rank_count.assign(n_grains, 0);
        unsigned int n_rounds = 0;
        for (unsigned int m = 0; m < n_rows; ++m)
        {
          row_of_input[m] = rank_count[grain(m)]++;
          n_rounds        = std::max(n_rounds, row_of_input[m] + 1);
        }
        round_start.assign(n_rounds + 1, 0);
        for (unsigned int m = 0; m < n_rows; ++m)
          ++round_start[row_of_input[m] + 1];
        for (unsigned int q = 0; q < n_rounds; ++q)
          round_start[q + 1] += round_start[q];
        for (unsigned int m = 0; m < n_rows; ++m)
          row_of_input[m] = round_start[row_of_input[m]]++;
        return;
      }

      // Along a sweep key (the height against gravity): contacts sorted by
      // the key of their midpoint, so that a backward sweep carries the
      // weight from the top of a pile down to its floor in one pass, and a
      // forward sweep the reaction back up, instead of one layer per sweep.
      // On the 5000-disc pile (benchmarks/pile_at_rest/pile_2d_5000.prm) this
      // takes 27 % fewer sweeps than the rounds above and 38 % less time. Ties
      // keep the input order, so the order is deterministic.
      AssertThrow(sweep_key.size() == n_grains,
                  dealii::ExcMessage("ContactSolver: sweep_key must be "
                                     "empty or have one entry per grain."));
      keyed_rows.resize(n_rows);
      for (unsigned int m = 0; m < n_rows; ++m)
      {
        const unsigned int i = grain(m);
        keyed_rows[m]        = {(m < pairs.size() ?
                                   0.5 * (sweep_key[i] + sweep_key[pairs[m].second]) :
                                   sweep_key[i]),
                                m};
      }
      std::sort(keyed_rows.begin(), keyed_rows.end());
      for (unsigned int q = 0; q < n_rows; ++q)
        row_of_input[keyed_rows[q].second] = q;
    }



    template <int dim>
    void
    ContactSolver<dim>::order_slots(
      const std::vector<GrainPair<dim>>   &pairs,
      const std::vector<WallContact<dim>> &wall_contacts)
    {
      slot_of.clear();
      // In rounds (no sweep key) the rows already visit the grains in index
      // order. Along the sweep key a sweep reads the grains of one layer
      // after another, and in index order (by cell) these lie all over the
      // work arrays: at 10^6 grains two loads that miss the cache took
      // three quarters of a sweep. The grains get their slots in the order
      // the sweep first reads them, the grains without a contact after
      // them, so that a layer's grains lie together.
      if (keyed_rows.empty())
        return;
      constexpr unsigned int none = std::numeric_limits<unsigned int>::max();
      slot_of.assign(n_grains, none);
      unsigned int next = 0;
      const auto   take = [&](const unsigned int grain)
      {
        if (slot_of[grain] == none)
          slot_of[grain] = next++;
      };
      for (const auto &[key, m] : keyed_rows)
        if (m < pairs.size())
        {
          take(pairs[m].first);
          take(pairs[m].second);
        }
        else
          take(wall_contacts[m - pairs.size()].grain);
      for (unsigned int i = 0; i < n_grains; ++i)
        take(i);
    }



    template <int dim>
    void
    ContactSolver<dim>::save_warm_start(std::ostream &out) const
    {
      out << std::hexfloat;
      for (const CachedImpulse &c : cache)
      {
        out << c.key.first << ' ' << c.key.second << ' ' << c.p_n;
        for (unsigned int d = 0; d < dim; ++d)
          out << ' ' << c.p_t[d];
        if (parameters.rolling_friction > 0)
          for (unsigned int d = 0; d < spin_dim; ++d)
            out << ' ' << c.p_r[d];
        out << '\n';
      }
      out << std::defaultfloat;
    }


    template <int dim>
    void
    ContactSolver<dim>::load_warm_start(std::istream &in)
    {
      // (operator>> does not read hexadecimal floating point.)
      std::string line;
      while (std::getline(in, line))
      {
        std::istringstream fields(line);
        CachedImpulse      c{};
        std::string        value;
        if (!(fields >> c.key.first >> c.key.second >> value))
          continue;
        c.p_n = std::strtod(value.c_str(), nullptr);
        for (unsigned int d = 0; d < dim; ++d)
        {
          fields >> value;
          c.p_t[d] = std::strtod(value.c_str(), nullptr);
        }
        // Rolling impulses follow where the run that saved them had
        // rolling friction.
        for (unsigned int d = 0; d < spin_dim; ++d)
          if (fields >> value)
            c.p_r[d] = std::strtod(value.c_str(), nullptr);
        cache.push_back(c);
      }
      const auto by_key = [](const CachedImpulse &a, const CachedImpulse &b)
      { return a.key < b.key; };
      std::stable_sort(cache.begin(), cache.end(), by_key);
      cache.erase(std::unique(cache.begin(),
                              cache.end(),
                              [](const CachedImpulse &a, const CachedImpulse &b)
                              { return a.key == b.key; }),
                  cache.end());
    }


    template <int dim>
    void
    ContactSolver<dim>::warm_start()
    {
      if (cache.empty())
        return;

      // Both the new keys and the cache are mostly sorted: search forward
      // from the last hit with a doubling step, and start over only where
      // the new keys go back (from the pairs to the walls).
      const std::size_t n_cached = cache.size();
      std::size_t       cursor   = 0;
      Key               last(0, 0);
      const bool        friction = (parameters.friction > 0);
      const bool        rolling  = with_rolling();
      for (unsigned int k = 0; k < rows.size(); ++k)
      {
        const Key &key = keys[k];
        if (key < last)
          cursor = 0;
        last = key;

        std::size_t lo = cursor, step = 1, hi = cursor;
        while (hi < n_cached && cache[hi].key < key)
        {
          lo = hi + 1;
          hi += step;
          step *= 2;
        }
        hi     = std::min(hi + 1, n_cached);
        cursor = std::lower_bound(cache.begin() + lo,
                                  cache.begin() + hi,
                                  key,
                                  [](const CachedImpulse &c, const Key &k)
                                  { return c.key < k; }) -
                 cache.begin();
        if (cursor == n_cached || cache[cursor].key != key)
          continue;

        Row &row        = rows[k];
        row.p_n         = cache[cursor].p_n;
        double p_t[dim] = {};
        if (friction)
        {
          // The normal has turned since the last step: keep the part of
          // the old tangential impulse in the new tangent plane, inside
          // the cone.
          Tensor<1, dim> normal, t = key_sign[k] * cache[cursor].p_t;
          for (unsigned int d = 0; d < dim; ++d)
            normal[d] = row.normal[d];
          t -= (t * normal) * normal;
          const double limit = parameters.friction * row.p_n;
          const double norm  = t.norm();
          if (norm > limit)
            t *= limit / norm;
          for (unsigned int d = 0; d < dim; ++d)
            p_t[d] = friction_rows[k].p_t[d] = t[d];
        }
        apply_impulse(k, row.p_n, p_t);
        if (rolling)
          warm_start_rolling(k, cache[cursor].p_r);
      }
    }



    template <int dim>
    void
    ContactSolver<dim>::warm_start_rolling(const unsigned int k,
                                           const double      *cached_p_r)
    {
      // As the tangential impulse: the part about axes in the new tangent
      // plane (3D), inside the new limit. A pile held by rolling friction
      // then starts each step with its rolling impulses instead of
      // rebuilding them from zero in the sweeps.
      const Row  &row = rows[k];
      RollingRow &r   = rolling_rows[k];
      double      p_r[spin_dim], norm2 = 0;
      for (unsigned int d = 0; d < spin_dim; ++d)
        p_r[d] = key_sign[k] * cached_p_r[d];
      if constexpr (dim == 3)
      {
        double along_normal = 0;
        for (unsigned int d = 0; d < dim; ++d)
          along_normal += p_r[d] * row.normal[d];
        for (unsigned int d = 0; d < dim; ++d)
          p_r[d] -= along_normal * row.normal[d];
      }
      for (unsigned int d = 0; d < spin_dim; ++d)
        norm2 += p_r[d] * p_r[d];
      const double limit = r.limit * row.p_n;
      const double scale =
        (norm2 > limit * limit ? limit / std::sqrt(norm2) : 1.);
      SpinSlot &sa = spins[row.i];
      SpinSlot &sb = spins[row.j];
      for (unsigned int d = 0; d < spin_dim; ++d)
      {
        r.p_r[d] = scale * p_r[d];
        sa.angular_velocity[d] -= sa.inverse_inertia * r.p_r[d];
        sb.angular_velocity[d] += sb.inverse_inertia * r.p_r[d];
      }
    }



    template <int dim>
    void
    ContactSolver<dim>::apply_impulse(const unsigned int k,
                                      const double       dp_n,
                                      const double      *dp_t)
    {
      const Row &row = rows[k];
      GrainSlot &a   = grains[row.i];
      GrainSlot &b   = grains[row.j];
      for (unsigned int d = 0; d < dim; ++d)
      {
        const double P = dp_n * row.normal[d] + dp_t[d];
        a.velocity[d] -= a.inverse_mass * P;
        b.velocity[d] += b.inverse_mass * P;
      }
      if (with_friction())
      {
        const FrictionRow &f = friction_rows[k];
        double             torque[spin_dim];
        internal::vector_cross<dim>(row.normal, dp_t, torque);
        SpinSlot &sa = spins[row.i];
        SpinSlot &sb = spins[row.j];
        for (unsigned int d = 0; d < spin_dim; ++d)
        {
          sa.angular_velocity[d] -= sa.inverse_inertia * f.radius_i * torque[d];
          sb.angular_velocity[d] -= sb.inverse_inertia * f.radius_j * torque[d];
        }
      }
    }



    template <int dim>
    SweepResult
    ContactSolver<dim>::sweep()
    {
      const SweepResult result = (with_rolling()  ? sweep_rows<true, true>() :
                                  with_friction() ? sweep_rows<true, false>() :
                                                    sweep_rows<false, false>());
      // Alternating the order lets information cross a chain of contacts in
      // both directions at the same speed (a column on a floor converges
      // no matter in which order its contacts were listed).
      forward = !forward;
      return result;
    }



    template <int dim>
    template <bool with_friction, bool with_rolling>
    SweepResult
    ContactSolver<dim>::sweep_rows()
    {
      GrainSlot *const   g      = grains.data();
      SpinSlot *const    s      = spins.data();
      Row *const         rw     = rows.data();
      FrictionRow *const fr     = friction_rows.data();
      RollingRow *const  rr     = rolling_rows.data();
      const double       mu     = parameters.friction;
      const long         n      = rows.size();
      const long         start  = (forward ? 0 : n - 1);
      const long         stride = (forward ? 1 : -1);
      double             max_d2 = 0; // squared, to spare the root
      double             max_p2 = 0;

      for (long q = 0; q < n; ++q)
      {
        const long k   = start + q * stride;
        Row       &row = rw[k];
        GrainSlot &a   = g[row.i];
        GrainSlot &b   = g[row.j];

        if constexpr (!with_friction)
        {
          double u_n = 0;
          for (unsigned int d = 0; d < dim; ++d)
            u_n += (b.velocity[d] - a.velocity[d]) * row.normal[d];
          const double p =
            std::max(0., row.p_n + row.inverse_w * (row.target - u_n));
          const double dp = p - row.p_n;
          row.p_n         = p;
          const double da = a.inverse_mass * dp;
          const double db = b.inverse_mass * dp;
          for (unsigned int d = 0; d < dim; ++d)
          {
            a.velocity[d] -= da * row.normal[d];
            b.velocity[d] += db * row.normal[d];
          }
          max_d2 = std::max(max_d2, dp * dp);
          max_p2 = std::max(max_p2, p * p);
        }
        else
        {
          FrictionRow &f  = fr[k];
          SpinSlot    &sa = s[row.i];
          SpinSlot    &sb = s[row.j];

          double spin[spin_dim], lever[dim];
          for (unsigned int d = 0; d < spin_dim; ++d)
            spin[d] = f.radius_i * sa.angular_velocity[d] +
                      f.radius_j * sb.angular_velocity[d];
          internal::spin_cross<dim>(spin, row.normal, lever);
          double u[dim], u_n = 0;
          for (unsigned int d = 0; d < dim; ++d)
          {
            u[d] = b.velocity[d] - a.velocity[d] - lever[d];
            u_n += u[d] * row.normal[d];
          }

          const double p_n =
            std::max(0., row.p_n + row.inverse_w * (row.target - u_n));
          const double dp_n = p_n - row.p_n;
          row.p_n           = p_n;

          double p_t[dim], norm2 = 0;
          for (unsigned int d = 0; d < dim; ++d)
          {
            p_t[d] = f.p_t[d] - f.inverse_w_t * (u[d] - u_n * row.normal[d]);
            norm2 += p_t[d] * p_t[d];
          }
          const double limit = mu * p_n;
          if (norm2 > limit * limit)
          {
            const double scale = limit / std::sqrt(norm2);
            for (unsigned int d = 0; d < dim; ++d)
              p_t[d] *= scale;
          }

          double dp[dim], dp_t[dim], change2 = dp_n * dp_n, p2 = p_n * p_n;
          for (unsigned int d = 0; d < dim; ++d)
          {
            dp_t[d]  = p_t[d] - f.p_t[d];
            f.p_t[d] = p_t[d];
            dp[d]    = dp_n * row.normal[d] + dp_t[d];
            a.velocity[d] -= a.inverse_mass * dp[d];
            b.velocity[d] += b.inverse_mass * dp[d];
            change2 += dp_t[d] * dp_t[d];
            p2 += p_t[d] * p_t[d];
          }
          double torque[spin_dim];
          internal::vector_cross<dim>(row.normal, dp_t, torque);
          for (unsigned int d = 0; d < spin_dim; ++d)
          {
            sa.angular_velocity[d] -=
              sa.inverse_inertia * f.radius_i * torque[d];
            sb.angular_velocity[d] -=
              sb.inverse_inertia * f.radius_j * torque[d];
          }
          if constexpr (with_rolling)
          {
            // The relative rolling w = omega_j - omega_i (its part about
            // axes in the tangent plane in 3D: spinning about the normal
            // is free) is brought to zero inside the disc |p_r| <= mu_r R*
            // p_n, as the tangential slip inside Coulomb's cone.
            RollingRow &r = rr[k];
            double      w[spin_dim], p_r[spin_dim], spin_n = 0, norm_r2 = 0;
            for (unsigned int d = 0; d < spin_dim; ++d)
              w[d] = sb.angular_velocity[d] - sa.angular_velocity[d];
            if constexpr (dim == 3)
            {
              for (unsigned int d = 0; d < dim; ++d)
                spin_n += w[d] * row.normal[d];
              for (unsigned int d = 0; d < dim; ++d)
                w[d] -= spin_n * row.normal[d];
            }
            for (unsigned int d = 0; d < spin_dim; ++d)
            {
              p_r[d] = r.p_r[d] - r.inverse_w_r * w[d];
              norm_r2 += p_r[d] * p_r[d];
            }
            const double limit_r = r.limit * p_n;
            if (norm_r2 > limit_r * limit_r)
            {
              const double scale = limit_r / std::sqrt(norm_r2);
              for (unsigned int d = 0; d < spin_dim; ++d)
                p_r[d] *= scale;
            }
            for (unsigned int d = 0; d < spin_dim; ++d)
            {
              const double dp_r = p_r[d] - r.p_r[d];
              r.p_r[d]          = p_r[d];
              sa.angular_velocity[d] -= sa.inverse_inertia * dp_r;
              sb.angular_velocity[d] += sb.inverse_inertia * dp_r;
              // Measured as the tangential force's impulse that would
              // give the same torque.
              change2 += dp_r * dp_r * r.inverse_r_rolled * r.inverse_r_rolled;
              p2 += p_r[d] * p_r[d] * r.inverse_r_rolled * r.inverse_r_rolled;
            }
          }
          max_d2 = std::max(max_d2, change2);
          max_p2 = std::max(max_p2, p2);
        }
      }
      return {std::sqrt(max_d2), std::sqrt(max_p2)};
    }



    template <int dim>
    double
    ContactSolver<dim>::normal_velocity(const Row &row) const
    {
      double u_n = 0;
      for (unsigned int d = 0; d < dim; ++d)
        u_n += (grains[row.j].velocity[d] - grains[row.i].velocity[d]) *
               row.normal[d];
      return u_n;
    }



    template <int dim>
    double
    ContactSolver<dim>::max_overlap_from(const std::vector<double> &from) const
    {
      double overlap = 0;
      for (unsigned int k = 0; k < rows.size(); ++k)
        // Between two fixed grains nothing can be done: not our failure.
        if (rows[k].inverse_w > 0)
          overlap =
            std::max(overlap, -(from[k] + dt * normal_velocity(rows[k])));
      return overlap;
    }



    template <int dim>
    double
    ContactSolver<dim>::predicted_max_overlap() const
    {
      return max_overlap_from(gaps);
    }



    template <int dim>
    double
    ContactSolver<dim>::end_of_step_overlap() const
    {
      return max_overlap_from(start_gaps);
    }



    template <int dim>
    void
    ContactSolver<dim>::begin_position_correction()
    {
      Assert(!correcting, dealii::ExcInternalError());
      correcting = true;
      // Down to half the limit, not to contact: a grain lifted by the
      // whole overlap would leave gaps that its neighbours fall into, with
      // up to overlap / dt of speed (on a settled pile, more kinetic energy
      // than the velocity solve leaves); what remains is below the limit,
      // so the next steps need no correction until a solve's errors have
      // added half the limit again.
      const double kept_overlap = 0.5 * overlap_limit();
      solved_grains             = grains;
      solved_p_n.resize(rows.size());
      for (unsigned int k = 0; k < rows.size(); ++k)
      {
        Row &row      = rows[k];
        solved_p_n[k] = row.p_n;
        // The gap the velocities leave; walls have moved with them.
        gaps[k]    = start_gaps[k] + dt * normal_velocity(row);
        row.target = -(gaps[k] + kept_overlap) / dt;
        row.p_n    = 0;
      }
      for (GrainSlot &slot : grains)
        for (unsigned int d = 0; d < dim; ++d)
          slot.velocity[d] = 0;
      forward = true;
    }



    template <int dim>
    bool
    ContactSolver<dim>::with_friction() const
    {
      return parameters.friction > 0 && !correcting;
    }



    template <int dim>
    bool
    ContactSolver<dim>::with_rolling() const
    {
      return with_friction() && !rolling_rows.empty();
    }



    template <int dim>
    double
    ContactSolver<dim>::allowed_overlap() const
    {
      // The velocities may add half the limit to an overlap that the last
      // correction left at half the limit, so that a step without a new
      // impact ends within the limit and needs no correction: correcting
      // every step shuffles a settled bed like tapping (doc/contacts.md).
      return (correcting ? 1. : 0.5) * overlap_limit();
    }



    template <int dim>
    double
    ContactSolver<dim>::overlap_limit() const
    {
      return parameters.overlap_tolerance * smallest_radius;
    }



    template <int dim>
    bool
    ContactSolver<dim>::converged(const SweepResult &s,
                                  const double       max_overlap) const
    {
      return s.max_change <= parameters.tolerance * s.max_impulse &&
             max_overlap <= allowed_overlap();
    }



    template <int dim>
    bool
    ContactSolver<dim>::settled_by(const double energy_share) const
    {
      return energy_share <= parameters.tolerance * parameters.tolerance;
    }



    template <int dim>
    void
    ContactSolver<dim>::finish(GrainArrays<dim> &grain_arrays)
    {
      AssertThrow(grain_arrays.velocity.size() == n_grains,
                  dealii::ExcMessage(
                    "ContactSolver: finish() needs the GrainArrays given to "
                    "setup()."));
      if (correcting)
      {
        grain_arrays.position_correction.resize(n_grains);
        for (unsigned int i = 0; i < n_grains; ++i)
          for (unsigned int d = 0; d < dim; ++d)
            grain_arrays.position_correction[i][d] =
              dt * grains[slot(i)].velocity[d];
        std::swap(grains, solved_grains);
        for (unsigned int k = 0; k < rows.size(); ++k)
          rows[k].p_n = solved_p_n[k];
        correcting = false;
      }
      else
        grain_arrays.position_correction.clear();

      const bool friction = (parameters.friction > 0);
      for (unsigned int i = 0; i < n_grains; ++i)
      {
        for (unsigned int d = 0; d < dim; ++d)
          grain_arrays.velocity[i][d] = grains[slot(i)].velocity[d];
        if (friction)
          for (unsigned int d = 0; d < spin_dim; ++d)
            grain_arrays.angular_velocity[i][d] =
              spins[slot(i)].angular_velocity[d];
      }

      const unsigned int n_rows = rows.size();
      pair_results.normal.resize(n_pairs);
      pair_results.tangential.resize(n_pairs);
      wall_results.normal.resize(n_rows - n_pairs);
      wall_results.tangential.resize(n_rows - n_pairs);
      cache.clear();
      cache.reserve(n_rows);
      for (unsigned int m = 0; m < n_rows; ++m)
      {
        const unsigned int k = row_of_input[m];
        Tensor<1, dim>     p_t;
        if (friction)
          for (unsigned int d = 0; d < dim; ++d)
            p_t[d] = friction_rows[k].p_t[d];
        ContactImpulses<dim> &out = (m < n_pairs ? pair_results : wall_results);
        const unsigned int    q   = (m < n_pairs ? m : m - n_pairs);
        out.normal[q]             = rows[k].p_n;
        out.tangential[q]         = p_t;
        if (rows[k].p_n > 0)
        {
          CachedImpulse c{keys[k], rows[k].p_n, key_sign[k] * p_t, {}};
          if (!rolling_rows.empty())
            for (unsigned int d = 0; d < spin_dim; ++d)
              c.p_r[d] = key_sign[k] * rolling_rows[k].p_r[d];
          cache.push_back(c);
        }
      }

      // Pairs and walls each come sorted from the neighbour searches, so
      // this is a merge; a caller with other orders pays a sort.
      const auto by_key = [](const CachedImpulse &a, const CachedImpulse &b)
      { return a.key < b.key; };
      const auto middle =
        std::find_if(cache.begin(),
                     cache.end(),
                     [](const CachedImpulse &c)
                     { return (c.key.second & wall_key_bit) != 0; });
      if (!std::is_sorted(cache.begin(), middle, by_key))
        std::sort(cache.begin(), middle, by_key);
      if (!std::is_sorted(middle, cache.end(), by_key))
        std::sort(middle, cache.end(), by_key);
      std::inplace_merge(cache.begin(), middle, cache.end(), by_key);
    }



    template <int dim>
    const ContactImpulses<dim> &
    ContactSolver<dim>::pair_impulses() const
    {
      return pair_results;
    }



    template <int dim>
    const ContactImpulses<dim> &
    ContactSolver<dim>::wall_impulses() const
    {
      return wall_results;
    }



    template <int dim>
    Tensor<1, dim>
    ContactSolver<dim>::get_velocity(const unsigned int grain) const
    {
      AssertIndexRange(grain, n_grains);
      Tensor<1, dim> v;
      for (unsigned int d = 0; d < dim; ++d)
        v[d] = grains[slot(grain)].velocity[d];
      return v;
    }



    template <int dim>
    void
    ContactSolver<dim>::set_velocity(const unsigned int    grain,
                                     const Tensor<1, dim> &velocity)
    {
      AssertIndexRange(grain, n_grains);
      for (unsigned int d = 0; d < dim; ++d)
        grains[slot(grain)].velocity[d] = velocity[d];
    }



    template <int dim>
    AngularVelocity<dim>
    ContactSolver<dim>::get_angular_velocity(const unsigned int grain) const
    {
      AssertIndexRange(grain, n_grains);
      AngularVelocity<dim> w;
      if (!spins.empty())
        for (unsigned int d = 0; d < spin_dim; ++d)
          w[d] = spins[slot(grain)].angular_velocity[d];
      return w;
    }



    template <int dim>
    void
    ContactSolver<dim>::set_angular_velocity(
      const unsigned int          grain,
      const AngularVelocity<dim> &angular_velocity)
    {
      AssertIndexRange(grain, n_grains);
      if (!spins.empty())
        for (unsigned int d = 0; d < spin_dim; ++d)
          spins[slot(grain)].angular_velocity[d] = angular_velocity[d];
    }



    template class ContactSolver<2>;
    template class ContactSolver<3>;
  } // namespace Contact
} // namespace ImmersedGrains
