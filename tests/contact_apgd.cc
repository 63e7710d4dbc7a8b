// The accelerated solver (Contacts/Solver = apgd) against projected
// Gauss-Seidel on the same problems: a random dense packing of polydisperse
// discs and spheres in a closed box, falling from rest under gravity with a
// few grains thrown in fast and one fixed, stepped 20 times, each step
// solved to a relative tolerance of 1e-10 by both methods from the same
// state. The end-of-step velocities are unique (the impulses need not be,
// on a hyperstatic packing), so they must agree to 1e-7 of the speed scale;
// the predicted overlap must be below its limit. With friction (mu = 0.3,
// rotation) the problem is no longer a convex program and need not have a
// unique answer: both must converge, and the Coulomb cone must hold. A cap
// of 3 iterations must be reported as a failure, not hidden. Gauss-Seidel
// runs without its subspace correction (the method APGD is measured
// against), and once more with it: it must converge too, and without
// friction reach the same velocities in fewer sweeps. Both sides are this
// code's solvers: a random packing has no closed-form answer, but without
// friction its end-of-step velocities are unique, so two different
// methods solved to 1e-10 must meet; 1e-7 of the speed scale leaves the
// tolerance's effect on a hyperstatic packing room.

#include <immersed_grains/contact/bucket_grid.h>
#include <immersed_grains/contact/contact_solver.h>
#include <immersed_grains/contact/walls.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

using namespace ImmersedGrains::Contact;
using dealii::Point;
using dealii::Tensor;

namespace
{
  bool all_ok = true;

  void
  report(const char *what, const bool ok)
  {
    std::printf("  %s: %s\n", what, ok ? "yes" : "no");
    all_ok = all_ok && ok;
  }

