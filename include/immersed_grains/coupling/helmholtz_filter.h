#ifndef immersed_grains_coupling_helmholtz_filter_h
#define immersed_grains_coupling_helmholtz_filter_h

#include <deal.II/base/geometry_info.h>
#include <deal.II/base/index_set.h>
#include <deal.II/distributed/tria.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/fe/fe_q.h>
#include <deal.II/fe/mapping.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/trilinos_sparse_matrix.h>
#include <deal.II/lac/trilinos_vector.h>

#include <immersed_grains/linear_algebra/ghost_exchange.h>
#include <immersed_grains/mesh/geometry.h>

#include <array>
#include <memory>
#include <vector>

class Amesos_BaseSolver;
class Epetra_LinearProblem;

namespace ImmersedGrains
{
  /**
   * The Q1 Helmholtz filter that turns sums over grains into fields:
   *
   *   (M + l^2 K) f = b,
   *
   * with M the consistent or the lumped (row-sum) mass matrix, K the
   * stiffness matrix and l the filter length (0: an L2 projection). Since
   * K 1 = 0 and the Q1 shape functions sum to one, the integral of f equals
   * the sum of the entries of b whatever M, l, the mesh or the partition:
   * the filter conserves what it spreads. The operator is symmetric, so the
   * filtered value of a field u at a point x, N(x)^T A^{-1} (N, u), is the
   * adjoint of spreading a point quantity at x: a grain that spreads its
   * drag with the filter and feels the filtered fluid velocity exchanges
   * exactly the momentum the fluid receives (doc/theory.md section 3).
   * With the lumped M the matrix is an M-matrix on box meshes, so the filter
   * of a non-negative b is non-negative.
   */
  template <int dim>
  class HelmholtzFilter
  {
  public:
    using Vector = dealii::TrilinosWrappers::MPI::Vector;

    HelmholtzFilter(const dealii::parallel::distributed::Triangulation<dim> &,
                    const Geometry<dim> &geometry);

    ~HelmholtzFilter();

    /**
     * (Re)builds DoFs and the matrix; call after every mesh change. The
     * consistent mass matrix for mass_product() only @p with_mass_matrix.
     */
    void
    setup(bool lumped, double length, bool with_mass_matrix = false);

    /** A vector over the locally owned DoFs, zero (for right-hand sides). */
    Vector
    make_owned_vector() const;

    /** A ghosted vector, zero (for filtered fields). */
    Vector
    make_ghosted_vector() const;

    /** Adds a cell's contributions b_j to @p rhs through the constraints. */
    void
    add_cell_contribution(
      const typename dealii::DoFHandler<dim>::active_cell_iterator &cell,
      const dealii::Vector<double>                                 &local,
      std::vector<dealii::types::global_dof_index>                 &indices,
      Vector                                                       &rhs) const;

    /**
     * (N_j, f) for a ghosted field @p f into the owned @p rhs, through the
     * constraints (the consistent mass matrix applied to f).
     */
    void
    mass_product(const Vector &f, Vector &rhs) const;

    /** Solves A f = @p rhs (compressed, owned) into the ghosted @p f: with
     *  the factorisation of setup() where there is one, else by
     *  conjugate gradients to a relative residual of 1e-15. */
    void
    solve(const Vector &rhs, Vector &f) const;

    /**
     * solve() for several right-hand sides at once: one conjugate-gradient
     * iteration per column, in lockstep, so that each iteration reads the
     * matrix once and reduces all inner products in one message. Each
     * column stops at solve()'s tolerance.
     */
    void
    solve(const std::vector<const Vector *> &rhs,
          const std::vector<Vector *>       &f) const;

    /** The Q1 DoFHandler's cell of a triangulation cell. */
    typename dealii::DoFHandler<dim>::active_cell_iterator
    dof_cell(const typename dealii::Triangulation<dim>::active_cell_iterator
               &cell) const;

    /** Integral of a ghosted field over the locally owned cells, summed. */
    double
    integral(const Vector &f) const;

    /**
     * The integral of each shape function over the locally owned cells,
     * every DoF's own (hanging and periodic ones included, not condensed),
     * summed over ranks onto the owners: the integral of a ghosted field f
     * whose constrained entries are distributed is the sum over owned DoFs
     * of weights_i g(f_i) for any g applied node by node (g = identity:
     * integral()).
     */
    const Vector &
    shape_integrals() const;

    const dealii::DoFHandler<dim> &
    get_dof_handler() const;

    const dealii::FE_Q<dim> &
    get_fe() const;

    /**
     * The values of get_fe()'s shape functions (Q1, one per vertex) at the
     * point @p x of the reference cell, in its DoF order, all at once:
     * bit for bit what get_fe().shape_value(j, x) gives, which evaluates
     * each factor again for every function (a tenth of the grains' drag on
     * a million grains).
     */
    static std::array<double, dealii::GeometryInfo<dim>::vertices_per_cell>
    shape_values(const dealii::Point<dim> &x);

    const dealii::Mapping<dim> &
    get_mapping() const;

    const dealii::IndexSet &
    locally_owned_dofs() const;

  private:
    const dealii::parallel::distributed::Triangulation<dim> &triangulation;
    const Geometry<dim>                                     &geometry;
    const dealii::Mapping<dim>                              &mapping;
    dealii::FE_Q<dim>                                        fe;
    dealii::DoFHandler<dim>                                  dof_handler;
    dealii::AffineConstraints<double>                        constraints;
    dealii::IndexSet                                         owned, relevant;
    dealii::TrilinosWrappers::SparseMatrix                   matrix;
    dealii::TrilinosWrappers::SparseMatrix                   mass_matrix;
    Vector                                                   lumped_inverse;
    // Vectors of the two layouts that every vector of this filter copies
    // (sharing Epetra's maps), and the copies between the layouts.
    Vector        owned_template, ghosted_template;
    GhostExchange ghost_exchange;
    // The inverse of the matrix's diagonal: the conjugate gradients' Jacobi
    // preconditioner.
    Vector diagonal_inverse;
    Vector weights;
    // A plain lumped projection is a division, not a linear solve.
    bool diagonal = false;
    // Up to direct_limit() unknowns (a rank's share of it on several
    // ranks), A's sparse LU, on the first rank (setup()); solve() then
    // costs two triangular solves per field.
    std::unique_ptr<Epetra_LinearProblem> direct_problem;
    std::unique_ptr<Amesos_BaseSolver>    direct_solver;
  };
} // namespace ImmersedGrains

#endif
