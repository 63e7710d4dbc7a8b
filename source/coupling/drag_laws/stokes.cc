// Stokes drag of an isolated sphere, D = 3 pi mu d w = 6 mu (A / r) w
// (the same expression per unit depth for discs), with no fluid-fraction
// correction: the cheap law for dilute Stokes-regime scenes and tests.
#include <immersed_grains/coupling/drag_law.h>

namespace ImmersedGrains
{
  class Stokes : public DragLaw
  {
  public:
    double
    coefficient(const DragInput &in) const override
    {
      return 6 * in.viscosity * in.area / in.radius;
    }
  };
} // namespace ImmersedGrains

IMMERSED_GRAINS_REGISTER_DRAG_LAW(Stokes,
                                  "Stokes",
                                  "isolated-sphere Stokes drag 3 pi mu d w")