  template <int dim>
  void
  packing(const double friction)
  {
    // A lattice of spacing 1 with radii in [0.4, 0.5]: many contacts
    // within the alert distance, some closed, some overlapping slightly.
    const unsigned int n_side = (dim == 2 ? 20 : 8);
    Point<dim>         lower, upper;
    for (unsigned int d = 0; d < dim; ++d)
      upper[d] = n_side;
    std::array<bool, dim>     periodic{};
    std::array<bool, 2 * dim> faces;
    faces.fill(true);
    BucketGrid<dim> grid(lower, upper, periodic);
    Walls<dim>      walls;
    walls.add_box(lower, upper, faces);

    std::mt19937                           random(7);
    std::uniform_real_distribution<double> uniform(0, 1);
    std::vector<Point<dim>>                x;
    GrainArrays<dim>                       grains;
    const unsigned int                     n = std::pow(n_side, dim);
    for (unsigned int q = 0; q < n; ++q)
    {
      Point<dim>   p;
      unsigned int rest = q;
      for (unsigned int d = 0; d < dim; ++d, rest /= n_side)
        p[d] = 0.5 + (rest % n_side) + 0.02 * (uniform(random) - 0.5);
      x.push_back(p);
      const double r = 0.45 + 0.06 * (uniform(random) - 0.5);
      grains.radius.push_back(r);
      const double m = std::pow(r, dim);
      grains.inverse_mass.push_back(q == n / 2 ? 0. : 1 / m);
      grains.inverse_inertia.push_back(q == n / 2 ? 0. : 2.5 / (m * r * r));
      Tensor<1, dim> v;
      if (q % 37 == 0 && q != n / 2)
        for (unsigned int d = 0; d < dim; ++d)
          v[d] = 4 * (uniform(random) - 0.5);
      grains.velocity.push_back(v);
      grains.angular_velocity.emplace_back();
    }
    grains.start_velocity = grains.velocity;

    ContactParameters gs, apgd;
    gs.subspace_interval = 0;
    gs.tolerance = apgd.tolerance = 1e-10;
    gs.overlap_tolerance = apgd.overlap_tolerance = 1e-6;
    gs.max_iterations                             = 100000;
    apgd.max_iterations                           = 20000;
    gs.friction = apgd.friction = friction;
    apgd.method                 = ContactMethod::apgd;
    ContactParameters subspace  = gs;
    subspace.subspace_interval  = 10;
    ContactSolver<dim> solver_gs(gs), solver_apgd(apgd),
      solver_subspace(subspace);

    const double                  dt = 0.01, g = 10, alert = 0.3;
    std::vector<GrainPair<dim>>   pairs;
    std::vector<WallContact<dim>> contacts;
    double                        max_difference = 0, max_overlap = 0;
    double                        cone_excess = 0, subspace_difference = 0;
    bool                          converged = true;
    unsigned int sweeps = 0, iterations = 0, subspace_sweeps = 0;
    for (unsigned int step = 0; step < 20; ++step)
    {
      for (unsigned int i = 0; i < n; ++i)
        if (grains.inverse_mass[i] > 0)
          grains.velocity[i][dim - 1] -= dt * g;
      grid.find_pairs(x, grains.radius, alert, pairs);
      walls.find_contacts(x, grains.radius, alert, contacts);

      GrainArrays<dim>   other = grains, third = grains;
      const SolverResult a =
        solver_gs.solve(pairs, contacts, walls.velocities(), grains, dt);
      const SolverResult b =
        solver_apgd.solve(pairs, contacts, walls.velocities(), other, dt);
      const SolverResult c =
        solver_subspace.solve(pairs, contacts, walls.velocities(), third, dt);
      converged = converged && a.converged && b.converged && c.converged;
      sweeps += a.iterations;
      iterations += b.iterations;
      subspace_sweeps += c.iterations;
      max_overlap =
        std::max(max_overlap, b.max_overlap / solver_apgd.overlap_limit());
      if (friction == 0)
        for (unsigned int i = 0; i < n; ++i)
        {
          max_difference =
            std::max(max_difference,
                     (grains.velocity[i] - other.velocity[i]).norm());
          subspace_difference =
            std::max(subspace_difference,
                     (grains.velocity[i] - third.velocity[i]).norm());
        }
      const auto &p = solver_apgd.pair_impulses();
      for (unsigned int q = 0; q < p.normal.size(); ++q)
        cone_excess = std::max(cone_excess,
                               p.tangential[q].norm() - friction * p.normal[q]);

      for (unsigned int i = 0; i < n; ++i)
        x[i] += dt * grains.velocity[i];
      grains.start_velocity = grains.velocity;
    }

    std::printf("%dD, %u grains, friction %.1f:\n", dim, n, friction);
    report("both converge in every step", converged);
    report("APGD needs fewer iterations than Gauss-Seidel sweeps",
           iterations < sweeps);
    report("predicted overlap below its limit", max_overlap <= 1);
    report("Coulomb cone holds", cone_excess <= 1e-12);
    if (friction == 0)
    {
      report("same velocities to 1e-7 of the speed scale g dt",
             max_difference < 1e-8);
      report("with subspace corrections: the same velocities",
             subspace_difference < 1e-8);
      report("with subspace corrections: fewer sweeps",
             subspace_sweeps < sweeps);
    }

    // A cap the solver cannot meet is a reported failure.
    ContactParameters capped = apgd;
    capped.max_iterations    = 3;
    capped.warm_start        = false;
    ContactSolver<dim> solver_capped(capped);
    GrainArrays<dim>   again = grains;
    for (unsigned int i = 0; i < n; ++i)
      if (again.inverse_mass[i] > 0)
        again.velocity[i][dim - 1] -= dt * g;
    const SolverResult c =
      solver_capped.solve(pairs, contacts, walls.velocities(), again, dt);
    // (3 for the velocities, and 3 more if the position correction runs.)
    report("a cap of 3 iterations is reported as not converged",
           !c.converged && (c.iterations == 3 || c.iterations == 6) &&
             c.residual > 1e-10);
  }
} // namespace

int
main()
{
  packing<2>(0);
  packing<3>(0);
  packing<2>(0.3);
  packing<3>(0.3);
  std::printf("%s\n", all_ok ? "OK" : "FAILED");
  return all_ok ? 0 : 1;
}
