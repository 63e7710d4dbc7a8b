// Two-body collisions through the whole contact chain (bucket grid or walls,
// then ContactSolver) against Newton's law for rigid spheres
// (doc/references.md, "Collisions": v1' = v1 - (1+e) m2/(m1+m2) (v12.n) n,
// v2' = v2 + (1+e) m1/(m1+m2) (v12.n) n), head-on and oblique, e in
// {0, 0.5, 1}, equal and unequal masses, discs and spheres; a grain against a
// fixed grain and a moving wall (m2 -> infinity); the contact laws of the
// step (no bounce from inside the alert distance, gap closed exactly with
// e = 0); and friction: momentum and angular momentum conservation, Coulomb's
// cone, and the impulsive stick (v_t' = 5/7 v_t for a sphere, 2/3 for a
// disc) and slide (dv_t = -mu (1+e) |v_n|) results. Checked to 1e-10
// relative, for a contact solve run to 1e-14.

#include <immersed_grains/contact/bucket_grid.h>
#include <immersed_grains/contact/contact_solver.h>
#include <immersed_grains/contact/walls.h>

#include <cmath>
#include <cstdio>
#include <string>

using namespace ImmersedGrains::Contact;
using dealii::Point;
using dealii::Tensor;

namespace
{
  const double dt = 1e-3;

  double max_error = 0; // relative to the speed scale of each case
  bool   all_ok    = true;

  void
  report(const std::string &name, const double error, const double limit)
  {
    const bool ok = (error < limit);
    all_ok        = all_ok && ok;
    max_error     = std::max(max_error, error);
    std::printf("%-48s %s\n", name.c_str(), ok ? "OK" : "FAILED");
  }

  template <int dim>
  Tensor<1, dim>
  unit_normal()
  {
    // Not along an axis, so that every component is exercised.
    Tensor<1, dim> n;
    if (dim == 2)
    {
      n[0] = 0.6;
      n[1] = 0.8;
    }
    else
    {
      n[0]       = 2. / 7;
      n[1]       = 3. / 7;
      n[dim - 1] = 6. / 7;
    }
    return n;
  }

  template <int dim>
  Tensor<1, dim>
  unit_tangent()
  {
    Tensor<1, dim> t;
    if (dim == 2)
    {
      t[0] = -0.8;
      t[1] = 0.6;
    }
    else
    {
      t[0]       = 3. / 7;
      t[1]       = -6. / 7;
      t[dim - 1] = 2. / 7;
    }
    return t;
  }

  template <int dim>
  GrainArrays<dim>
  two_grains(const double          m1,
             const double          m2,
             const Tensor<1, dim> &v1,
             const Tensor<1, dim> &v2)
  {
    GrainArrays<dim> g;
    g.velocity         = {v1, v2};
    g.start_velocity   = {v1, v2};
    g.inverse_mass     = {m1 > 0 ? 1. / m1 : 0., m2 > 0 ? 1. / m2 : 0.};
    g.radius           = {0.5, 0.7};
    g.angular_velocity = {AngularVelocity<dim>(), AngularVelocity<dim>()};
    g.inverse_inertia  = {0, 0};
    return g;
  }

  template <int dim>
  SolverResult
  collide(GrainArrays<dim>     &g,
          const double          gap,
          const double          e,
          const double          mu,
          std::vector<double>  *impulse = nullptr,
          ContactImpulses<dim> *all     = nullptr)
  {
    const Tensor<1, dim>    n = unit_normal<dim>();
    std::vector<Point<dim>> x(2);
    x[1] = Point<dim>(n * (g.radius[0] + g.radius[1] + gap));

    Point<dim> lower, upper;
    for (unsigned int d = 0; d < dim; ++d)
    {
      lower[d] = -5;
      upper[d] = 5;
    }
    BucketGrid<dim>             grid(lower, upper);
    std::vector<GrainPair<dim>> pairs;
    grid.find_pairs(x, g.radius, 0.1, pairs);

    ContactParameters parameters;
    parameters.restitution = e;
    parameters.friction    = mu;
    parameters.tolerance   = 1e-14;
    ContactSolver<dim> solver(parameters);
    const SolverResult result = solver.solve(pairs, {}, {}, g, dt);
    if (impulse)
      *impulse = solver.pair_impulses().normal;
    if (all)
      *all = solver.pair_impulses();
    return result;
  }

