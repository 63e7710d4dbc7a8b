// The seed's closure (Constant et al. 2019): Dallavalle's drag coefficient
// C_d = (0.63 + 4.8 Re^{-1/2})^2 with the Wen & Yu voidage function
// f(phi) = phi^{-1.8}:
//   D = f(phi) C_d(Re) (A rho / 2) |w| w,   Re = 2 r rho |w| phi / mu.
// Written as C_d |w| = (0.63 sqrt|w| + 4.8 sqrt(mu / (2 r rho phi)))^2 so that
// Re -> 0 is exact: gamma -> 0.96 * 6 pi mu r phi^{-2.8} (3D).
#include <immersed_grains/coupling/drag_law.h>

#include <cmath>

namespace ImmersedGrains
{
  class DallavalleWenYu : public DragLaw
  {
  public:
    double
    coefficient(const DragInput &in) const override
    {
      const double phi = in.fluid_fraction;
      const double root =
        0.63 * std::sqrt(in.slip_speed) +
        4.8 * std::sqrt(in.viscosity / (2 * in.radius * in.density * phi));
      return std::pow(phi, -1.8) * 0.5 * in.area * in.density * root * root;
    }
  };
} // namespace ImmersedGrains

IMMERSED_GRAINS_REGISTER_DRAG_LAW(
  DallavalleWenYu,
  "Dallavalle-Wen-Yu",
  "the seed's law: phi^-1.8 (0.63 + 4.8 Re^-1/2)^2 (A rho/2) |w| w")
