// Throughput of the contact core: a dense lattice packing of N grains (FCC
// spheres in 3D, hexagonal discs in 2D, positions jittered by 1e-3 r so that
// gaps and overlaps are random) in a closed box under gravity, e = 0, stepped
// a few times with warm starting. Every grain touches 12 (3D) or 6 (2D)
// others, the hardest case for projected Gauss-Seidel.
//
// Reports per N, averaged over 5 steps after a first one for warm-up:
// contacts, iterations per step (Gauss-Seidel sweeps or APGD trial steps),
// contact updates per second in the iterations alone and for the whole
// solve (setup and write-back included), nanoseconds per update (one
// contact visited once in a sweep, or once in an APGD iteration's scatter
// and gather), the time per step to converge, and the neighbour search
// time per step. Goal: a few ns per contact update, 2e7 updates/s per
// core.
//
// Usage: contact_throughput [--friction MU] [--solver gauss-seidel|apgd]
//                           [--shuffle] [dim] [N ...]
//        (default: frictionless, Gauss-Seidel, 3D, N = 1000 10000 100000;
//        --shuffle numbers the grains in random order instead of lattice
//        order, to measure the neighbour search on unsorted input)

#include <immersed_grains/contact/bucket_grid.h>
#include <immersed_grains/contact/contact_solver.h>
#include <immersed_grains/contact/walls.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

using namespace ImmersedGrains::Contact;
using dealii::Point;
using dealii::Tensor;

namespace
{
  using Clock = std::chrono::steady_clock;

  double
  seconds_since(const Clock::time_point start)
  {
    return std::chrono::duration<double>(Clock::now() - start).count();
  }

  // Lattice sites with nearest-neighbour distance 2 r, lowest corner at
  // (r, ..., r), filling a cube (square) until n sites are placed.
  template <int dim>
  std::vector<Point<dim>>
  lattice(const unsigned int n, const double r, Point<dim> &upper)
  {
    std::vector<Point<dim>> x;
    if (dim == 3)
    {
      // FCC: sites of a cubic grid of spacing sqrt(2) r with even index
      // sum.
      const double       s    = std::sqrt(2.) * r;
      const unsigned int side = std::ceil(std::cbrt(2. * n));
      for (unsigned int k = 0; k < side && x.size() < n; ++k)
        for (unsigned int j = 0; j < side && x.size() < n; ++j)
          for (unsigned int i = 0; i < side && x.size() < n; ++i)
            if ((i + j + k) % 2 == 0)
            {
              Point<dim> p;
              p[0]       = r + s * i;
              p[1]       = r + s * j;
              p[dim - 1] = r + s * k;
              x.push_back(p);
            }
      for (unsigned int d = 0; d < dim; ++d)
        upper[d] = 2 * r + s * (side - 1);
    }
    else
    {
      // Hexagonal: rows sqrt(3) r apart, every other row shifted by r.
      const unsigned int side = std::ceil(std::sqrt(1.0 * n));
      const double       h    = std::sqrt(3.) * r;
      for (unsigned int j = 0; j < 2 * side && x.size() < n; ++j)
        for (unsigned int i = 0; i < side && x.size() < n; ++i)
        {
          Point<dim> p;
          p[0] = r + 2 * r * i + (j % 2) * r;
          p[1] = r + h * j;
          x.push_back(p);
        }
      upper[0] = 2 * r * side + r;
      upper[1] = x.back()[1] + r;
    }
    return x;
  }

