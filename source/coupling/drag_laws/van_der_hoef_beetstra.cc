// van der Hoef, Beetstra & Kuipers (J. Fluid Mech. 528, 2005) and Beetstra,
// van der Hoef & Kuipers (AIChE J. 53, 2007): the drag on a grain of
// diameter d_i in a random array of several sizes, from lattice-Boltzmann
// simulations of bidisperse arrays. They fit the total force on the grain
// (drag plus its share of the mean pressure gradient), normalised by the
// Stokes drag 3 pi mu d_i phi w of the superficial slip, as
//   F_i^total = (phi y_i + s y_i^2) F(phi, Re) / phi,   s = 1 - phi,
// y_i = d_i / <d> with <d> the Sauter mean diameter, F Beetstra's
// monodisperse law. The fluid here carries the mean pressure gradient
// separately (each grain feels -V_i grad p besides its drag), and in a
// steady array grad p is the sum of the total forces per volume; with the
// Sauter mean that sum is exactly the one-size array's, so the drag that
// remains is
//   F_i = y_i F(phi, Re),   Re = phi rho <d> |w| / mu,
// gamma_i = 3 pi mu d_i phi y_i F. The authors' third term,
// 0.064 phi y_i^3, is left out, as in Beetstra et al.'s correction of the
// form for this split (with it, one size would not give Beetstra's law).
// Unlike Yin & Sundaresan's form, it keeps the factor y_i in the dilute
// limit (a small grain among large ones then has less than its Stokes
// drag); the lattice data cover solid fractions 0.1-0.6.
#include <immersed_grains/coupling/beetstra_drag.h>
#include <immersed_grains/coupling/drag_law.h>

namespace ImmersedGrains
{
  class VanDerHoefBeetstra : public DragLaw
  {
  public:
    double
    coefficient(const DragInput &in) const override
    {
      const double phi    = in.fluid_fraction;
      const double d      = 2 * in.radius;
      const double mean_d = in.mean_diameter > 0 ? in.mean_diameter : d;
      const double y      = d / mean_d;
      const double re =
        phi * in.density * mean_d * in.slip_speed / in.viscosity;
      // 3 pi mu d_i = 6 mu A / r in 3D; the same expression per unit depth
      // in 2D.
      return 6 * in.viscosity * in.area / in.radius * phi * y *
             beetstra_normalised_drag(phi, re);
    }

    bool
    needs_mean_diameter() const override
    {
      return true;
    }
  };
} // namespace ImmersedGrains

IMMERSED_GRAINS_REGISTER_DRAG_LAW(
  VanDerHoefBeetstra,
  "van der Hoef-Beetstra",
  "van der Hoef et al. (2005) and Beetstra et al. (2007): Beetstra's law "
  "times each grain's diameter over the Sauter mean diameter around it "
  "(grains of several sizes, solid fractions 0.1-0.6)")
