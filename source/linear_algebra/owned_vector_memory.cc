#include <immersed_grains/linear_algebra/owned_vector_memory.h>

#include <algorithm>

namespace ImmersedGrains
{
  void
  ignore_non_local_entries(dealii::TrilinosWrappers::MPI::Vector &vector)
  {
    if (vector.size() > 0)
      vector.trilinos_vector().setIgnoreNonLocalEntries(true);
  }


  void
  ignore_non_local_entries(dealii::TrilinosWrappers::MPI::BlockVector &vector)
  {
    for (unsigned int b = 0; b < vector.n_blocks(); ++b)
      ignore_non_local_entries(vector.block(b));
  }


  OwnedVectorMemory::~OwnedVectorMemory()
  {
    Assert(std::none_of(slots.begin(),
                        slots.end(),
                        [](const Slot &slot) { return slot.in_use; }),
           dealii::ExcInternalError());
  }


  OwnedVectorMemory::VectorType *
  OwnedVectorMemory::alloc()
  {
    for (Slot &slot : slots)
      if (!slot.in_use)
      {
        slot.in_use = true;
        return slot.vector.get();
      }
    slots.push_back({std::make_unique<VectorType>(), true});
    return slots.back().vector.get();
  }


  void
  OwnedVectorMemory::free(const VectorType *const v)
  {
    for (Slot &slot : slots)
      if (slot.vector.get() == v)
      {
        Assert(slot.in_use, dealii::ExcInternalError());
        slot.in_use = false;
        // The solver has given it its layout by now: the next solve's
        // reinit() keeps the Epetra vector and only zeroes it.
        ignore_non_local_entries(*slot.vector);
        return;
      }
    Assert(false, dealii::ExcInternalError());
  }


  void
  OwnedVectorMemory::clear()
  {
    Assert(std::none_of(slots.begin(),
                        slots.end(),
                        [](const Slot &slot) { return slot.in_use; }),
           dealii::ExcInternalError());
    slots.clear();
  }
} // namespace ImmersedGrains
