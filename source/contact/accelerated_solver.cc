#include <immersed_grains/contact/contact_solver.h>

#include "row_kinematics.h"

#include <algorithm>
#include <cmath>

// Accelerated projected gradient descent (APGD) for the contact problem of
// contact_solver.cc (Mazhar, Heyn, Negrut & Tasora, "Using Nesterov's method
// to accelerate multibody dynamics with friction and contact", ACM TOG
// 34(3), 32, 2015; Nesterov's scheme with the adaptive step of Beck &
// Teboulle's FISTA and the gradient restart of O'Donoghue & Candes, Found.
// Comput. Math. 15, 2015).
//
// Without friction the step's normal impulses p solve the quadratic program
//
//   min f(p) = 1/2 p.N p + p.(u_free - ubar)   over p >= 0,
//
// N = H^T M_eff^{-1} H the Delassus operator, whose gradient
// N p + u_free - ubar = u_n(p) - ubar is the relative normal velocity the
// impulses p leave, less its target; its optimality conditions are the
// complementarity conditions 0 <= p _|_ u_n - ubar >= 0 of the normal law.
// With D = diag(w_n) (the diagonal of N, w_n = 1/m_i + 1/m_j) as metric,
// one iteration is
//
//   y       = p_k + beta_k (p_k - p_{k-1})
//   p_{k+1} = proj_{p >= 0} (y - D^{-1} (u_n(y) - ubar) / L)
//
// accepted if the step d = p_{k+1} - y satisfies d.N d <= L d.D d (the
// quadratic upper bound that makes it a descent step), else L doubles and
// the trial is redone; after each accepted step L shrinks by 0.9 so that the
// step follows the local curvature. theta_{k+1} solves
// theta_{k+1}^2 = (1 - theta_{k+1}) theta_k^2, beta_{k+1} =
// theta_k (1 - theta_k) / (theta_k^2 + theta_{k+1}), and the momentum
// restarts (theta = 1, beta = 0) when grad f(y).(p_{k+1} - p_k) > 0.
// With L = 1 and no momentum this is projected Jacobi.
//
// Nothing but contact-space vectors is needed besides one application of N
// per trial: u_n is linear in p, so u_n(y) = u_n(p_k) + beta_k (u_n(p_k) -
// u_n(p_{k-1})), and N d = u_n(p_{k+1}) - u_n(y). A trial applies the
// impulse change p_{k+1} - p_k to the working velocities (scatter), then
// reads u_n(p_{k+1}) back (gather); in between, a distributed caller glues
// the copies of shared grains (mass splitting, distributed_contacts.cc), so
// every rank sees the velocities of the global iterate.
//
// With friction p is the contact's impulse vector p_n n + p_t, u the
// relative velocity of the contact points (rotation included), the gradient
// u - ubar n, the metric the contact's Delassus block W = w_n n(x)n +
// w_t (1 - n(x)n), and the projection the one of the Gauss-Seidel update
// (p_n onto p_n >= 0, then p_t onto |p_t| <= mu p_n): Coulomb's law, not
// the cone complementarity relaxation of Mazhar et al., so there is no
// convergence proof but the same fixed points as Gauss-Seidel.
//
// Convergence is tested as for Gauss-Seidel: the change one projected
// Jacobi step would make at p_{k+1} (the impulse change of a sweep) against
// the largest impulse, and the predicted overlap.

namespace ImmersedGrains
{
  namespace Contact
  {



