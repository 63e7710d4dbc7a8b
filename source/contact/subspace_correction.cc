#include <immersed_grains/contact/contact_solver.h>

#include <algorithm>
#include <cmath>

// A subspace correction for projected Gauss-Seidel on dense packings.
//
// Without friction the step's normal impulses minimise the quadratic
//
//   f(p) = 1/2 p.N p + p.(u_free - ubar)   over p >= 0
//
// (accelerated_solver.cc), N = H^T M^{-1} H the Delassus operator, whose
// gradient u_n(p) - ubar is the contact velocity less its target. A sweep
// is one round of coordinate descent on f, and it removes an error e at a
// rate set by e.N e / e.D e (D = diag N): a force network that nearly
// balances every grain is hardly touched. A frictionless packing has about
// one contact per degree of freedom (it is isostatic at jamming), and N then
// has a great many such small eigenvalues, spread over all the grains, not
// smooth in space (doc/contacts.md, "Subspace correction").
//
// Once the sweeps have found which contacts carry an impulse, the problem
// on those contacts A is linear. A correction takes a fixed number of
// conjugate-gradient steps (Jacobi-preconditioned: D_AA) from zero on
// N_AA d = -(u_n - ubar)_A, the change that would make every contact of A
// hold exactly; they need about the square root of the iterations a sweep
// method needs. It then moves the impulses along d by the step that
// minimises f along d, projected onto p >= 0 and halved until f falls. This is
// the subspace minimisation of Silcowitz-Hansen, Niebe & Erleben's PGS-SM
// (GRAPP 2010) and of the truncated nonsmooth Newton multigrid (Graeser &
// Kornhuber, J. Comput. Math. 27, 2009) with a Krylov solve in place of the
// multigrid: the impulses of a nearly isostatic network are not unique (N_AA is
// singular where A holds more contacts than the grains have degrees of
// freedom), but a few conjugate-gradient steps from zero stay in the range of
// N_AA and the line search only accepts a step that lowers f. Every correction
// lowering f, the iteration keeps Gauss-Seidel's convergence; the sweeps
// that follow change the set of contacts where the correction has pushed
// an impulse to zero or a closed contact apart.

namespace ImmersedGrains
{
  namespace Contact
  {
    template <int dim>
    double
    ContactSolver<dim>::apply_delassus(const std::vector<double>   &d,
                                       std::vector<double>         &image,
                                       const std::function<void()> &glue)
    {
      // The scratch slots hold the inverse masses (subspace_correction());
      // their velocities are set to M^-1 H d alone. Each slot adds up its
      // rows' impulses in their order: the sums of a scatter over the rows,
      // to the last bit, without a store that the next row must wait for.
      grains.swap(subspace_velocities);
      const unsigned int n       = subspace_geometry.size();
      const unsigned int n_slots = grains.size();
      for (unsigned int g = 0; g < n_slots; ++g)
      {
        GrainSlot   &slot = grains[g];
        double       v[dim]{};
        const double inverse_mass = slot.inverse_mass;
        for (unsigned int e = subspace_incidence_start[g];
             e < subspace_incidence_start[g + 1];
             ++e)
        {
          // v - p n is v + (-p) n to the last bit: no branch on the side.
          const unsigned int entry = subspace_incidence[e];
          const double       p =
            (entry % 2 == 0 ? -inverse_mass : inverse_mass) * d[entry / 2];
          const double *normal = subspace_geometry[entry / 2].normal;
          for (unsigned int c = 0; c < dim; ++c)
            v[c] += p * normal[c];
        }
        for (unsigned int c = 0; c < dim; ++c)
          slot.velocity[c] = v[c];
      }
      glue();
      // The product d.(N d) beside the gather: its chain of additions
      // overlaps the gather's independent work.
      double d_image = 0;
      for (unsigned int q = 0; q < n; ++q)
      {
        const SubspaceRow &row = subspace_geometry[q];
        const GrainSlot   &a   = grains[row.i];
        const GrainSlot   &b   = grains[row.j];
        double             u_n = 0;
        for (unsigned int c = 0; c < dim; ++c)
          u_n += (b.velocity[c] - a.velocity[c]) * row.normal[c];
        image[q] = u_n;
        d_image += d[q] * u_n;
      }
      grains.swap(subspace_velocities);
      return d_image;
    }



