// Di Felice (Int. J. Multiphase Flow 20, 1994):
//   D = C_d(Re) (A rho / 2) phi^2 |w| w phi^{-chi},
//   chi = 3.7 - 0.65 exp(-(1.5 - log10 Re)^2 / 2),
// Dallavalle C_d, Re = 2 r rho |w| phi / mu. At Re -> 0, chi -> 3.7 and the
// exponential underflows to 0 without special cases.
#include <immersed_grains/coupling/drag_law.h>

#include <cmath>

namespace ImmersedGrains
{
  class DiFelice : public DragLaw
  {
  public:
    double
    coefficient(const DragInput &in) const override
    {
      const double phi = in.fluid_fraction;
      const double re  = reynolds(in);
      const double chi =
        re > 0 ?
          3.7 - 0.65 * std::exp(-0.5 * std::pow(1.5 - std::log10(re), 2)) :
          3.7;
      const double root =
        0.63 * std::sqrt(in.slip_speed) +
        4.8 * std::sqrt(in.viscosity / (2 * in.radius * in.density * phi));
      return 0.5 * in.area * in.density * root * root * std::pow(phi, 2 - chi);
    }
  };
} // namespace ImmersedGrains

IMMERSED_GRAINS_REGISTER_DRAG_LAW(DiFelice,
                                  "Di Felice",
                                  "Di Felice (1994) voidage exponent chi(Re)")