  template <int dim>
  void
  newton_collisions()
  {
    const Tensor<1, dim> n = unit_normal<dim>();
    const Tensor<1, dim> t = unit_tangent<dim>();
    for (const double e : {0., 0.5, 1.})
      for (const double m2 : {2., 7.})
        for (const bool oblique : {false, true})
        {
          const double   m1 = 2;
          Tensor<1, dim> v1 = 1.3 * n, v2 = -0.4 * n;
          if (oblique)
          {
            v1 += 0.9 * t;
            v2 -= 1.1 * t;
          }
          GrainArrays<dim> g = two_grains<dim>(m1, m2, v1, v2);
          collide(g, 0., e, 0.);

          const double         v12n = (v1 - v2) * n;
          const Tensor<1, dim> e1   = v1 - (1 + e) * m2 / (m1 + m2) * v12n * n;
          const Tensor<1, dim> e2   = v2 + (1 + e) * m1 / (m1 + m2) * v12n * n;
          const double         error =
            std::max((g.velocity[0] - e1).norm(), (g.velocity[1] - e2).norm()) /
            std::max(v1.norm(), v2.norm());

          char name[80];
          std::snprintf(name,
                        sizeof(name),
                        "%dD e=%.1f %s masses %s",
                        dim,
                        e,
                        m2 == m1 ? "equal  " : "unequal",
                        oblique ? "oblique" : "head-on");
          report(name, error, 1e-10);
        }
  }

  // A grain against an infinitely heavy partner: a fixed grain, then a
  // moving wall. Newton: v' = v - (1+e) ((v - V).n) n.
  template <int dim>
  void
  infinite_mass_collisions()
  {
    const Tensor<1, dim> n = unit_normal<dim>();
    const Tensor<1, dim> t = unit_tangent<dim>();
    for (const double e : {0., 0.5, 1.})
    {
      const Tensor<1, dim> v = 1.3 * n + 0.7 * t;
      GrainArrays<dim>     g = two_grains<dim>(2., 0., v, Tensor<1, dim>());
      collide(g, 0., e, 0.);
      const Tensor<1, dim> expected = v - (1 + e) * (v * n) * n;
      char                 name[80];
      std::snprintf(name, sizeof(name), "%dD e=%.1f fixed grain", dim, e);
      report(name,
             std::max((g.velocity[0] - expected).norm(), g.velocity[1].norm()) /
               v.norm(),
             1e-10);
    }

    for (const double e : {0., 0.5, 1.})
    {
      // Floor through the origin with inward normal (0,..,1), moving.
      Walls<dim>     walls;
      Tensor<1, dim> up, wall_velocity;
      up[dim - 1]            = 1;
      wall_velocity[0]       = 0.3;
      wall_velocity[dim - 1] = 0.2;
      walls.add_plane(Point<dim>(), up, wall_velocity);

      GrainArrays<dim> g;
      Tensor<1, dim>   v;
      v[0]             = 0.8;
      v[dim - 1]       = -1.5;
      g.velocity       = {v};
      g.start_velocity = {v};
      g.inverse_mass   = {0.5};
      g.radius         = {0.5};
      std::vector<Point<dim>> x(1);
      x[0][dim - 1] = 0.5;
      std::vector<WallContact<dim>> contacts;
      walls.find_contacts(x, g.radius, 0.1, contacts);

      ContactParameters parameters;
      parameters.restitution = e;
      parameters.tolerance   = 1e-14;
      ContactSolver<dim> solver(parameters);
      solver.solve({}, contacts, walls.velocities(), g, dt);
      const Tensor<1, dim> expected =
        v - (1 + e) * ((v - wall_velocity) * up) * up;
      char name[80];
      std::snprintf(name, sizeof(name), "%dD e=%.1f moving wall", dim, e);
      report(name, (g.velocity[0] - expected).norm() / v.norm(), 1e-10);
    }
  }

