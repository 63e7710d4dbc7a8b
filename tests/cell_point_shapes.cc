// CellPointShapes evaluates a scalar element's shape functions at arbitrary
// reference points of a cell, as the grains' coupling does at each grain.
// For the tensor-product elements it evaluates the 1D polynomials itself;
// its values must equal dealii::TensorProductPolynomials::evaluate() to the
// last bit (the products in the same order), so that the simulations'
// results do not depend on which path evaluated them: the window is zero.
// The real-space gradients go through the d-linear map's Jacobian; they are
// compared with FEValues (MappingQ1) on a distorted cell, where the two
// compute the same quantity by different sums: within 1e-12 of the largest
// gradient. Each element is asked for values first, then gradients at the
// same points, then values at new points, as the coupling asks.
#include <deal.II/base/quadrature.h>
#include <deal.II/base/tensor_product_polynomials.h>
#include <deal.II/fe/fe_dgq.h>
#include <deal.II/fe/fe_poly.h>
#include <deal.II/fe/fe_q.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/fe/mapping_q1.h>
#include <deal.II/grid/grid_generator.h>
#include <deal.II/grid/tria.h>

#include <immersed_grains/mesh/cell_point_shapes.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

using namespace dealii;
using namespace ImmersedGrains;

namespace
{
  // Reproducible pseudo-random numbers in (0, 1).
  double
  next_random(unsigned long &state)
  {
    state = state * 6364136223846793005UL + 1442695040888963407UL;
    return ((state >> 11) + 0.5) / 9007199254740992.0;
  }

  template <int dim>
  std::vector<Point<dim>>
  random_points(const unsigned int n, unsigned long &state)
  {
    std::vector<Point<dim>> points(n);
    for (auto &p : points)
      for (unsigned int d = 0; d < dim; ++d)
        p[d] = next_random(state);
    return points;
  }

  template <int dim>
  void
  check(const FiniteElement<dim> &fe, const std::string &name)
  {
    Triangulation<dim> triangulation;
    GridGenerator::hyper_cube(triangulation, 0.0, 1.0);
    // A distorted cell: every vertex moved, so the map is not affine.
    unsigned long state = 17;
    for (const unsigned int v : GeometryInfo<dim>::vertex_indices())
      for (unsigned int d = 0; d < dim; ++d)
        triangulation.begin_active()->vertex(v)[d] +=
          0.2 * (next_random(state) - 0.5);
    const auto cell = triangulation.begin_active();

    CellPointShapes<dim> shapes(fe);
    const auto &poly = dynamic_cast<const FE_Poly<dim> &>(fe).get_poly_space();
    const unsigned int n = fe.n_dofs_per_cell();

    unsigned int n_points = 0, value_differences = 0;
    double       gradient_error = 0, largest_gradient = 0;
    for (unsigned int round = 0; round < 3; ++round)
    {
      const auto points = random_points<dim>(20, state);
      n_points += points.size();
      // TensorProductPolynomials' values at the points.
      std::vector<std::vector<double>> expected(points.size(),
                                                std::vector<double>(n));
      std::vector<Tensor<1, dim>>      no_1;
      std::vector<Tensor<2, dim>>      no_2;
      std::vector<Tensor<3, dim>>      no_3;
      std::vector<Tensor<4, dim>>      no_4;
      for (unsigned int q = 0; q < points.size(); ++q)
        poly.evaluate(points[q], expected[q], no_1, no_2, no_3, no_4);
      const auto count_value_differences = [&]()
      {
        for (unsigned int q = 0; q < points.size(); ++q)
          for (unsigned int i = 0; i < n; ++i)
            value_differences += shapes.value(i, q) != expected[q][i];
      };
      // Values alone, then with gradients at the same points.
      shapes.reinit(cell, points, false);
      count_value_differences();
      shapes.reinit(cell, points, true);
      count_value_differences();
      const MappingQ1<dim> mapping;
      FEValues<dim>        fe_values(mapping,
                              fe,
                              Quadrature<dim>(points),
                              update_gradients);
      fe_values.reinit(cell);
      for (unsigned int q = 0; q < points.size(); ++q)
        for (unsigned int i = 0; i < n; ++i)
        {
          gradient_error = std::max(
            gradient_error,
            (shapes.gradient(i, q) - fe_values.shape_grad(i, q)).norm());
          largest_gradient =
            std::max(largest_gradient, fe_values.shape_grad(i, q).norm());
        }
    }
    std::printf("%s: %u points, values equal to TensorProductPolynomials bit "
                "for bit: %s; gradients within 1e-12 of FEValues on a "
                "distorted cell: %s\n",
                name.c_str(),
                n_points,
                value_differences == 0 ? "yes" : "NO",
                gradient_error <= 1e-12 * largest_gradient ? "yes" : "NO");
  }
} // namespace


int
main()
{
  check(FE_Q<2>(1), "FE_Q<2>(1)");
  check(FE_Q<2>(2), "FE_Q<2>(2)");
  check(FE_DGQ<2>(2), "FE_DGQ<2>(2)");
  check(FE_Q<3>(1), "FE_Q<3>(1)");
  check(FE_Q<3>(2), "FE_Q<3>(2)");
  check(FE_DGQ<3>(3), "FE_DGQ<3>(3)");
}
