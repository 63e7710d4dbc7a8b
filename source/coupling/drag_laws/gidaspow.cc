// Gidaspow (Multiphase Flow and Fluidization, 1994): Wen & Yu above
// phi = 0.8, Ergun below. Per unit mixture volume
//   Wen-Yu: beta = 3/4 C_d rho phi (1 - phi) |w| / d phi^{-2.65},
//           C_d = 24/Re (1 + 0.15 Re^0.687) (Re < 1000), 0.44 above,
//           Re = phi rho d |w| / mu;
//   Ergun:  beta = 150 (1 - phi)^2 mu / (phi d^2) + 1.75 (1 - phi) rho |w| / d;
// per grain gamma = beta V / (1 - phi). C_d |w| is formed without dividing
// by Re, so Re -> 0 is exact.
#include <immersed_grains/coupling/drag_law.h>

#include <cmath>

namespace ImmersedGrains
{
  class Gidaspow : public DragLaw
  {
  public:
    double
    coefficient(const DragInput &in) const override
    {
      const double phi = in.fluid_fraction, d = 2 * in.radius;
      if (phi > 0.8)
      {
        const double re   = phi * in.density * d * in.slip_speed / in.viscosity;
        const double cd_w = re < 1000 ?
                              24 * in.viscosity / (phi * in.density * d) *
                                (1 + 0.15 * std::pow(re, 0.687)) :
                              0.44 * in.slip_speed;
        return 0.75 * cd_w * in.density * phi / d * std::pow(phi, -2.65) *
               in.volume;
      }
      return (150 * (1 - phi) * in.viscosity / (phi * d * d) +
              1.75 * in.density * in.slip_speed / d) *
             in.volume;
    }
  };
} // namespace ImmersedGrains

IMMERSED_GRAINS_REGISTER_DRAG_LAW(Gidaspow,
                                  "Gidaspow",
                                  "Wen-Yu above phi = 0.8, Ergun below (1994)")
