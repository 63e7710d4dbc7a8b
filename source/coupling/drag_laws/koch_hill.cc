// Koch & Hill (Annu. Rev. Fluid Mech. 33, 2001), force normalised by the
// Stokes drag 3 pi mu d phi w of the superficial slip: F = F0 + F3 Re / 2,
//   F0 = (1 + 3 sqrt(s/2) + 135/64 s ln s + 16.14 s)
//        / (1 + 0.681 s - 8.48 s^2 + 8.16 s^3)            (s < 0.4),
//   F0 = 10 s / phi^3                                      (s >= 0.4),
//   F3 = 0.0673 + 0.212 s + 0.0232 / phi^5,
// s = 1 - phi, Re = phi rho d |w| / mu.
#include <immersed_grains/coupling/drag_law.h>

#include <cmath>

namespace ImmersedGrains
{
  class KochHill : public DragLaw
  {
  public:
    double
    coefficient(const DragInput &in) const override
    {
      const double phi = in.fluid_fraction, s = 1 - phi;
      const double re =
        phi * in.density * 2 * in.radius * in.slip_speed / in.viscosity;
      const double s_ln_s = s > 0 ? s * std::log(s) : 0.0;
      const double f0 =
        s < 0.4 ? (1 + 3 * std::sqrt(s / 2) + 135.0 / 64 * s_ln_s + 16.14 * s) /
                    (1 + 0.681 * s - 8.48 * s * s + 8.16 * s * s * s) :
                  10 * s / (phi * phi * phi);
      const double f3 = 0.0673 + 0.212 * s + 0.0232 / std::pow(phi, 5);
      return 6 * in.viscosity * in.area / in.radius * phi *
             (f0 + 0.5 * f3 * re);
    }
  };
} // namespace ImmersedGrains

IMMERSED_GRAINS_REGISTER_DRAG_LAW(KochHill,
                                  "Koch-Hill",
                                  "Koch & Hill (2001) lattice-Boltzmann fit")
