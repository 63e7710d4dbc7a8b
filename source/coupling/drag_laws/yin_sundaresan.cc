// Yin & Sundaresan (AIChE J. 55, 2009): the drag on a grain of diameter d_i
// among grains of other sizes, from lattice-Boltzmann simulations of
// polydisperse random arrays. Normalised like Beetstra's law, by the Stokes
// drag 3 pi mu d_i phi w of the superficial slip:
//   F_i = 1/phi + (F(phi, Re) - 1/phi) (a y_i + (1 - a) y_i^2),
//   a   = 1 - 2.66 s + 9.096 s^2 - 11.338 s^3,   s = 1 - phi,
// y_i = d_i / <d> with <d> the Sauter mean diameter around the grain,
// F the monodisperse law of Beetstra et al. (2007) at
// Re = phi rho <d> |w| / mu. With one size (y_i = 1) it is Beetstra's law;
// in the dilute limit (F -> 1/phi -> 1) every grain has its Stokes drag.
// A larger grain than the mean feels more of the hindrance and a smaller
// one less. The coupling supplies <d> (DragInput::mean_diameter).
#include <immersed_grains/coupling/beetstra_drag.h>
#include <immersed_grains/coupling/drag_law.h>

namespace ImmersedGrains
{
  class YinSundaresan : public DragLaw
  {
  public:
    double
    coefficient(const DragInput &in) const override
    {
      const double phi = in.fluid_fraction, s = 1 - phi;
      const double d      = 2 * in.radius;
      const double mean_d = in.mean_diameter > 0 ? in.mean_diameter : d;
      const double y      = d / mean_d;
      const double re =
        phi * in.density * mean_d * in.slip_speed / in.viscosity;
      const double a    = 1 - 2.66 * s + 9.096 * s * s - 11.338 * s * s * s;
      const double open = 1 / phi;
      const double f    = y == 1 ?
                            beetstra_normalised_drag(phi, re) :
                            open + (beetstra_normalised_drag(phi, re) - open) *
                                  (a * y + (1 - a) * y * y);
      // 3 pi mu d_i = 6 mu A / r in 3D; the same expression per unit depth
      // in 2D.
      return 6 * in.viscosity * in.area / in.radius * phi * f;
    }

    bool
    needs_mean_diameter() const override
    {
      return true;
    }
  };
} // namespace ImmersedGrains

IMMERSED_GRAINS_REGISTER_DRAG_LAW(
  YinSundaresan,
  "Yin-Sundaresan",
  "Yin & Sundaresan (2009): Beetstra's law corrected for each grain's "
  "diameter against the Sauter mean diameter around it (grains of several "
  "sizes)")
