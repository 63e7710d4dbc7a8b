// A column of 10 equal grains resting on a floor wall, stepped 1000 times
// through the whole chain (bucket grid, walls, contact solver, explicit
// position update), in 2D and 3D, in vacuum and in a fluid at rest with
// buoyancy and implicit drag (inverse mass 1/(m + dt beta)).
//
// Statics (doc/references.md, "Resting column"): the contact under grain
// j from the top carries j m g (1 - rho/rho_p); checked at every step to
// 1e-8 relative, four orders above the solve's tolerance (1e-12). The gap
// term keeps the column where it is: what the
// solver leaves unconverged (relative impulse change 1e-12 per sweep)
// moves a grain by about 1e-13 r within a step and the next step takes it
// back, so the drift stays below 1e-11 r over the run instead of adding
// up. Projected Gauss-Seidel needs O(n^2) sweeps on a column of n grains
// from scratch; warm starting from the last step must cut that to a tenth
// in every later step, also after the grains are renumbered (matched by
// ids).

#include <immersed_grains/contact/bucket_grid.h>
#include <immersed_grains/contact/contact_solver.h>
#include <immersed_grains/contact/walls.h>

#include <cmath>
#include <cstdio>
#include <vector>

using namespace ImmersedGrains::Contact;
using dealii::Point;
using dealii::Tensor;

namespace
{
  bool all_ok = true;

