#ifndef immersed_grains_coupling_closure_porosity_h
#define immersed_grains_coupling_closure_porosity_h

#include <algorithm>
#include <cmath>

namespace ImmersedGrains
{
  /**
   * The porosity a drag closure reads, from the fluid fraction phi of the
   * scene. Drag closures are fitted on sphere packings. In 3D the two are
   * the same. A 2D scene's discs are a cut through a packing of spheres:
   * they pack to area fractions up to 0.91 (hexagonal) where spheres reach
   * 0.74 (FCC), and a random disc packing (0.82-0.84) would read a porosity
   * of 0.16-0.18 that no closure was fitted on. With `sphere packing` a
   * disc packing reads the porosity of the sphere packing with the same gap
   * between neighbours relative to the radius on the densest lattices
   * (hexagonal against FCC):
   *
   *   1 - eps = (pi / (3 sqrt 2)) ((1 - phi) / (pi / (2 sqrt 3)))^{3/2}
   *           = (2 / sqrt(pi sqrt 3)) (1 - phi)^{3/2},
   *
   * which takes random close packing onto random close packing (0.82-0.84
   * onto 0.64-0.66) and a dilute cloud of mean spacing s onto one of the
   * same spacing (doc/theory.md, "Dense 2D beds").
   */
  struct ClosurePorosity
  {
    bool sphere_packing = false;

    /** 2 / sqrt(pi sqrt 3): FCC over hexagonal packing to the power 3/2. */
    static constexpr double lattice_factor = 0.857382758104992;

    /** The closure's porosity for the fluid fraction @p phi. */
    double
    of(const double phi) const
    {
      if (!sphere_packing)
        return phi;
      const double solid = std::clamp(1 - phi, 0.0, 1.0);
      return 1 - lattice_factor * solid * std::sqrt(solid);
    }

    /** The fluid fraction whose closure porosity is @p eps (inverse of
     *  of()). */
    double
    fluid_fraction_of(const double eps) const
    {
      if (!sphere_packing)
        return eps;
      const double solid = std::clamp(1 - eps, 0.0, lattice_factor);
      return 1 - std::cbrt(std::pow(solid / lattice_factor, 2));
    }
  };
} // namespace ImmersedGrains

#endif
