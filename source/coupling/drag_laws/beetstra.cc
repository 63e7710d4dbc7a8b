// Beetstra, van der Hoef & Kuipers (AIChE J. 53, 2007), lattice-Boltzmann
// fit for monodisperse arrays, force normalised by the Stokes drag
// 3 pi mu d phi w of the superficial slip:
//   F = 10 s / phi^2 + phi^2 (1 + 1.5 sqrt(s))
//     + 0.413 Re / (24 phi^2) (1/phi + 3 s phi + 8.4 Re^-0.343)
//                             / (1 + 10^{3 s} Re^{-(1 + 4 s)/2}),
// s = 1 - phi, Re = phi rho d |w| / mu. The last term is rewritten with
// Re^{(1+4s)/2} multiplied through so that Re -> 0 is finite.
#include <immersed_grains/coupling/beetstra_drag.h>
#include <immersed_grains/coupling/drag_law.h>

#include <cmath>

namespace ImmersedGrains
{
  double
  beetstra_normalised_drag(const double phi, const double re)
  {
    const double s = 1 - phi;
    const double p = 0.5 * (1 + 4 * s);
    const double a = 1 / phi + 3 * s * phi;
    const double inertial =
      0.413 / (24 * phi * phi) *
      (a * std::pow(re, 1 + p) + 8.4 * std::pow(re, 0.657 + p)) /
      (std::pow(re, p) + std::pow(10.0, 3 * s));
    return 10 * s / (phi * phi) + phi * phi * (1 + 1.5 * std::sqrt(s)) +
           inertial;
  }


  class Beetstra : public DragLaw
  {
  public:
    double
    coefficient(const DragInput &in) const override
    {
      const double phi = in.fluid_fraction;
      const double re =
        phi * in.density * 2 * in.radius * in.slip_speed / in.viscosity;
      // 3 pi mu d = 6 mu A / r in 3D; the same expression per unit depth in 2D.
      return 6 * in.viscosity * in.area / in.radius * phi *
             beetstra_normalised_drag(phi, re);
    }
  };
} // namespace ImmersedGrains

IMMERSED_GRAINS_REGISTER_DRAG_LAW(Beetstra,
                                  "Beetstra",
                                  "Beetstra, van der Hoef & Kuipers (2007)")
