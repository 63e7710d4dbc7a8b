#include <deal.II/base/geometry_info.h>
#include <deal.II/base/tensor_product_polynomials.h>
#include <deal.II/fe/fe_poly.h>

#include <immersed_grains/mesh/cell_point_shapes.h>

#include <array>
#include <cmath>

namespace ImmersedGrains
{
  template <int dim>
  CellPointShapes<dim>::CellPointShapes(
    const dealii::FiniteElement<dim> &scalar_fe)
      : fe(scalar_fe)
      , polynomial_fe(
          dynamic_cast<const dealii::FE_Poly<dim, dim> *>(&scalar_fe))
      , n_dofs(scalar_fe.n_dofs_per_cell())
  {
    Assert(scalar_fe.n_components() == 1, dealii::ExcNotImplemented());
    // The tensor-product elements (FE_Q, FE_DGQ) evaluated here.
    if (polynomial_fe != nullptr)
      if (const auto *tensor_product =
            dynamic_cast<const dealii::TensorProductPolynomials<dim> *>(
              &polynomial_fe->get_poly_space()))
      {
        polynomials_1d    = tensor_product->get_underlying_polynomials();
        numbering_inverse = tensor_product->get_numbering_inverse();
      }
  }


  template <int dim>
  void
  CellPointShapes<dim>::reinit(
    const typename dealii::Triangulation<dim>::cell_iterator &cell,
    const std::vector<dealii::Point<dim>>                    &reference_points,
    const bool                                                with_gradients)
  {
    if (reference_points != points)
    {
      points = reference_points;
      values.resize(points.size() * n_dofs);
      have_reference_gradients = false;
      evaluate_reference(with_gradients);
    }
    else if (with_gradients && !have_reference_gradients)
      evaluate_reference(true);
    if (!with_gradients)
      return;

    // The vertices once per cell: in 3D each look-up goes through the
    // cell's faces and lines, and grains share a cell by the tens.
    std::array<dealii::Point<dim>, dealii::GeometryInfo<dim>::vertices_per_cell>
      vertices;
    for (const unsigned int v : dealii::GeometryInfo<dim>::vertex_indices())
      vertices[v] = cell->vertex(v);
    gradients.resize(points.size() * n_dofs);
    determinants.resize(points.size());
    for (unsigned int q = 0; q < points.size(); ++q)
    {
      // J_ij = dx_i/dxi_j of the d-linear map through the cell's vertices.
      dealii::Tensor<2, dim> jacobian;
      for (const unsigned int v : dealii::GeometryInfo<dim>::vertex_indices())
      {
        const dealii::Tensor<1, dim> shape =
          dealii::GeometryInfo<dim>::d_linear_shape_function_gradient(points[q],
                                                                      v);
        for (unsigned int i = 0; i < dim; ++i)
          for (unsigned int j = 0; j < dim; ++j)
            jacobian[i][j] += vertices[v][i] * shape[j];
      }
      determinants[q]                      = std::abs(determinant(jacobian));
      const dealii::Tensor<2, dim> inverse = invert(jacobian);
      // grad_x N = J^{-T} grad_xi N.
      for (unsigned int i = 0; i < n_dofs; ++i)
        gradients[q * n_dofs + i] =
          reference_gradients[q * n_dofs + i] * inverse;
    }
  }


  template <int dim>
  void
  CellPointShapes<dim>::evaluate_reference(const bool with_gradients)
  {
    // The gradients only where asked: a Q2 function's cost three times its
    // value's, and the velocity at the grains needs none.
    if (with_gradients)
    {
      reference_gradients.resize(points.size() * n_dofs);
      have_reference_gradients = true;
    }
    if (!polynomials_1d.empty())
    {
      for (unsigned int q = 0; q < points.size(); ++q)
        evaluate_tensor_product(q, with_gradients);
      return;
    }
    point_values.resize(n_dofs);
    point_gradients.resize(with_gradients ? n_dofs : 0);
    for (unsigned int q = 0; q < points.size(); ++q)
    {
      if (polynomial_fe != nullptr)
        polynomial_fe->get_poly_space().evaluate(points[q],
                                                 point_values,
                                                 point_gradients,
                                                 no_second,
                                                 no_third,
                                                 no_fourth);
      else
        for (unsigned int i = 0; i < n_dofs; ++i)
        {
          point_values[i] = fe.shape_value(i, points[q]);
          if (with_gradients)
            point_gradients[i] = fe.shape_grad(i, points[q]);
        }
      for (unsigned int i = 0; i < n_dofs; ++i)
        values[q * n_dofs + i] = point_values[i];
      if (with_gradients)
        for (unsigned int i = 0; i < n_dofs; ++i)
          reference_gradients[q * n_dofs + i] = point_gradients[i];
    }
  }


