#ifndef immersed_grains_linear_algebra_ghost_exchange_h
#define immersed_grains_linear_algebra_ghost_exchange_h

#include <deal.II/base/index_set.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/trilinos_parallel_block_vector.h>
#include <deal.II/lac/trilinos_vector.h>

#include <memory>
#include <vector>

class Epetra_Import;

namespace ImmersedGrains
{
  /**
   * Copies between distributed Trilinos vectors and their ghosted twins of
   * one layout, with the communication pattern found once per layout.
   *
   * deal.II's assignment between the two layouts first compares their
   * Epetra maps (a reduction over all ranks) and then builds a new
   * Epetra_Import (the remote indices exchanged and looked up) at every
   * call, where the data copied is a few kilobytes on a 2D scene
   * (doc/performance.md, "Two ranks"). Here the import is built in
   * reinit(); the owned values are copied by local positions, and only the
   * ghosts travel. The copies are exact, as deal.II's are.
   *
   * The vectors given must have the layout given to reinit(): their local
   * lengths are checked, and Epetra checks the import's maps. Vectors that
   * share the templates' Epetra maps (copies of them) pass Epetra's check
   * at once; others are compared entry by entry.
   */
  class GhostExchange
  {
  public:
    using Vector      = dealii::TrilinosWrappers::MPI::Vector;
    using BlockVector = dealii::TrilinosWrappers::MPI::BlockVector;

    GhostExchange();
    ~GhostExchange();

    /** The layout of one vector: the ghosted @p ghosted_template against
     * the owned @p owned_template. */
    void
    reinit(const Vector &owned_template, const Vector &ghosted_template);

    /** The layout of a block vector, block by block. */
    void
    reinit(const BlockVector &owned_template,
           const BlockVector &ghosted_template);

    void
    clear();

    /** @p ghosted = @p owned, ghosts included. */
    void
    to_ghosted(const Vector &owned, Vector &ghosted) const;

    void
    to_ghosted(const BlockVector &owned, BlockVector &ghosted) const;

    /** @p owned = the locally owned values of @p ghosted, no
     * communication. */
    void
    to_owned(const Vector &ghosted, Vector &owned) const;

    void
    to_owned(const BlockVector &ghosted, BlockVector &owned) const;

    /**
     * AffineConstraints::distribute() on @p owned, the masters read from
     * @p ghosted, which then holds the result, ghosts included. The same
     * values, summed in the same order, as deal.II's, which builds a
     * ghosted copy with a new import and then an export at every call.
     */
    void
    distribute(const dealii::AffineConstraints<double> &constraints,
               Vector                                  &owned,
               Vector                                  &ghosted) const;

    void
    distribute(const dealii::AffineConstraints<double> &constraints,
               BlockVector                             &owned,
               BlockVector                             &ghosted) const;

    /** @p destination = @p source for two vectors of the same layout
     * (ghosted or not), without deal.II's comparison of their maps. */
    static void
    copy(const Vector &source, Vector &destination);

    static void
    copy(const BlockVector &source, BlockVector &destination);

  private:
    struct Block
    {
      std::unique_ptr<Epetra_Import> import; // owned map -> ghosted map
      // Ghosted local position of each owned local position.
      std::vector<int> owned_in_ghosted;
      int              ghosted_length = 0;
    };

    std::vector<Block> blocks;

    void
    to_ghosted(const Block &block, const Vector &owned, Vector &ghosted) const;

    void
    to_owned(const Block &block, const Vector &ghosted, Vector &owned) const;

    // The constrained values of the owned entries, from the masters in
    // the ghosted vectors (global indices over the blocks in order).
    void
    set_constrained(const dealii::AffineConstraints<double> &constraints,
                    const std::vector<Vector *>             &owned,
                    const std::vector<const Vector *>       &ghosted) const;
  };
} // namespace ImmersedGrains

#endif
