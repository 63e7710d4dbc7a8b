// Every registered drag law: the coefficient gamma (drag = gamma w) relative
// to isolated-sphere Stokes drag 6 pi mu r, at Re = 0 exactly (no Reynolds
// floor: the seed's scene runs at Re ~ 1e-6) and at Re = 10, over fluid
// fractions 1 .. 0.4. Checked limits: at phi = 1 and Re = 0 the Dallavalle-
// based laws give 0.96 (C_d -> 23.04/Re), the others 1; every value finite
// and positive; gamma grows with the slip speed. The code checks the last
// three; the table, limits included, is held by the .output at 4 digits.
// Its entries follow in closed form from each law's published formula
// (doc/references.md, "Other drag laws"), e.g. 0.96 phi^-2.8 at Re = 0 for
// Dallavalle-Wen-Yu (1.7932 at phi = 0.8), C_d Re/24 = 1.9223 for it at
// phi = 1 and Re = 10, and 150 (1 - phi)/(18 phi) for Gidaspow's Ergun
// branch at phi <= 0.8 (5.5556 at 0.6).
// Yin-Sundaresan, the polydisperse law, is then tabulated against the
// grain's diameter over the Sauter mean around it, y = d / <d> (0.5, 1, 2)
// at Re = 0: phi F with F = 1/phi + (F_B - 1/phi)(c y + (1 - c) y^2),
// e.g. 17.245 at phi = 0.6 and y = 2 (F_B = 11.8126, c = 0.665728).
// Checked: y = 1 gives Beetstra's law to 1e-14 and phi = 1 the Stokes drag
// whatever y, the two limits its authors built in; at phi < 1 gamma grows
// faster than d (the normalised drag grows with y).
// van der Hoef-Beetstra, the other polydisperse law, likewise: y times
// Beetstra's law, checked to 1e-14 (e.g. 14.175 at phi = 0.6 and y = 2).
#include <immersed_grains/coupling/drag_law.h>

#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>

using namespace ImmersedGrains;

int
main()
{
  const double r = 12.5e-6, rho = 1200, mu = 0.12;
  DragInput in{r, M_PI * r * r, 4.0 / 3 * M_PI * r * r * r, 1.0, 0.0, rho, mu};
  const double stokes = 6 * M_PI * mu * r;

  std::istringstream names(DragLaw::names());
  unsigned int       failures = 0;
  std::printf("law                phi  gamma/6pi.mu.r at Re=0   at Re=10\n");
  for (std::string name; std::getline(names, name, '|');)
  {
    const auto law = DragLaw::create(name);
    for (const double phi : {1.0, 0.8, 0.6, 0.4})
    {
      in.fluid_fraction = phi;
      in.slip_speed     = 0;
      const double g0   = law->coefficient(in) / stokes;
      in.slip_speed     = 10 * mu / (2 * r * rho * phi); // Re = 10
      const double g10  = law->coefficient(in) / stokes;
      std::printf(
        "%-18s %.1f  %10.4f            %10.4f\n", name.c_str(), phi, g0, g10);
      if (!(std::isfinite(g0) && g0 > 0 && std::isfinite(g10) &&
            g10 >= g0 * (1 - 1e-12)))
        ++failures;
    }
  }

  // The polydisperse law against the diameter ratio y = d / <d>.
  const auto beetstra = DragLaw::create("Beetstra");
  const auto yin      = DragLaw::create("Yin-Sundaresan");
  std::printf("Yin-Sundaresan     phi  gamma/6pi.mu.r at Re=0 for y = 0.5, 1, "
              "2\n");
  in.slip_speed = 0;
  for (const double phi : {1.0, 0.8, 0.6, 0.4})
  {
    in.fluid_fraction = phi;
    double last       = 0;
    std::printf("                   %.1f ", phi);
    for (const double y : {0.5, 1.0, 2.0})
    {
      in.mean_diameter     = 2 * r / y;
      const double g       = yin->coefficient(in) / stokes;
      const double mono    = beetstra->coefficient(in) / stokes;
      const bool   correct = phi == 1 ?
                               std::abs(g - 1) < 1e-12 :
                               (y == 0.5 || g > last) &&
                               (y != 1 || std::abs(g - mono) <= 1e-14 * mono);
      if (!correct)
        ++failures;
      std::printf(" %10.4f", g);
      last = g;
    }
    std::printf("\n");
  }
  // van der Hoef-Beetstra: Beetstra's law times y, exactly (the factor is
  // the law; at phi = 1 too, where it keeps y and Yin-Sundaresan does not).
  const auto hoef = DragLaw::create("van der Hoef-Beetstra");
  std::printf("van der Hoef-B.    phi  gamma/6pi.mu.r at Re=0 for y = 0.5, 1, "
              "2\n");
  for (const double phi : {1.0, 0.8, 0.6, 0.4})
  {
    in.fluid_fraction = phi;
    std::printf("                   %.1f ", phi);
    for (const double y : {0.5, 1.0, 2.0})
    {
      in.mean_diameter  = 2 * r / y;
      const double g    = hoef->coefficient(in) / stokes;
      const double mono = beetstra->coefficient(in) / stokes;
      if (!(std::abs(g - y * mono) <= 1e-14 * y * mono))
        ++failures;
      std::printf(" %10.4f", g);
    }
    std::printf("\n");
  }
  in.mean_diameter = 0;
  std::printf("%u failures\n", failures);
  return failures == 0 ? 0 : 1;
}