  template <int dim>
  void
  column(const double fluid_density, const double viscosity)
  {
    const unsigned int n_grains = 10;
    const double       r = 1e-3, rho_p = 2400, g = 9.81, dt = 1e-3;
    const double volume = (dim == 2 ? M_PI * r * r : 4. / 3 * M_PI * r * r * r);
    const double m      = rho_p * volume;
    // Linearised Stokes drag: beta = dD/dw (3D 6 pi mu r; per unit depth in
    // 2D the same form is used, only the value matters here).
    const double beta   = 6 * M_PI * viscosity * r;
    const double weight = m * g * (1 - fluid_density / rho_p);

    Point<dim> lower, upper;
    for (unsigned int d = 0; d < dim; ++d)
    {
      lower[d] = -2 * r;
      upper[d] = 2 * r;
    }
    upper[dim - 1] = 2 * r * (n_grains + 1);
    std::array<bool, dim>     periodic{};
    BucketGrid<dim>           grid(lower, upper, periodic);
    Walls<dim>                walls;
    std::array<bool, 2 * dim> faces{};
    faces[2 * (dim - 1)] = true; // the floor only
    walls.add_box(lower, upper, faces);

    std::vector<Point<dim>> x(n_grains);
    for (unsigned int k = 0; k < n_grains; ++k)
      x[k][dim - 1] = lower[dim - 1] + r + 2 * r * k;
    const std::vector<Point<dim>> x0 = x;

    GrainArrays<dim> grains;
    grains.velocity.resize(n_grains);
    grains.radius.assign(n_grains, r);
    grains.inverse_mass.assign(n_grains, 1 / (m + dt * beta));

    ContactParameters parameters;
    parameters.tolerance      = 1e-12;
    parameters.max_iterations = 20000;
    ContactSolver<dim>            solver(parameters);
    std::vector<GrainPair<dim>>   pairs;
    std::vector<WallContact<dim>> contacts;

    double       max_force_error = 0, max_drift = 0;
    unsigned int first_iterations = 0, max_later_iterations = 0;
    bool         solver_ok = true, lists_ok = true;
    for (unsigned int step = 0; step < 1000; ++step)
    {
      // Free step with implicit drag against fluid at rest:
      // (m + dt beta) v_free = m v + dt weight.
      for (auto &v : grains.velocity)
      {
        v *= m / (m + dt * beta);
        v[dim - 1] -= dt * weight / (m + dt * beta);
      }
      grid.find_pairs(x, grains.radius, 0.1 * r, pairs);
      walls.find_contacts(x, grains.radius, 0.1 * r, contacts);
      lists_ok &= (pairs.size() == n_grains - 1 && contacts.size() == 1);
      const SolverResult result =
        solver.solve(pairs, contacts, walls.velocities(), grains, dt);
      solver_ok &= result.converged;
      if (step == 0)
        first_iterations = result.iterations;
      else
        max_later_iterations =
          std::max(max_later_iterations, result.iterations);
      for (unsigned int k = 0; k < n_grains; ++k)
        x[k] += dt * grains.velocity[k];

      // Pair (k, k+1) is under grain k+1, the (n - k - 1)-th from the top.
      const auto &p = solver.pair_impulses().normal;
      for (unsigned int q = 0; q < pairs.size(); ++q)
      {
        const double expected = (n_grains - pairs[q].first - 1) * weight;
        max_force_error =
          std::max(max_force_error, std::abs(p[q] / dt - expected) / expected);
      }
      const double floor_force = solver.wall_impulses().normal[0] / dt;
      max_force_error          = std::max(max_force_error,
                                 std::abs(floor_force - n_grains * weight) /
                                   (n_grains * weight));
      for (unsigned int k = 0; k < n_grains; ++k)
        max_drift = std::max(max_drift, (x[k] - x0[k]).norm() / r);
    }

    // Renumber the grains top to bottom, as a particle exchange might, and
    // give their old numbers as ids: the warm start must still find last
    // step's impulses, so the step costs no more than the others.
    const std::vector<double> last_floor = solver.wall_impulses().normal;
    GrainArrays<dim>          renumbered = grains;
    std::vector<Point<dim>>   x_renumbered(n_grains);
    renumbered.id.resize(n_grains);
    for (unsigned int k = 0; k < n_grains; ++k)
    {
      const unsigned int old = n_grains - 1 - k;
      x_renumbered[k]        = x[old];
      renumbered.velocity[k] = grains.velocity[old];
      renumbered.velocity[k][dim - 1] -= dt * weight / (m + dt * beta);
      renumbered.id[k] = old;
    }
    grid.find_pairs(x_renumbered, renumbered.radius, 0.1 * r, pairs);
    walls.find_contacts(x_renumbered, renumbered.radius, 0.1 * r, contacts);
    const SolverResult renumbered_result =
      solver.solve(pairs, contacts, walls.velocities(), renumbered, dt);
    const bool renumbered_ok =
      renumbered_result.converged &&
      renumbered_result.iterations <= max_later_iterations &&
      std::abs(solver.wall_impulses().normal[0] / last_floor[0] - 1) < 1e-8;

    std::printf("%dD, rho/rho_p = %.1f, %s:\n",
                dim,
                fluid_density / rho_p,
                viscosity > 0 ? "implicit drag" : "no drag");
    // After the renumbering, pair q is under grain q, the (q+1)-th from the
    // top.
    const auto &p = solver.pair_impulses().normal;
    std::printf("  contact force / (m g (1 - rho/rho_p)), top to bottom:");
    for (unsigned int q = 0; q < pairs.size(); ++q)
      std::printf(" %.9f", p[q] / dt / weight);
    std::printf(" %.9f (floor)\n",
                solver.wall_impulses().normal[0] / dt / weight);
    const bool forces_ok = max_force_error < 1e-8;
    const bool drift_ok  = max_drift < 1e-11;
    const bool warm_ok   = 10 * max_later_iterations <= first_iterations;
    std::printf("  contact lists complete at every step: %s\n",
                lists_ok ? "yes" : "no");
    std::printf("  every step converged: %s\n", solver_ok ? "yes" : "no");
    std::printf("  forces = j m g (1 - rho/rho_p) to 1e-8 at every step: %s\n",
                forces_ok ? "yes" : "no");
    std::printf("  max drift over 1000 steps < 1e-11 r: %s\n",
                drift_ok ? "yes" : "no");
    std::printf("  warm-started steps need < 1/10 of the first step's "
                "sweeps: %s\n",
                warm_ok ? "yes" : "no");
    std::printf("  warm start survives renumbering (ids): %s\n",
                renumbered_ok ? "yes" : "no");
    all_ok = all_ok && lists_ok && solver_ok && forces_ok && drift_ok &&
             warm_ok && renumbered_ok;
  }
} // namespace

int
main()
{
  column<2>(0, 0);
  column<3>(0, 0);
  // Glass in glycerine, the seed's materials.
  column<2>(1200, 0.12);
  column<3>(1200, 0.12);
  std::printf("%s\n", all_ok ? "OK" : "FAILED");
  return all_ok ? 0 : 1;
}
