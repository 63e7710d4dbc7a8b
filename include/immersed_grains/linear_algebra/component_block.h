#ifndef immersed_grains_linear_algebra_component_block_h
#define immersed_grains_linear_algebra_component_block_h

#include <deal.II/lac/trilinos_sparse_matrix.h>
#include <deal.II/lac/trilinos_vector.h>

#include <memory>
#include <vector>

class Epetra_CrsMatrix;
class Epetra_Map;
class Epetra_MultiVector;

namespace ImmersedGrains
{
  /**
   * A square matrix that acts alike on each of its n components,
   * A = K (x) I_n with the unknowns numbered node by node (n per node),
   * held once as the scalar matrix K of the nodes, except on the rows of
   * fixed unknowns (constrained ones: a row with only its diagonal, and no
   * column in the other rows).
   *
   * The fluid's velocity block has this form wherever its components couple
   * only with themselves (no Newton derivative of the advection term, no
   * slip constraint that ties components together): every component's free
   * rows hold the same values. A slip wall along a coordinate plane fixes
   * only the normal component, so the components differ there by which
   * unknowns are fixed, not by their values.
   *
   * K holds every coupling between two nodes that some component has free
   * at both. A product reads each of K's entries once for all n components
   * instead of once per component, a third of the matrix's memory traffic
   * in 3D, and gives A's product exactly: a component's fixed unknowns are
   * zeroed before it and take their diagonal after it.
   *
   * A itself stays as it is: K's values are copied from A's rows after each
   * assembly (update()).
   */
  class ComponentBlock
  {
  public:
    ComponentBlock();
    ~ComponentBlock();

    /**
     * Whether @p matrix's pattern on this rank is that of K (x) I_n for
     * @p n_components, @p fixed telling for each of its locally owned rows
     * (in Epetra's local order) whether it is a fixed unknown's: every owned
     * node holds its n rows, numbered n i + c, a free row n i + c has
     * entries only in columns n j + c, and a fixed row only its diagonal.
     * If so, K's pattern is set up (values zero). Collective: the answer is
     * the same on every rank.
     */
    bool
    reinit(const dealii::TrilinosWrappers::SparseMatrix &matrix,
           unsigned int                                  n_components,
           const std::vector<bool>                      &fixed);

    /**
     * Copies K's values from @p matrix. The first call after reinit() also
     * compares every free row's entries with them, and returns false
     * (collectively) where any differs: then @p matrix is not of this form
     * and this object must not stand for it.
     */
    bool
    update(const dealii::TrilinosWrappers::SparseMatrix &matrix);

    /** dst = A src. */
    void
    vmult(dealii::TrilinosWrappers::MPI::Vector       &dst,
          const dealii::TrilinosWrappers::MPI::Vector &src) const;

    /** The same on Epetra vectors numbered like A's rows (one column). */
    void
    vmult(Epetra_MultiVector &dst, const Epetra_MultiVector &src) const;

    /** K, whose rows are the nodes this rank owns. */
    const Epetra_CrsMatrix &
    scalar_matrix() const;

    unsigned int
    n_components() const;

    /**
     * Whether every node is fixed in all its components or in none (no
     * slip wall): then K's ILU(0) is A's. Collective at reinit().
     */
    bool
    components_fixed_alike() const;

    /** The rows of A (its range map), for operators that stand for A. */
    const Epetra_Map &
    component_map() const;

    /**
     * Copies an Epetra vector numbered like A's rows into the columns of
     * @p split (one per component, numbered like K's rows), with zeros at
     * the fixed unknowns.
     */
    void
    split(const Epetra_MultiVector &interleaved,
          Epetra_MultiVector       &split) const;

    /**
     * The reverse of split() for the free unknowns; a fixed unknown gets its
     * diagonal entry of A times its entry in @p fixed_source (as A's product
     * and A's inverse, with the diagonal's inverse, give it).
     */
    void
    interleave(const Epetra_MultiVector &split,
               const Epetra_MultiVector &fixed_source,
               Epetra_MultiVector       &interleaved,
               bool                      inverse_diagonal) const;

  private:
    unsigned int                      components = 0;
    std::unique_ptr<Epetra_Map>       node_map;
    std::unique_ptr<Epetra_Map>       node_column_map;
    std::unique_ptr<Epetra_Map>       row_map;
    std::unique_ptr<Epetra_CrsMatrix> matrix;
    bool                              values_checked = false;
    bool                              fixed_alike    = false;

    // Where each of K's entries (in its storage order) is read in A's
    // values, and the A rows whose free entries update() checks once.
    std::vector<int> source;
    // A's fixed rows (local order), where their diagonal is in A's values,
    // and its value at the last update().
    std::vector<int>            fixed_rows, fixed_diagonal;
    std::vector<double>         fixed_values;
    mutable std::vector<double> fixed_results;

    // The split copies of a product's source and destination.
    mutable std::unique_ptr<Epetra_MultiVector> split_source, split_destination;
  };
} // namespace ImmersedGrains

#endif
