#ifndef immersed_grains_grains_periodic_span_h
#define immersed_grains_grains_periodic_span_h

#include <deal.II/base/point.h>

#include <immersed_grains/mesh/geometry.h>

#include <cmath>
#include <vector>

namespace ImmersedGrains
{
  /**
   * Whether a box of grains centred at @p center with edges @p size spans
   * the periodic axis @p d of a box domain: a suspension placed in it is
   * homogeneous across that axis's periodic faces. Spanning within 1e-4 of
   * the period counts (a centre and a size written with six digits differ
   * from the corners by a few 1e-6 of them).
   */
  template <int dim>
  bool
  spans_periodic_axis(const Geometry<dim>       &geometry,
                      const dealii::Point<dim>  &center,
                      const std::vector<double> &size,
                      const unsigned int         d)
  {
    const double L   = geometry.upper_corner[d] - geometry.lower_corner[d];
    const double tol = 1e-4 * L;
    return geometry.is_box() && geometry.is_periodic(d) &&
           std::abs(center[d] - size[d] / 2 - geometry.lower_corner[d]) <=
             tol &&
           std::abs(center[d] + size[d] / 2 - geometry.upper_corner[d]) <= tol;
  }
} // namespace ImmersedGrains

#endif