  // What the step does with contacts that are not simply touching.
  template <int dim>
  void
  step_laws()
  {
    const Tensor<1, dim> n = unit_normal<dim>();
    char                 name[80];

    // Approaching, inside the alert distance, but too far to meet within
    // the step: no impulse, even with e = 1.
    {
      GrainArrays<dim>    g = two_grains<dim>(2., 3., n, -n);
      std::vector<double> p;
      collide(g, 0.05, 1., 0., &p);
      std::snprintf(name, sizeof(name), "%dD no bounce from afar", dim);
      report(name,
             std::max((g.velocity[0] - n).norm(), (g.velocity[1] + n).norm()) +
               std::abs(p[0]),
             1e-14);
    }
    // Meeting within the step with e = 0: the gap closes exactly, no more.
    {
      const double     gap = 0.4 * 2 * dt;
      GrainArrays<dim> g   = two_grains<dim>(2., 3., n, -n);
      collide(g, gap, 0., 0.);
      const double end_gap = gap + dt * (g.velocity[1] - g.velocity[0]) * n;
      std::snprintf(name, sizeof(name), "%dD e=0 closes the gap exactly", dim);
      report(name, std::abs(end_gap) / gap, 1e-10);
    }
    // Separating while touching: untouched.
    {
      GrainArrays<dim> g = two_grains<dim>(2., 3., -n, n);
      collide(g, 0., 0.5, 0.);
      std::snprintf(name, sizeof(name), "%dD separating pair untouched", dim);
      report(name,
             std::max((g.velocity[0] + n).norm(), (g.velocity[1] - n).norm()),
             1e-14);
    }
    // An overlap at rest beyond the tolerance is reduced to half the
    // tolerance within one step by moving the grains
    // (GrainArrays::position_correction), which leave it without speed:
    // pushing them apart would give them |gap|/dt.
    {
      const double     overlap = 1e-3; // twice the limit, 1e-3 r_min
      GrainArrays<dim> g =
        two_grains<dim>(2., 3., Tensor<1, dim>(), Tensor<1, dim>());
      collide(g, -overlap, 1., 0.);
      const double limit = ContactParameters().overlap_tolerance * 0.5;
      double end_gap     = -overlap + dt * (g.velocity[1] - g.velocity[0]) * n;
      if (!g.position_correction.empty())
        end_gap += (g.position_correction[1] - g.position_correction[0]) * n;
      std::snprintf(name,
                    sizeof(name),
                    "%dD overlap down to half the limit in one step",
                    dim);
      report(name, std::abs(end_gap + 0.5 * limit) / overlap, 1e-10);
      std::snprintf(name,
                    sizeof(name),
                    "%dD ... the grains keep no speed",
                    dim);
      report(name, std::max(g.velocity[0].norm(), g.velocity[1].norm()), 1e-14);
    }
  }

  template <int dim>
  double
  cross_z_or_vector_part(const Tensor<1, dim> &a,
                         const Tensor<1, dim> &b,
                         const unsigned int    c)
  {
    if (dim == 2)
      return a[0] * b[1] - a[1] * b[0];
    return a[(c + 1) % 3] * b[(c + 2) % 3] - a[(c + 2) % 3] * b[(c + 1) % 3];
  }

  // Oblique collision of two spinning grains with friction: conservation of
  // linear and angular momentum (about the origin, spin included) and
  // Coulomb's law at the contact.
  template <int dim>
  void
  friction_pair(const double mu)
  {
    const Tensor<1, dim> n  = unit_normal<dim>();
    const Tensor<1, dim> t  = unit_tangent<dim>();
    const double         m1 = 2, m2 = 5;
    GrainArrays<dim>     g =
      two_grains<dim>(m1, m2, 1.3 * n + 0.9 * t, -0.4 * n - 1.1 * t);
    const double I1 = 0.4 * m1 * 0.25, I2 = 0.4 * m2 * 0.49;
    g.inverse_inertia = {1 / I1, 1 / I2};
    for (unsigned int c = 0; c < AngularVelocity<dim>::dimension; ++c)
    {
      g.angular_velocity[0][c] = 0.7 - 0.3 * c;
      g.angular_velocity[1][c] = -1.1 + 0.5 * c;
    }
    const GrainArrays<dim> before = g;
    ContactImpulses<dim>   impulses;
    collide(g, 0., 0.5, mu, nullptr, &impulses);

    const Point<dim> x1, x2(n * 1.2);
    const auto       momenta = [&](const GrainArrays<dim> &s)
    {
      std::vector<double> m(dim + AngularVelocity<dim>::dimension);
      for (unsigned int d = 0; d < dim; ++d)
        m[d] = m1 * s.velocity[0][d] + m2 * s.velocity[1][d];
      for (unsigned int c = 0; c < AngularVelocity<dim>::dimension; ++c)
        m[dim + c] = m1 * cross_z_or_vector_part<dim>(x1, s.velocity[0], c) +
                     m2 * cross_z_or_vector_part<dim>(x2, s.velocity[1], c) +
                     I1 * s.angular_velocity[0][c] +
                     I2 * s.angular_velocity[1][c];
      return m;
    };
    const std::vector<double> m0 = momenta(before), m_end = momenta(g);
    double                    error = 0;
    for (unsigned int k = 0; k < m0.size(); ++k)
      error = std::max(error, std::abs(m_end[k] - m0[k]));
    char name[80];
    std::snprintf(
      name, sizeof(name), "%dD mu=%.2f momentum and angular momentum", dim, mu);
    report(name, error / (m2 * 1.5), 1e-10);

    // Coulomb: inside the cone with zero slip, or on its edge opposite to
    // the slip.
    const auto spin_velocity = [&](const unsigned int i, const double r)
    {
      // w x (r n) for the lever r n.
      Tensor<1, dim> v;
      const auto    &w = g.angular_velocity[i];
      if (dim == 2)
      {
        v[0] = -w[0] * r * n[1];
        v[1] = w[0] * r * n[0];
      }
      else
        for (unsigned int c = 0; c < 3; ++c)
          v[c] = r * (w[(c + 1) % 3] * n[(c + 2) % 3] -
                      w[(c + 2) % 3] * n[(c + 1) % 3]);
      return v;
    };
    Tensor<1, dim> slip = g.velocity[1] + spin_velocity(1, -0.7) -
                          g.velocity[0] - spin_velocity(0, 0.5);
    slip -= (slip * n) * n;
    const Tensor<1, dim> p_t   = impulses.tangential[0];
    const double         p_n   = impulses.normal[0];
    const double         scale = 1.5;
    double               coulomb;
    if (p_t.norm() < mu * p_n * (1 - 1e-9))
      coulomb = slip.norm() / scale;
    else
      coulomb = (p_t + mu * p_n * slip / slip.norm()).norm() / p_n;
    std::snprintf(name,
                  sizeof(name),
                  "%dD mu=%.2f Coulomb law (%s)",
                  dim,
                  mu,
                  p_t.norm() < mu * p_n * (1 - 1e-9) ? "stick" : "slide");
    report(name, coulomb, 1e-10);
  }

