#ifndef immersed_grains_coupling_beetstra_drag_h
#define immersed_grains_coupling_beetstra_drag_h

namespace ImmersedGrains
{
  /**
   * Beetstra, van der Hoef & Kuipers' (2007) drag on a sphere in a random
   * monodisperse array, normalised by the Stokes drag 3 pi mu d phi w of
   * the superficial slip, at fluid fraction @p phi and Reynolds number
   * @p reynolds = phi rho d |w| / mu. The Beetstra law returns it for the
   * grain's own diameter; the polydisperse laws correct it for the sizes
   * around (source/coupling/drag_laws/beetstra.cc).
   */
  double
  beetstra_normalised_drag(double phi, double reynolds);
} // namespace ImmersedGrains

#endif
