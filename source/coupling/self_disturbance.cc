#include <immersed_grains/coupling/self_disturbance.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>

namespace ImmersedGrains
{
  namespace
  {
    // K mu h of the cell spread and, against l/h, of the Q1 hat with the
    // Helmholtz filter (3D, benchmarks/self_disturbance/kernel_integrals.py).
    constexpr double cell_constant_3d = 0.09984;
    constexpr std::array<std::pair<double, double>, 8> filtered_constants_3d{
      {{0.0, 0.07162},
       {0.125, 0.06638},
       {0.25, 0.05647},
       {0.5, 0.04015},
       {1.0, 0.02394},
       {2.0, 0.01282},
       {4.0, 0.00654},
       {8.0, 0.00328}}};

    double
    filtered_constant_3d(const double x)
    {
      const auto &table = filtered_constants_3d;
      if (x >= table.back().first)
        // The continuum Helmholtz kernel, 1 / (12 pi l/h), to 1 %.
        return table.back().second * table.back().first / x;
      for (unsigned int i = 1; i < table.size(); ++i)
        if (x <= table[i].first)
        {
          const auto [x0, c0] = table[i - 1];
          const auto [x1, c1] = table[i];
          return c0 + (c1 - c0) * (x - x0) / (x1 - x0);
        }
      return table.back().second;
    }

    // The 1D factor of the Q1 L2 projection's kernel at its own point, in
    // units of 1/h: sum_jk N_j N_k (M^-1)_jk on a uniform mesh, with the
    // infinite mesh's inverse mass matrix (diagonal g0, neighbours g1).
    double
    projection_factor_1d(const double xi, const bool lumped)
    {
      const double g0 = lumped ? 1.0 : std::sqrt(3.0);
      const double g1 = lumped ? 0.0 : -(2 - std::sqrt(3.0)) * std::sqrt(3.0);
      return ((1 - xi) * (1 - xi) + xi * xi) * g0 + 2 * xi * (1 - xi) * g1;
    }
  } // namespace


  template <int dim>
  SelfDisturbance<dim>::SelfDisturbance(const std::string &distribution,
                                        const double       smoothing_length,
                                        const bool         lumped)
      : kernel(distribution == "cell"     ? Kernel::cell :
               distribution == "filtered" ? Kernel::filtered :
                                            Kernel::none)
      , smoothing_length(smoothing_length)
      , lumped(lumped)
  {
  }


  template <int dim>
  double
  SelfDisturbance<dim>::mobility(const double h,
                                 const double phi,
                                 const double mu) const
  {
    if (dim != 3 || kernel == Kernel::none)
      return 0.0;
    const double c = kernel == Kernel::cell ?
                       cell_constant_3d :
                       filtered_constant_3d(smoothing_length / h);
    return c / (phi * mu * h);
  }


  template <int dim>
  double
  SelfDisturbance<dim>::structure_factor(const double s)
  {
    const double solid = std::clamp(s, 0.0, 1.0);
    return dim == 3 ? std::pow(1 - solid, 4) / std::pow(1 + 2 * solid, 2) :
                      std::pow(1 - solid, 3) / (1 + solid);
  }


  template <int dim>
  double
  SelfDisturbance<dim>::build_up_time(const double h,
                                      const double kinematic_viscosity) const
  {
    double width_squared = 0;
    if (kernel == Kernel::cell)
      width_squared = 0.60 * h * h;
    else if (kernel == Kernel::filtered)
      width_squared = 1.14 * h * h + 9.4 * smoothing_length * smoothing_length;
    return width_squared / kinematic_viscosity;
  }


  template <int dim>
  double
  SelfDisturbance<dim>::own_solid_fraction(const dealii::Point<dim> &reference,
                                           const double              h,
                                           const double volume) const
  {
    double nodal = 1;
    for (unsigned int d = 0; d < dim; ++d)
      nodal *= projection_factor_1d(reference[d], lumped) / h;
    if (smoothing_length <= 0)
      return volume * nodal;
    // The felt field is filtered twice: its kernel at zero is 1/(8 pi l^3)
    // (3D) or 1/(4 pi l^2) (2D) once l exceeds the cell; the widths of the
    // nodal and the filter kernels add in quadrature.
    const double filter_width = dim == 3 ?
                                  std::cbrt(8 * M_PI) * smoothing_length :
                                  std::sqrt(4 * M_PI) * smoothing_length;
    const double nodal_width  = std::pow(nodal, -1.0 / dim);
    return volume /
           std::pow(nodal_width * nodal_width + filter_width * filter_width,
                    0.5 * dim);
  }


  template class SelfDisturbance<2>;
  template class SelfDisturbance<3>;
} // namespace ImmersedGrains