  // A grain without spin hitting a floor obliquely. Stick: w_t = 1/m + r^2/I
  // gives v_t' = v_t (1 - 1/(m w_t)) = 5/7 v_t for a sphere (I = 2/5 m r^2),
  // 2/3 v_t for a disc (I = 1/2 m r^2). Slide: p_t = mu p_n, so
  // v_t' = v_t - mu (1+e) |v_n| and the spin gains r mu (1+e) |v_n| m / I.
  template <int dim>
  void
  friction_on_floor(const double mu)
  {
    const double   m = 2, r = 0.5, e = 0.5;
    const double   I = (dim == 2 ? 0.5 : 0.4) * m * r * r;
    Walls<dim>     walls;
    Tensor<1, dim> up;
    up[dim - 1] = 1;
    walls.add_plane(Point<dim>(), up);

    GrainArrays<dim> g;
    Tensor<1, dim>   v;
    v[0]               = 0.8;
    v[dim - 1]         = -1.5;
    g.velocity         = {v};
    g.start_velocity   = {v};
    g.inverse_mass     = {1 / m};
    g.inverse_inertia  = {1 / I};
    g.radius           = {r};
    g.angular_velocity = {AngularVelocity<dim>()};
    std::vector<Point<dim>> x(1);
    x[0][dim - 1] = r;
    std::vector<WallContact<dim>> contacts;
    walls.find_contacts(x, g.radius, 0.1, contacts);

    ContactParameters parameters;
    parameters.restitution = e;
    parameters.friction    = mu;
    parameters.tolerance   = 1e-14;
    ContactSolver<dim> solver(parameters);
    solver.solve({}, contacts, walls.velocities(), g, dt);

    const bool   stick = (mu >= 1);
    const double v_t   = stick ? v[0] * (1 - 1 / (m * (1 / m + r * r / I))) :
                                 v[0] - mu * (1 + e) * std::abs(v[dim - 1]);
    // Spin axis: -z in 2D, +y in 3D, for motion along +x on a floor below.
    const double spin =
      stick ? v_t / r : r * mu * (1 + e) * std::abs(v[dim - 1]) * m / I;
    const double w =
      (dim == 2 ? -g.angular_velocity[0][0] : g.angular_velocity[0][dim - 2]);
    const double error =
      std::max({std::abs(g.velocity[0][0] - v_t),
                std::abs(g.velocity[0][dim - 1] - e * std::abs(v[dim - 1])),
                std::abs(w - spin) * r}) /
      v.norm();
    char name[80];
    std::snprintf(name,
                  sizeof(name),
                  "%dD mu=%.2f floor impact (%s)",
                  dim,
                  mu,
                  stick ? "stick: 5/7, 2/3 rule" : "slide");
    report(name, error, 1e-10);
  }
} // namespace

int
main()
{
  newton_collisions<2>();
  newton_collisions<3>();
  infinite_mass_collisions<2>();
  infinite_mass_collisions<3>();
  step_laws<2>();
  step_laws<3>();
  for (const double mu : {0.05, 2.})
  {
    friction_pair<2>(mu);
    friction_pair<3>(mu);
    friction_on_floor<2>(mu);
    friction_on_floor<3>(mu);
  }
  std::printf("max relative error < 1e-10: %s\n", all_ok ? "yes" : "NO");
  return all_ok ? 0 : 1;
}
