// A ball dropped from rest onto a floor wall under gravity, with the simplest
// explicit free step (v += dt g; contact solve; x += dt v), for discs and
// spheres.
//
// Rebounds: each impact leaves with e times the arrival speed, so the k-th
// apex is h_k = e^(2k) h0. The scheme takes the arrival speed at the start of
// the impact step and lets the ball turn up to one step's travel early, so
// each bounce is off by O(g dt) in speed; relative to V_k = e^k sqrt(2 g h0)
// these errors add up over the bounces. The check is
//   |h_k / (e^(2k) h0) - 1| <= 4 k g dt / V_k,
// at dt and, with half the bound, at dt/2 (the error depends on where in a
// step each impact falls, so it shrinks with dt without halving exactly).
//
// Rest: the bounce times add up to the finite time
//   T = t0 + 2 e V0 / (g (1 - e)),  t0 = sqrt(2 h0 / g),  V0 = g t0,
// and the ball must come to rest (zero velocity for the rest of the run)
// at a fixed dt, within 2 % of T (the printed rest times lie within 1 %
// after T: each impact is off by up to a step).

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
  const double gravity = 9.81;
  const double h0      = 1.0; // initial height of the ball's bottom
  const double radius  = 0.05;

  struct Run
  {
    std::vector<double> apex;      // heights of the bottom at each apex
    double              rest_time; // -1: never at rest
    bool                solver_ok;
  };

  template <int dim>
  Run
  drop(const double e, const double dt, const double end_time)
  {
    Walls<dim>     walls;
    Tensor<1, dim> up;
    up[dim - 1] = 1;
    walls.add_plane(Point<dim>(), up);

    GrainArrays<dim> ball;
    ball.velocity.resize(1);
    ball.inverse_mass = {1 / 0.3};
    ball.radius       = {radius};
    std::vector<Point<dim>> x(1);
    x[0][dim - 1] = radius + h0;

    ContactParameters parameters;
    parameters.restitution = e;
    parameters.tolerance   = 1e-12;
    ContactSolver<dim>            solver(parameters);
    std::vector<WallContact<dim>> contacts;

    Run    run{{}, -1, true};
    double last_moving = 0;
    for (unsigned int step = 0; step * dt < end_time; ++step)
    {
      const double t      = (step + 1) * dt;
      ball.start_velocity = ball.velocity;
      ball.velocity[0][dim - 1] -= dt * gravity;
      walls.find_contacts(x, ball.radius, radius, contacts);
      run.solver_ok &=
        solver.solve({}, contacts, walls.velocities(), ball, dt).converged;
      x[0] += dt * ball.velocity[0];

      const double vz_before = ball.start_velocity[0][dim - 1];
      const double vz        = ball.velocity[0][dim - 1];
      if (vz_before > 0 && vz <= 0)
        run.apex.push_back(x[0][dim - 1] - radius);
      if (ball.velocity[0].norm() > 0)
        last_moving = t;
    }
    if (last_moving < end_time - dt)
      run.rest_time = last_moving;
    return run;
  }

  bool all_ok = true;

  template <int dim>
  void
  check(const double e, const unsigned int n_bounces)
  {
    const double dt = 1e-4;
    const double t0 = std::sqrt(2 * h0 / gravity);
    const double V0 = gravity * t0;
    const double T  = (e < 1 ? t0 + 2 * e * V0 / (gravity * (1 - e)) : 0.);
    const double end_time = (e < 1 ? 1.5 * T : t0 * (2 * n_bounces + 1.5));

    const Run fine   = drop<dim>(e, dt / 2, end_time);
    const Run coarse = drop<dim>(e, dt, end_time);
    std::printf("%dD e=%.1f, dt=%g:\n", dim, e, dt);
    bool ok = coarse.solver_ok && fine.solver_ok &&
              coarse.apex.size() >= n_bounces && fine.apex.size() >= n_bounces;
    for (unsigned int k = 1; ok && k <= n_bounces; ++k)
    {
      const double expected   = std::pow(e, 2 * k) * h0;
      const double V_k        = std::pow(e, k) * V0;
      const double limit      = 4 * k * gravity * dt / V_k;
      const double error      = std::abs(coarse.apex[k - 1] / expected - 1);
      const double error_fine = std::abs(fine.apex[k - 1] / expected - 1);
      const bool   within     = (error <= limit);
      const bool   half_dt_ok = (error_fine <= limit / 2);
      ok                      = ok && within && half_dt_ok;
      std::printf("  apex %u: h = %.4f, e^%u h0 = %.4f, "
                  "within 4 k g dt / V_k: %s, at dt/2 within half: %s\n",
                  k,
                  coarse.apex[k - 1],
                  2 * k,
                  expected,
                  within ? "yes" : "no",
                  half_dt_ok ? "yes" : "no");
    }
    if (e < 1)
    {
      const bool at_rest =
        coarse.rest_time > 0 && std::abs(coarse.rest_time - T) < 0.02 * T;
      ok = ok && at_rest;
      std::printf("  at rest after t = %.2f s (finite-time limit T = %.2f "
                  "s, within 2 %%: %s)\n",
                  coarse.rest_time,
                  T,
                  at_rest ? "yes" : "no");
    }
    std::printf("  %s\n", ok ? "OK" : "FAILED");
    all_ok = all_ok && ok;
  }
} // namespace

int
main()
{
  check<2>(0.5, 3);
  check<3>(0.5, 3);
  check<3>(0.8, 5);
  check<3>(1.0, 5);
  check<3>(0.0, 0);
  return all_ok ? 0 : 1;
}