    namespace
    {
      // The one-contact projected step from impulse y with gradient g:
      // x = proj(y - s W^{-1} g), W = w_n n(x)n + w_t (1 - n(x)n), the
      // projection onto p_n >= 0 and then |p_t| <= mu p_n.
      template <int dim>
      inline void
      projected_step(const double *y,
                     const double *g,
                     const double *n,
                     const double  s_n, // s / w_n
                     const double  s_t, // s / w_t
                     const double  mu,
                     double       *x)
      {
        double y_n = 0, g_n = 0;
        for (unsigned int d = 0; d < dim; ++d)
        {
          y_n += y[d] * n[d];
          g_n += g[d] * n[d];
        }
        const double p_n = std::max(0., y_n - s_n * g_n);
        double       t[dim], t2 = 0;
        for (unsigned int d = 0; d < dim; ++d)
        {
          t[d] = (y[d] - y_n * n[d]) - s_t * (g[d] - g_n * n[d]);
          t2 += t[d] * t[d];
        }
        const double limit = mu * p_n;
        const double scale = (t2 > limit * limit ? limit / std::sqrt(t2) : 1.);
        for (unsigned int d = 0; d < dim; ++d)
          x[d] = p_n * n[d] + scale * t[d];
      }
    } // namespace



    template <int dim>
    template <bool with_friction>
    void
    ContactSolver<dim>::apgd_start()
    {
      constexpr unsigned int c      = (with_friction ? dim : 1);
      const std::size_t      n_rows = rows.size();
      p_old.resize(c * n_rows);
      p_new.resize(c * n_rows);
      u.resize(c * n_rows);
      u_old.resize(c * n_rows);
      u_new.resize(c * n_rows);
      // The warm-started impulses are the first iterate (and its own
      // predecessor: no momentum yet); apgd_measure() reads their
      // velocities.
      for (std::size_t k = 0; k < n_rows; ++k)
        for (unsigned int d = 0; d < c; ++d)
        {
          const double p   = (with_friction ? rows[k].p_n * rows[k].normal[d] +
                                              friction_rows[k].p_t[d] :
                                              rows[k].p_n);
          p_old[c * k + d] = p_new[c * k + d] = p;
        }
      std::fill(u.begin(), u.end(), 0.);
      std::fill(u_old.begin(), u_old.end(), 0.);
      theta    = 1;
      momentum = 0;
      // L >= 1 bounds the largest eigenvalue of D^{-1} N from below.
      lipschitz = std::max(lipschitz, 1.);
    }



    template <int dim>
    template <bool with_friction>
    void
    ContactSolver<dim>::apgd_trial()
    {
      constexpr unsigned int c      = (with_friction ? dim : 1);
      const std::size_t      n_rows = rows.size();
      const double           b      = momentum;
      const double           s      = 1. / lipschitz;
      const double           mu     = parameters.friction;
      accepted_grains               = grains;
      if (with_friction)
        accepted_spins = spins;

      for (std::size_t k = 0; k < n_rows; ++k)
      {
        Row   &row = rows[k];
        double y[c], g[c], x[c];
        for (unsigned int d = 0; d < c; ++d)
        {
          const double p = p_new[c * k + d]; // the accepted iterate
          y[d]           = p + b * (p - p_old[c * k + d]);
          g[d]           = u[c * k + d] + b * (u[c * k + d] - u_old[c * k + d]);
        }
        if constexpr (!with_friction)
        {
          x[0] = std::max(0., y[0] - s * row.inverse_w * (g[0] - row.target));
          const double dp = x[0] - p_new[k];
          p_new[k]        = x[0];
          GrainSlot   &ga = grains[row.i];
          GrainSlot   &gb = grains[row.j];
          const double da = ga.inverse_mass * dp;
          const double db = gb.inverse_mass * dp;
          for (unsigned int d = 0; d < dim; ++d)
          {
            ga.velocity[d] -= da * row.normal[d];
            gb.velocity[d] += db * row.normal[d];
          }
        }
        else
        {
          for (unsigned int d = 0; d < dim; ++d)
            g[d] -= row.target * row.normal[d];
          projected_step<dim>(y,
                              g,
                              row.normal,
                              s * row.inverse_w,
                              s * friction_rows[k].inverse_w_t,
                              mu,
                              x);
          double dp[dim], dp_n = 0;
          for (unsigned int d = 0; d < dim; ++d)
          {
            dp[d] = x[d] - p_new[c * k + d];
            dp_n += dp[d] * row.normal[d];
            p_new[c * k + d] = x[d];
          }
          for (unsigned int d = 0; d < dim; ++d)
            dp[d] -= dp_n * row.normal[d];
          apply_impulse(k, dp_n, dp);
        }
      }
    }