  template <int dim>
  void
  CellPointShapes<dim>::evaluate_tensor_product(const unsigned int q,
                                                const bool with_gradients)
  {
    // Each 1D polynomial once per coordinate, then the products, in the
    // order of deal.II's TensorProductPolynomials::evaluate() (9.4: the
    // factors from the first coordinate on), so that the values and
    // gradients are the same to the last bit (tests/cell_point_shapes);
    // without its per-call set-up, which cost as much as the products at a
    // Q1 element's eight functions.
    const unsigned int n           = polynomials_1d.size();
    const unsigned int derivatives = with_gradients ? 1 : 0;
    // one_d[(k * dim + d) * 2 + j]: the j-th derivative of polynomial k at
    // the point's coordinate d.
    one_d.resize(n * dim * 2);
    for (unsigned int k = 0; k < n; ++k)
      for (unsigned int d = 0; d < dim; ++d)
        polynomials_1d[k].value(points[q][d],
                                derivatives,
                                &one_d[(k * dim + d) * 2]);
    const auto f = [&](const unsigned int k, const unsigned int d)
    { return one_d[(k * dim + d) * 2]; };
    const auto df = [&](const unsigned int k, const unsigned int d)
    { return one_d[(k * dim + d) * 2 + 1]; };

    double *const                 out_values = &values[q * n_dofs];
    dealii::Tensor<1, dim> *const out_gradients =
      with_gradients ? &reference_gradients[q * n_dofs] : nullptr;
    const unsigned int n_z = dim == 3 ? n : 1;
    for (unsigned int iz = 0, lexicographic = 0; iz < n_z; ++iz)
      for (unsigned int iy = 0; iy < n; ++iy)
        for (unsigned int ix = 0; ix < n; ++ix, ++lexicographic)
        {
          const unsigned int i  = numbering_inverse[lexicographic];
          const double       xy = f(ix, 0) * f(iy, 1);
          if constexpr (dim == 2)
            out_values[i] = xy;
          else
            out_values[i] = xy * f(iz, 2);
          if (!with_gradients)
            continue;
          const double dx_y = df(ix, 0) * f(iy, 1);
          const double x_dy = f(ix, 0) * df(iy, 1);
          if constexpr (dim == 2)
          {
            out_gradients[i][0] = dx_y;
            out_gradients[i][1] = x_dy;
          }
          else
          {
            out_gradients[i][0]       = dx_y * f(iz, 2);
            out_gradients[i][1]       = x_dy * f(iz, 2);
            out_gradients[i][dim - 1] = xy * df(iz, 2);
          }
        }
  }


  template <int dim>
  double
  CellPointShapes<dim>::value_of(const std::vector<double> &coefficients,
                                 const unsigned int         q) const
  {
    double sum = 0;
    for (unsigned int i = 0; i < n_dofs; ++i)
      sum += coefficients[i] * values[q * n_dofs + i];
    return sum;
  }


  template <int dim>
  dealii::Tensor<1, dim>
  CellPointShapes<dim>::gradient_of(const std::vector<double> &coefficients,
                                    const unsigned int         q) const
  {
    dealii::Tensor<1, dim> sum;
    for (unsigned int i = 0; i < n_dofs; ++i)
      sum += coefficients[i] * gradients[q * n_dofs + i];
    return sum;
  }


  template class CellPointShapes<2>;
  template class CellPointShapes<3>;
} // namespace ImmersedGrains
