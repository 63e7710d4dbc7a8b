#ifndef immersed_grains_mesh_cell_point_shapes_h
#define immersed_grains_mesh_cell_point_shapes_h

#include <deal.II/base/point.h>
#include <deal.II/base/polynomial.h>
#include <deal.II/base/tensor.h>
#include <deal.II/fe/fe.h>
#include <deal.II/grid/tria.h>

#include <vector>

namespace dealii
{
  template <int dim, int spacedim>
  class FE_Poly;
}

namespace ImmersedGrains
{
  /**
   * Values and real-space gradients of a scalar finite element's shape
   * functions at given reference points of a cell under the d-linear
   * map (exact on the axis-parallel cells of a box mesh). The same point set
   * comes back at every cell of an assembly (its quadrature points), so the
   * reference values and gradients are kept until the points change, and a cell
   * costs only its Jacobians. This replaces a dealii::FEPointEvaluation built
   * per cell, whose set-up (tensor-product shape data) cost more than the
   * evaluation itself (doc/performance.md, "Shape functions at the grains").
   */
  template <int dim>
  class CellPointShapes
  {
  public:
    explicit CellPointShapes(const dealii::FiniteElement<dim> &scalar_fe);

    /** Evaluates at @p reference_points of @p cell; gradients only if
     * @p with_gradients. */
    void
    reinit(const typename dealii::Triangulation<dim>::cell_iterator &cell,
           const std::vector<dealii::Point<dim>> &reference_points,
           bool                                   with_gradients);

    unsigned int
    n_points() const
    {
      return points.size();
    }

    double
    value(const unsigned int i, const unsigned int q) const
    {
      return values[q * n_dofs + i];
    }

    const dealii::Tensor<1, dim> &
    gradient(const unsigned int i, const unsigned int q) const
    {
      return gradients[q * n_dofs + i];
    }

    /** |det J| at point q (volume element of the map). */
    double
    jacobian_determinant(const unsigned int q) const
    {
      return determinants[q];
    }

    /** sum_i coefficients[i] N_i(x_q). */
    double
    value_of(const std::vector<double> &coefficients,
             const unsigned int         q) const;

    /** sum_i coefficients[i] grad N_i(x_q). */
    dealii::Tensor<1, dim>
    gradient_of(const std::vector<double> &coefficients,
                const unsigned int         q) const;

  private:
    /** Values (and gradients if @p with_gradients) at the reference points. */
    void
    evaluate_reference(bool with_gradients);

    /** The same at point @p q for a tensor-product element. */
    void
    evaluate_tensor_product(unsigned int q, bool with_gradients);

    const dealii::FiniteElement<dim> &fe;
    const dealii::FE_Poly<dim, dim>  *polynomial_fe;
    const unsigned int                n_dofs;
    bool                              have_reference_gradients = false;
    // A tensor-product element's 1D polynomials and the map from the
    // lexicographic numbering to the element's (empty for other elements).
    std::vector<dealii::Polynomials::Polynomial<double>> polynomials_1d;
    std::vector<unsigned int>                            numbering_inverse;
    std::vector<double>                                  one_d;
    std::vector<dealii::Point<dim>>                      points;
    std::vector<double>                                  values;
    std::vector<dealii::Tensor<1, dim>>                  reference_gradients;
    std::vector<dealii::Tensor<1, dim>>                  gradients;
    std::vector<double>                                  determinants;
    // Scratch for one point's evaluation.
    std::vector<double>                 point_values;
    std::vector<dealii::Tensor<1, dim>> point_gradients;
    std::vector<dealii::Tensor<2, dim>> no_second;
    std::vector<dealii::Tensor<3, dim>> no_third;
    std::vector<dealii::Tensor<4, dim>> no_fourth;
  };
} // namespace ImmersedGrains

#endif