    template <int dim>
    double
    ContactSolver<dim>::subspace_correction(
      const std::function<void()>                       &glue,
      const std::function<void(double *, unsigned int)> &sum)
    {
      // Every rank takes the same decisions from here on (the sums), so
      // that the glues match.
      if (with_friction())
        return 0;

      subspace_rows.clear();
      subspace_inverse_w.clear();
      subspace_geometry.clear();
      for (unsigned int k = 0; k < rows.size(); ++k)
        if (rows[k].p_n > 0 && rows[k].inverse_w > 0)
        {
          subspace_rows.push_back(k);
          subspace_inverse_w.push_back(rows[k].inverse_w);
          SubspaceRow packed{rows[k].i, rows[k].j, {}};
          for (unsigned int c = 0; c < dim; ++c)
            packed.normal[c] = rows[k].normal[c];
          subspace_geometry.push_back(packed);
        }
      subspace_velocities  = grains;
      const unsigned int n = subspace_rows.size();
      subspace_incidence_start.assign(grains.size() + 1, 0);
      for (const SubspaceRow &row : subspace_geometry)
      {
        ++subspace_incidence_start[row.i + 1];
        ++subspace_incidence_start[row.j + 1];
      }
      for (unsigned int g = 0; g < grains.size(); ++g)
        subspace_incidence_start[g + 1] += subspace_incidence_start[g];
      subspace_incidence.resize(2 * n);
      {
        std::vector<unsigned int> &next = subspace_incidence_next;
        next.assign(subspace_incidence_start.begin(),
                    subspace_incidence_start.end() - 1);
        for (unsigned int q = 0; q < n; ++q)
        {
          subspace_incidence[next[subspace_geometry[q].i]++] = 2 * q;
          subspace_incidence[next[subspace_geometry[q].j]++] = 2 * q + 1;
        }
      }
      subspace_gradient.resize(n);
      subspace_solution.assign(n, 0.);
      subspace_residual.resize(n);
      subspace_search.resize(n);
      subspace_image.resize(n);
      subspace_p_n.resize(n);

      // Conjugate gradients on N_AA d = -(u_n - ubar)_A from d = 0.
      // With the scale of f: 1/2 p.D p, the energy the impulses would
      // carry if each acted alone.
      double start[2] = {0, 0};
      for (unsigned int q = 0; q < n; ++q)
      {
        const Row   &row     = rows[subspace_rows[q]];
        const double g       = normal_velocity(row) - row.target;
        subspace_gradient[q] = g;
        subspace_residual[q] = -g;
        subspace_search[q]   = -g * row.inverse_w;
        start[0] += g * g * row.inverse_w;
        start[1] += 0.5 * row.p_n * row.p_n / row.inverse_w;
      }
      sum(start, 2);
      double       rz         = start[0];
      const double initial_rz = rz;
      const double scale      = start[1];
      if (!(rz > 0) || !(scale > 0))
        return 0;
      for (unsigned int it = 0;
           it < parameters.subspace_iterations && rz > 1e-24 * initial_rz;
           ++it)
      {
        // Sums run in locals: sum() takes an address, and an accumulator
        // kept in memory stores on every term.
        double curvature =
          apply_delassus(subspace_search, subspace_image, glue);
        sum(&curvature, 1);
        if (!(curvature > 0))
          break;
        const double alpha    = rz / curvature;
        double       local_rz = 0;
        for (unsigned int q = 0; q < n; ++q)
        {
          subspace_solution[q] += alpha * subspace_search[q];
          subspace_residual[q] -= alpha * subspace_image[q];
          local_rz +=
            subspace_residual[q] * subspace_residual[q] * subspace_inverse_w[q];
        }
        double rz_new = local_rz;
        sum(&rz_new, 1);
        const double beta = rz_new / rz;
        rz                = rz_new;
        for (unsigned int q = 0; q < n; ++q)
          subspace_search[q] = subspace_residual[q] * subspace_inverse_w[q] +
                               beta * subspace_search[q];
      }

      // The step that minimises f along d: -grad f.d / d.N d.
      const double d_image =
        apply_delassus(subspace_solution, subspace_image, glue);
      double g_d = 0;
      for (unsigned int q = 0; q < n; ++q)
        g_d += subspace_gradient[q] * subspace_solution[q];
      double along[2] = {g_d, d_image};
      sum(along, 2);
      if (!(along[1] > 0) || !(along[0] < 0))
        return 0;
      double step = -along[0] / along[1];
      // What the step would lower f by without the projection: what a
      // correction reports where no projected step lowers f, so that a
      // step is not called solved for want of a step.
      const double predicted = 0.5 * step * -along[0] / scale;

      // Projected onto p >= 0 the step may raise f; halve it until f falls.
      // f changes by grad f.dp + 1/2 dp.N dp, and N dp is the change of the
      // contact velocities that dp makes.
      subspace_velocities = grains;
      for (unsigned int q = 0; q < n; ++q)
        subspace_p_n[q] = rows[subspace_rows[q]].p_n;
      for (unsigned int attempt = 0; attempt < 8; ++attempt, step *= 0.5)
      {
        for (unsigned int q = 0; q < n; ++q)
        {
          Row         &row = rows[subspace_rows[q]];
          const double p =
            std::max(0., subspace_p_n[q] + step * subspace_solution[q]);
          const double dp = p - subspace_p_n[q];
          row.p_n         = p;
          GrainSlot &a    = grains[row.i];
          GrainSlot &b    = grains[row.j];
          for (unsigned int c = 0; c < dim; ++c)
          {
            a.velocity[c] -= a.inverse_mass * dp * row.normal[c];
            b.velocity[c] += b.inverse_mass * dp * row.normal[c];
          }
        }
        glue();
        double change[2] = {0, 0};
        for (unsigned int q = 0; q < n; ++q)
        {
          const Row   &row = rows[subspace_rows[q]];
          const double dp  = row.p_n - subspace_p_n[q];
          const double du =
            normal_velocity(row) - row.target - subspace_gradient[q];
          change[0] += subspace_gradient[q] * dp;
          change[1] += dp * du;
        }
        sum(change, 2);
        const double share = -(change[0] + 0.5 * change[1]) / scale;
        // A correction that finds (almost) nothing left only tests: the
        // step is solved to the tolerance, and a step taken would need
        // another sweep to confirm it.
        if (share > 0 && !settled_by(share))
          return share;
        if (share > 0)
        {
          grains = subspace_velocities;
          for (unsigned int q = 0; q < n; ++q)
            rows[subspace_rows[q]].p_n = subspace_p_n[q];
          return share;
        }
        grains = subspace_velocities;
        for (unsigned int q = 0; q < n; ++q)
          rows[subspace_rows[q]].p_n = subspace_p_n[q];
      }
      return predicted;
    }



    template double
    ContactSolver<2>::subspace_correction(
      const std::function<void()> &,
      const std::function<void(double *, unsigned int)> &);
    template double
    ContactSolver<3>::subspace_correction(
      const std::function<void()> &,
      const std::function<void(double *, unsigned int)> &);
  } // namespace Contact
} // namespace ImmersedGrains
