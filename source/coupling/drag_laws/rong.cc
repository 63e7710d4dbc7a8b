// Rong, Dong & Yu (Chem. Eng. Sci. 99, 2013): Di Felice's form with
//   chi = 2.65 (phi + 1) - (5.3 - 3.5 phi) phi^2 exp(-(1.5 - log10 Re)^2 / 2),
// fitted to lattice-Boltzmann data for 0.4 < phi < 0.9.
#include <immersed_grains/coupling/drag_law.h>

#include <cmath>

namespace ImmersedGrains
{
  class Rong : public DragLaw
  {
  public:
    double
    coefficient(const DragInput &in) const override
    {
      const double phi = in.fluid_fraction;
      const double re  = reynolds(in);
      const double bump =
        re > 0 ? std::exp(-0.5 * std::pow(1.5 - std::log10(re), 2)) : 0.0;
      const double chi =
        2.65 * (phi + 1) - (5.3 - 3.5 * phi) * phi * phi * bump;
      const double root =
        0.63 * std::sqrt(in.slip_speed) +
        4.8 * std::sqrt(in.viscosity / (2 * in.radius * in.density * phi));
      return 0.5 * in.area * in.density * root * root * std::pow(phi, 2 - chi);
    }
  };
} // namespace ImmersedGrains

IMMERSED_GRAINS_REGISTER_DRAG_LAW(Rong,
                                  "Rong",
                                  "Rong, Dong & Yu (2013) voidage exponent")