    template <int dim>
    template <bool with_friction>
    AcceleratedMeasures
    ContactSolver<dim>::apgd_measure()
    {
      constexpr unsigned int c      = (with_friction ? dim : 1);
      const std::size_t      n_rows = rows.size();
      const double           b      = momentum;
      const double           mu     = parameters.friction;
      AcceleratedMeasures    m;
      double                 max_d2 = 0, max_p2 = 0, overlap = 0;

      for (std::size_t k = 0; k < n_rows; ++k)
      {
        const Row &row = rows[k];
        double     un[c];
        contact_velocity<with_friction>(k, un);

        // The accepted iterate p is in rows (and friction_rows).
        double p[c];
        if constexpr (!with_friction)
          p[0] = row.p_n;
        else
          for (unsigned int d = 0; d < dim; ++d)
            p[d] = row.p_n * row.normal[d] + friction_rows[k].p_t[d];

        double y[c], uy[c], g[c], x[c], dd[c], du[c];
        double un_n = 0, dd_n = 0;
        for (unsigned int d = 0; d < c; ++d)
        {
          y[d]  = p[d] + b * (p[d] - p_old[c * k + d]);
          uy[d] = u[c * k + d] + b * (u[c * k + d] - u_old[c * k + d]);
          g[d]  = uy[d] - row.target * (with_friction ? row.normal[d] : 1.);
          dd[d] = p_new[c * k + d] - y[d];
          du[d] = un[d] - uy[d];
          m.curvature += dd[d] * du[d];
          m.restart += g[d] * (p_new[c * k + d] - p[d]);
          un_n += un[d] * (with_friction ? row.normal[d] : 1.);
          dd_n += dd[d] * (with_friction ? row.normal[d] : 1.);
          u_new[c * k + d] = un[d];
        }

        // |d|_D^2; a contact between fixed grains has no metric (and
        // cannot move).
        if (row.inverse_w > 0)
        {
          m.metric += dd_n * dd_n / row.inverse_w;
          if constexpr (with_friction)
          {
            const double w_t = friction_rows[k].inverse_w_t;
            if (w_t > 0)
              for (unsigned int d = 0; d < dim; ++d)
              {
                const double t = dd[d] - dd_n * row.normal[d];
                m.metric += t * t / w_t;
              }
          }
          overlap = std::max(overlap, -(gaps[k] + dt * un_n));
        }

        // The change one projected Jacobi step would make.
        double change2 = 0, p2 = 0;
        if constexpr (!with_friction)
        {
          x[0] = std::max(0., p_new[k] + row.inverse_w * (row.target - un[0]));
          change2 = (x[0] - p_new[k]) * (x[0] - p_new[k]);
          p2      = p_new[k] * p_new[k];
        }
        else
        {
          double gn[dim];
          for (unsigned int d = 0; d < dim; ++d)
            gn[d] = un[d] - row.target * row.normal[d];
          projected_step<dim>(&p_new[c * k],
                              gn,
                              row.normal,
                              row.inverse_w,
                              friction_rows[k].inverse_w_t,
                              mu,
                              x);
          for (unsigned int d = 0; d < dim; ++d)
          {
            change2 += (x[d] - p_new[c * k + d]) * (x[d] - p_new[c * k + d]);
            p2 += p_new[c * k + d] * p_new[c * k + d];
          }
        }
        max_d2 = std::max(max_d2, change2);
        max_p2 = std::max(max_p2, p2);
      }
      m.max_change     = std::sqrt(max_d2);
      m.max_impulse    = std::sqrt(max_p2);
      m.max_overlap    = overlap;
      m.overlap_excess = overlap - allowed_overlap();
      return m;
    }