  template <int dim>
  void
  run(const unsigned int  n,
      const double        friction,
      const ContactMethod method,
      const bool          shuffle)
  {
    const double r = 1e-3, rho = 2400, g = 9.81, dt = 1e-4, alert = 0.1 * r;
    // One step to warm up (allocations, cold caches), then timed steps.
    const unsigned int n_steps = 5;

    Point<dim>                             lower, upper;
    std::vector<Point<dim>>                x = lattice<dim>(n, r, upper);
    std::mt19937                           random(42);
    std::uniform_real_distribution<double> jitter(-1e-3 * r, 1e-3 * r);
    for (auto &p : x)
      for (unsigned int d = 0; d < dim; ++d)
        p[d] += jitter(random);
    if (shuffle)
      std::shuffle(x.begin(), x.end(), random);

    BucketGrid<dim>           grid(lower, upper);
    Walls<dim>                walls;
    std::array<bool, 2 * dim> all_faces;
    all_faces.fill(true);
    walls.add_box(lower, upper, all_faces);

    const double mass =
      rho * (dim == 2 ? M_PI * r * r : 4. / 3 * M_PI * r * r * r);
    GrainArrays<dim> grains;
    grains.velocity.resize(n);
    grains.radius.assign(n, r);
    grains.inverse_mass.assign(n, 1 / mass);
    grains.angular_velocity.resize(n);
    grains.inverse_inertia.assign(n,
                                  1 / ((dim == 2 ? 0.5 : 0.4) * mass * r * r));

    ContactParameters parameters;
    parameters.tolerance = 1e-4;
    parameters.friction  = friction;
    parameters.method    = method;
    ContactSolver<dim> solver(parameters);

    std::vector<GrainPair<dim>>   pairs;
    std::vector<WallContact<dim>> contacts;
    double       search_time = 0, sweep_time = 0, solve_time = 0;
    double       updates = 0, sweeps = 0, n_contacts = 0, max_overlap = 0;
    unsigned int n_converged = 0;
    for (unsigned int step = 0; step <= n_steps; ++step)
    {
      if (step == 1)
      {
        search_time = sweep_time = solve_time = 0;
        updates = sweeps = n_contacts = max_overlap = 0;
        n_converged                                 = 0;
      }
      for (auto &v : grains.velocity)
        v[dim - 1] -= dt * g;

      auto start = Clock::now();
      grid.find_pairs(x, grains.radius, alert, pairs);
      walls.find_contacts(x, grains.radius, alert, contacts);
      search_time += seconds_since(start);

      // solve() spelled out, to time the sweeps apart from the packing.
      start = Clock::now();
      solver.setup(pairs, contacts, walls.velocities(), grains, dt);
      const auto   sweeps_start = Clock::now();
      unsigned int iterations   = 0;
      bool         converged    = false;
      double       overlap      = 0;
      if (method == ContactMethod::apgd)
      {
        const SolverResult result =
          solver.iterate_accelerated([] {}, [](AcceleratedMeasures &) {});
        iterations = result.iterations;
        converged  = result.converged;
        overlap    = result.max_overlap;
      }
      else
        while (!converged && iterations < parameters.max_iterations)
        {
          const SweepResult s = solver.sweep();
          ++iterations;
          if (s.max_change <= parameters.tolerance * s.max_impulse)
          {
            overlap   = solver.predicted_max_overlap();
            converged = solver.converged(s, overlap);
          }
        }
      sweep_time += seconds_since(sweeps_start);
      if (!converged && method != ContactMethod::apgd)
        overlap = solver.predicted_max_overlap();
      solver.finish(grains);
      solve_time += seconds_since(start);

      for (unsigned int i = 0; i < n; ++i)
        x[i] += dt * grains.velocity[i];

      const double m = pairs.size() + contacts.size();
      n_contacts += m;
      updates += m * iterations;
      sweeps += iterations;
      n_converged += converged;
      max_overlap = std::max(max_overlap, overlap);
    }

    std::printf("%dD %s mu=%.2g N=%-7u contacts=%-8.0f iterations/step=%-6.1f "
                "converged=%u/%u max overlap/r=%.1e\n",
                dim,
                method == ContactMethod::apgd ? "apgd" : "gauss-seidel",
                friction,
                n,
                n_contacts / n_steps,
                sweeps / n_steps,
                n_converged,
                n_steps,
                max_overlap / r);
    std::printf("    iterations: %.3g updates/s (%.1f ns/update); whole "
                "solve: %.3g updates/s, %.3g s/step; neighbour search: "
                "%.3g s/step (%.0f ns/grain)\n",
                updates / sweep_time,
                1e9 * sweep_time / updates,
                updates / solve_time,
                solve_time / n_steps,
                search_time / n_steps,
                1e9 * search_time / n_steps / n);
  }
} // namespace

int
main(int argc, char **argv)
{
  std::vector<std::string> args(argv + 1, argv + argc);
  double                   friction = 0;
  ContactMethod            method   = ContactMethod::gauss_seidel;
  bool                     shuffle  = false;
  while (!args.empty() && args[0].rfind("--", 0) == 0)
  {
    if (args[0] == "--shuffle")
    {
      shuffle = true;
      args.erase(args.begin());
      continue;
    }
    if (args.size() < 2 || (args[0] != "--friction" && args[0] != "--solver"))
    {
      std::fprintf(stderr,
                   "contact_throughput: unknown option %s\n",
                   args[0].c_str());
      return 1;
    }
    if (args[0] == "--friction")
      friction = std::atof(args[1].c_str());
    else if (args[1] == "apgd")
      method = ContactMethod::apgd;
    else if (args[1] != "gauss-seidel")
    {
      std::fprintf(stderr,
                   "contact_throughput: unknown solver %s\n",
                   args[1].c_str());
      return 1;
    }
    args.erase(args.begin(), args.begin() + 2);
  }
  const int dim = (args.empty() ? 3 : std::atoi(args[0].c_str()));
  std::vector<unsigned int> sizes;
  for (unsigned int a = 1; a < args.size(); ++a)
    sizes.push_back(std::atoi(args[a].c_str()));
  if (sizes.empty())
    sizes = {1000, 10000, 100000};
  if (dim != 2 && dim != 3)
  {
    std::fprintf(stderr, "contact_throughput: dim must be 2 or 3\n");
    return 1;
  }
  for (const unsigned int n : sizes)
  {
    if (dim == 2)
      run<2>(n, friction, method, shuffle);
    else
      run<3>(n, friction, method, shuffle);
  }
  return 0;
}
