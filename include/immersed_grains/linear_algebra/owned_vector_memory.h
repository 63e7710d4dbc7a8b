#ifndef immersed_grains_linear_algebra_owned_vector_memory_h
#define immersed_grains_linear_algebra_owned_vector_memory_h

#include <deal.II/lac/trilinos_parallel_block_vector.h>
#include <deal.II/lac/vector_memory.h>

#include <memory>
#include <vector>

namespace ImmersedGrains
{
  /**
   * Marks the Epetra vectors of @p vector as never receiving entries of
   * rows that another rank owns, so that Epetra skips their assembly step.
   *
   * Epetra_FEVector::GlobalAssemble(), which deal.II calls at every
   * compress() and at every reinit() that zeroes a vector, builds on
   * several ranks a map of the non-local entries and an exporter to their
   * owners (collective operations) even where there are none. Vectors
   * written only through their own rows (products, Krylov updates, local
   * writes) never need it. The mark is lost where a reinit() gives the
   * vector a new layout.
   */
  void
  ignore_non_local_entries(dealii::TrilinosWrappers::MPI::Vector &vector);

  void
  ignore_non_local_entries(dealii::TrilinosWrappers::MPI::BlockVector &vector);

  /**
   * The temporary vectors of deal.II's Krylov solvers, kept between solves
   * and marked with ignore_non_local_entries(): FGMRES zeroes each basis
   * vector with reinit() at every solve, and on two ranks the assembly
   * steps that reinit() starts took 2 % of the 2D cloud's run
   * (doc/performance.md, "Two ranks"). A solver's vectors are written only
   * through their own rows. Not thread-safe, like the solvers.
   */
  class OwnedVectorMemory
      : public dealii::VectorMemory<dealii::TrilinosWrappers::MPI::BlockVector>
  {
  public:
    using VectorType = dealii::TrilinosWrappers::MPI::BlockVector;

    ~OwnedVectorMemory() override;

    VectorType *
    alloc() override;

    void
    free(const VectorType *const v) override;

    /** Drops the vectors, all of which must be free (a new mesh). */
    void
    clear();

  private:
    struct Slot
    {
      std::unique_ptr<VectorType> vector;
      bool                        in_use;
    };
    std::vector<Slot> slots;
  };
} // namespace ImmersedGrains

#endif
