#ifndef immersed_grains_coupling_self_disturbance_h
#define immersed_grains_coupling_self_disturbance_h

#include <deal.II/base/point.h>

#include <string>

namespace ImmersedGrains
{
  /**
   * What a grain's own presence adds to the fields its drag law reads
   * (doc/theory.md, "The grain's own disturbance"), so that the law sees
   * the fluid as it would be without the grain, as the closures assume:
   *
   * - its own share of the projected solid fraction at its centre,
   *   phi_self = V P(x), P the projection kernel's value at the grain
   *   (for the Q1 L2 projection on a box cell the product over directions
   *   of (1-xi)^2 g0 + xi^2 g0 + 2 xi (1-xi) g1 over h, with g0 = sqrt(3),
   *   g1 = -(2 - sqrt(3)) sqrt(3) from the inverse of the 1D mass matrix,
   *   g0 = 1, g1 = 0 when lumped);
   * - its own disturbance of the fluid velocity it feels, u_self = K f with
   *   f the force it exerts on the fluid and K the self-mobility of the
   *   drag distribution: the regularised Stokeslet of the spreading
   *   kernel, felt through the same kernel,
   *     K = (1 / (phi mu)) int |g^(k)|^2 (1 - k_z^2 / k^2) / k^2 dk/(2 pi)^d,
   *   evaluated once for a unit cell (cell spread: the cell's indicator;
   *   filtered: the Q1 hat times the Helmholtz filter 1 / (1 + l^2 k^2)),
   *   so that K = c(l/h) / (phi mu h) in 3D. In 2D the integral diverges
   *   logarithmically with the box (a disc's Stokeslet): K is not modelled
   *   there and is 0.
   *
   * K depends only on the distribution and the cell: no constant in it is
   * fitted to a run (benchmarks/self_disturbance/ reproduces the
   * integrals and compares them with measured lone grains).
   *
   * Among other grains both parts are smaller: no other grain's centre
   * comes closer than a diameter, and the hole this leaves around the
   * grain takes out of the fields it reads a share of what the grain puts
   * in, the more so the denser the packing. For kernels wider than a
   * grain the share that stays is the static structure factor at zero
   * wave number, structure_factor() (doc/theory.md).
   *
   * The disturbance needs time to build up: a fluid with a time
   * derivative reaches K f over the kernel's diffusion time t_K =
   * build_up_time(), and a grain that slips through the fluid leaves its
   * disturbance behind after t_w = sqrt(nu t_K)/|w| (with advection).
   * Coupling relaxes each grain's u_self towards K f with
   *   d u_self/dt = K f / t_K - u_self (1/t_K + 1/t_w),
   * so that a steady Stokes fluid gets K f, a slow unsteady one the same
   * after a few t_K, and a fast grain (Re_h = |w| h/nu > 1) the Oseen-like
   * K f / (1 + t_K/t_w).
   */
  template <int dim>
  class SelfDisturbance
  {
  public:
    /**
     * @p distribution "cell", "filtered" or "point" (no velocity model:
     * K = 0); @p smoothing_length the filter's l; @p lumped the
     * projection's mass matrix.
     */
    SelfDisturbance(const std::string &distribution,
                    double             smoothing_length,
                    bool               lumped);

    /** K [s/kg] for a grain in a cell of size @p h at fluid fraction
     *  @p phi in a fluid of viscosity @p mu. */
    double
    mobility(double h, double phi, double mu) const;

    /** The time its disturbance takes to build up to 1 - 1/e of K f once
     *  the fluid feels a constant force (unsteady Stokes, fluid at rest):
     *  0.60 h^2/nu for the cell spread, (1.14 h^2 + 9.4 l^2)/nu filtered
     *  (benchmarks/self_disturbance/kernel_integrals.py). */
    double
    build_up_time(double h, double kinematic_viscosity) const;

    /** S(0) of hard spheres (3D, Percus-Yevick: (1 - s)^4 / (1 + 2 s)^2)
     *  or hard discs (2D, scaled-particle theory: (1 - s)^3 / (1 + s)) at
     *  solid fraction @p s: the part of a grain's own disturbance that its
     *  neighbours' exclusion hole leaves in a kernel much wider than the
     *  grain; 1 for a lone grain. */
    static double
    structure_factor(double s);

    /** The grain's own projected solid fraction at its centre, for a grain
     *  of volume @p volume at @p reference (unit cell coordinates) in a
     *  cell of size @p h. */
    double
    own_solid_fraction(const dealii::Point<dim> &reference,
                       double                    h,
                       double                    volume) const;

  private:
    enum class Kernel
    {
      cell,     // the cell's indicator
      filtered, // the Q1 hat times the Helmholtz filter
      none      // the point distribution: not modelled
    };
    const Kernel kernel;
    const double smoothing_length;
    const bool   lumped;
  };
} // namespace ImmersedGrains

#endif