    template <int dim>
    bool
    ContactSolver<dim>::apgd_accept(const AcceleratedMeasures &global)
    {
      const bool        friction = with_friction();
      const unsigned    c        = (friction ? dim : 1);
      const std::size_t n_rows   = rows.size();
      // The step-size test, with room for round-off in d.N d, which is a
      // difference of velocities.
      if (global.curvature > lipschitz * global.metric * (1 + 1e-9) &&
          global.curvature > 1e-14 * lipschitz * global.metric + 1e-300)
      {
        grains = accepted_grains;
        if (friction)
          spins = accepted_spins;
        // The trial impulses go back to the accepted ones.
        for (std::size_t k = 0; k < n_rows; ++k)
        {
          if (!friction)
            p_new[k] = rows[k].p_n;
          else
            for (unsigned int d = 0; d < dim; ++d)
              p_new[c * k + d] =
                rows[k].p_n * rows[k].normal[d] + friction_rows[k].p_t[d];
        }
        lipschitz *= 2;
        return false;
      }

      for (std::size_t k = 0; k < n_rows; ++k)
      {
        Row &row = rows[k];
        if (!friction)
        {
          p_old[k] = row.p_n;
          row.p_n  = p_new[k];
        }
        else
        {
          double p_n = 0;
          for (unsigned int d = 0; d < dim; ++d)
          {
            p_old[c * k + d] =
              row.p_n * row.normal[d] + friction_rows[k].p_t[d];
            p_n += p_new[c * k + d] * row.normal[d];
          }
          row.p_n = p_n;
          for (unsigned int d = 0; d < dim; ++d)
            friction_rows[k].p_t[d] = p_new[c * k + d] - p_n * row.normal[d];
        }
      }
      std::swap(u_old, u);
      std::swap(u, u_new);

      if (global.restart > 0)
      {
        theta    = 1;
        momentum = 0;
      }
      else
      {
        const double next =
          0.5 * (-theta * theta + theta * std::sqrt(theta * theta + 4));
        momentum = theta * (1 - theta) / (theta * theta + next);
        theta    = next;
      }
      lipschitz *= 0.9;
      return true;
    }



    template <int dim>
    SolverResult
    ContactSolver<dim>::iterate_accelerated(
      const std::function<void()>                      &glue,
      const std::function<void(AcceleratedMeasures &)> &reduce)
    {
      const bool   friction = with_friction();
      SolverResult result;
      result.n_contacts = rows.size();

      // The starting point (warm start) may already be converged.
      friction ? apgd_start<true>() : apgd_start<false>();
      AcceleratedMeasures m =
        (friction ? apgd_measure<true>() : apgd_measure<false>());
      reduce(m);
      std::swap(u, u_new);
      u_old = u;

      const auto test = [&](const AcceleratedMeasures &m)
      {
        result.residual =
          (m.max_impulse > 0 ? m.max_change / m.max_impulse : 0.);
        result.max_overlap = m.max_overlap;
        result.converged =
          m.max_change <= parameters.tolerance * m.max_impulse &&
          m.overlap_excess <= 0;
      };
      test(m);
      while (!result.converged && result.iterations < parameters.max_iterations)
      {
        friction ? apgd_trial<true>() : apgd_trial<false>();
        glue();
        m = (friction ? apgd_measure<true>() : apgd_measure<false>());
        reduce(m);
        ++result.iterations;
        if (apgd_accept(m))
          test(m);
      }
      return result;
    }



    template SolverResult
    ContactSolver<2>::iterate_accelerated(
      const std::function<void()> &,
      const std::function<void(AcceleratedMeasures &)> &);
    template SolverResult
    ContactSolver<3>::iterate_accelerated(
      const std::function<void()> &,
      const std::function<void(AcceleratedMeasures &)> &);
  } // namespace Contact
} // namespace ImmersedGrains
