#include <deal.II/base/geometry_info.h>
#include <deal.II/fe/fe_poly.h>

#include <immersed_grains/mesh/cell_point_shapes.h>

#include <cmath>

namespace ImmersedGrains
{
  template <int dim>
  CellPointShapes<dim>::CellPointShapes(
    const dealii::FiniteElement<dim> &scalar_fe)
      : fe(scalar_fe)
      , n_dofs(scalar_fe.n_dofs_per_cell())
  {
    Assert(scalar_fe.n_components() == 1, dealii::ExcNotImplemented());
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
      reference_gradients.resize(points.size() * n_dofs);
      // A polynomial element evaluates all its functions at once (each 1D
      // polynomial once); shape_value() per function repeats that work
      // n_dofs times, which showed in the grains' interaction force.
      const auto *polynomial_fe =
        dynamic_cast<const dealii::FE_Poly<dim> *>(&fe);
      std::vector<double>                 point_values(n_dofs);
      std::vector<dealii::Tensor<1, dim>> point_gradients(n_dofs);
      std::vector<dealii::Tensor<2, dim>> no_second;
      std::vector<dealii::Tensor<3, dim>> no_third;
      std::vector<dealii::Tensor<4, dim>> no_fourth;
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
            point_values[i]    = fe.shape_value(i, points[q]);
            point_gradients[i] = fe.shape_grad(i, points[q]);
          }
        for (unsigned int i = 0; i < n_dofs; ++i)
        {
          values[q * n_dofs + i]              = point_values[i];
          reference_gradients[q * n_dofs + i] = point_gradients[i];
        }
      }
    }
    if (!with_gradients)
      return;
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
        const dealii::Point<dim> &x = cell->vertex(v);
        for (unsigned int i = 0; i < dim; ++i)
          for (unsigned int j = 0; j < dim; ++j)
            jacobian[i][j] += x[i] * shape[j];
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
