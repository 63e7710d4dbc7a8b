#include <deal.II/base/exceptions.h>
#include <deal.II/base/mpi.h>

#include <immersed_grains/linear_algebra/ghost_exchange.h>

#include <Epetra_FEVector.h>
#include <Epetra_Import.h>

#include <algorithm>

namespace ImmersedGrains
{
  GhostExchange::GhostExchange() = default;

  GhostExchange::~GhostExchange() = default;


  void
  GhostExchange::clear()
  {
    blocks.clear();
  }


  void
  GhostExchange::reinit(const Vector &owned_template,
                        const Vector &ghosted_template)
  {
    const Epetra_BlockMap &owned_map = owned_template.trilinos_vector().Map();
    const Epetra_BlockMap &ghosted_map =
      ghosted_template.trilinos_vector().Map();
    AssertThrow(owned_map.UniqueGIDs(),
                dealii::ExcMessage("GhostExchange: the owned vector has "
                                   "ghost entries"));
    Block block;
    block.ghosted_length = ghosted_map.NumMyElements();
    block.owned_in_ghosted.resize(owned_map.NumMyElements());
    for (int k = 0; k < owned_map.NumMyElements(); ++k)
    {
      block.owned_in_ghosted[k] = ghosted_map.LID(owned_map.GID64(k));
      AssertThrow(block.owned_in_ghosted[k] >= 0,
                  dealii::ExcMessage("GhostExchange: an owned entry is "
                                     "missing from the ghosted layout"));
    }
    // The import is collective: every rank takes it where any rank has
    // ghosts.
    const unsigned int ghosts =
      ghosted_map.NumMyElements() - owned_map.NumMyElements();
    const MPI_Comm comm = owned_template.get_mpi_communicator();
    if (dealii::Utilities::MPI::max(ghosts, comm) > 0)
      block.import = std::make_unique<Epetra_Import>(ghosted_map, owned_map);
    blocks.clear();
    blocks.push_back(std::move(block));
  }


  void
  GhostExchange::reinit(const BlockVector &owned_template,
                        const BlockVector &ghosted_template)
  {
    AssertDimension(owned_template.n_blocks(), ghosted_template.n_blocks());
    std::vector<Block> all;
    for (unsigned int b = 0; b < owned_template.n_blocks(); ++b)
    {
      reinit(owned_template.block(b), ghosted_template.block(b));
      all.push_back(std::move(blocks.front()));
    }
    blocks = std::move(all);
  }


  void
  GhostExchange::to_ghosted(const Block  &block,
                            const Vector &owned,
                            Vector       &ghosted) const
  {
    const Epetra_MultiVector &source      = owned.trilinos_vector();
    Epetra_MultiVector       &destination = ghosted.trilinos_vector();
    AssertThrow(source.MyLength() ==
                    static_cast<int>(block.owned_in_ghosted.size()) &&
                  destination.MyLength() == block.ghosted_length,
                dealii::ExcMessage("GhostExchange: a vector of another "
                                   "layout"));
    if (block.import)
    {
      const int status = destination.Import(source, *block.import, Insert);
      AssertThrow(status == 0,
                  dealii::ExcMessage("GhostExchange: Epetra's import failed"));
      return;
    }
    const double *from = source[0];
    double       *to   = destination[0];
    for (std::size_t k = 0; k < block.owned_in_ghosted.size(); ++k)
      to[block.owned_in_ghosted[k]] = from[k];
  }


  void
  GhostExchange::to_owned(const Block  &block,
                          const Vector &ghosted,
                          Vector       &owned) const
  {
    const Epetra_MultiVector &source      = ghosted.trilinos_vector();
    Epetra_MultiVector       &destination = owned.trilinos_vector();
    AssertThrow(destination.MyLength() ==
                    static_cast<int>(block.owned_in_ghosted.size()) &&
                  source.MyLength() == block.ghosted_length,
                dealii::ExcMessage("GhostExchange: a vector of another "
                                   "layout"));
    const double *from = source[0];
    double       *to   = destination[0];
    for (std::size_t k = 0; k < block.owned_in_ghosted.size(); ++k)
      to[k] = from[block.owned_in_ghosted[k]];
  }


  void
  GhostExchange::to_ghosted(const Vector &owned, Vector &ghosted) const
  {
    AssertDimension(blocks.size(), 1);
    to_ghosted(blocks.front(), owned, ghosted);
  }


  void
  GhostExchange::to_ghosted(const BlockVector &owned,
                            BlockVector       &ghosted) const
  {
    AssertDimension(blocks.size(), owned.n_blocks());
    AssertDimension(blocks.size(), ghosted.n_blocks());
    for (unsigned int b = 0; b < blocks.size(); ++b)
      to_ghosted(blocks[b], owned.block(b), ghosted.block(b));
  }


  void
  GhostExchange::to_owned(const Vector &ghosted, Vector &owned) const
  {
    AssertDimension(blocks.size(), 1);
    to_owned(blocks.front(), ghosted, owned);
  }


  void
  GhostExchange::to_owned(const BlockVector &ghosted, BlockVector &owned) const
  {
    AssertDimension(blocks.size(), owned.n_blocks());
    AssertDimension(blocks.size(), ghosted.n_blocks());
    for (unsigned int b = 0; b < blocks.size(); ++b)
      to_owned(blocks[b], ghosted.block(b), owned.block(b));
  }


  void
  GhostExchange::set_constrained(
    const dealii::AffineConstraints<double> &constraints,
    const std::vector<Vector *>             &owned,
    const std::vector<const Vector *>       &ghosted) const
  {
    using size_type = dealii::types::global_dof_index;
    std::vector<size_type> offsets(owned.size() + 1, 0);
    for (unsigned int b = 0; b < owned.size(); ++b)
      offsets[b + 1] = offsets[b] + owned[b]->size();
    const auto block_of = [&](const size_type i)
    {
      return static_cast<unsigned int>(
        std::upper_bound(offsets.begin() + 1, offsets.end(), i) -
        offsets.begin() - 1);
    };
    for (const auto &line : constraints.get_lines())
    {
      const unsigned int  b  = block_of(line.index);
      Epetra_MultiVector &to = owned[b]->trilinos_vector();
      const int           slot =
        to.Map().LID(static_cast<long long>(line.index - offsets[b]));
      if (slot < 0)
        continue; // another rank's entry
      double value = line.inhomogeneity;
      for (const auto &entry : line.entries)
      {
        const unsigned int        e    = block_of(entry.first);
        const Epetra_MultiVector &from = ghosted[e]->trilinos_vector();
        const int                 master =
          from.Map().LID(static_cast<long long>(entry.first - offsets[e]));
        AssertThrow(master >= 0,
                    dealii::ExcMessage("GhostExchange::distribute: a master "
                                       "outside the ghosted layout"));
        value += from[0][master] * entry.second;
      }
      to[0][slot] = value;
    }
  }


  void
  GhostExchange::distribute(
    const dealii::AffineConstraints<double> &constraints,
    Vector                                  &owned,
    Vector                                  &ghosted) const
  {
    to_ghosted(owned, ghosted);
    set_constrained(constraints, {&owned}, {&ghosted});
    to_ghosted(owned, ghosted);
  }


  void
  GhostExchange::distribute(
    const dealii::AffineConstraints<double> &constraints,
    BlockVector                             &owned,
    BlockVector                             &ghosted) const
  {
    to_ghosted(owned, ghosted);
    std::vector<Vector *>       owned_blocks;
    std::vector<const Vector *> ghosted_blocks;
    for (unsigned int b = 0; b < owned.n_blocks(); ++b)
    {
      owned_blocks.push_back(&owned.block(b));
      ghosted_blocks.push_back(&ghosted.block(b));
    }
    set_constrained(constraints, owned_blocks, ghosted_blocks);
    to_ghosted(owned, ghosted);
  }


  void
  GhostExchange::copy(const Vector &source, Vector &destination)
  {
    const Epetra_MultiVector &from = source.trilinos_vector();
    Epetra_MultiVector       &to   = destination.trilinos_vector();
    AssertThrow(from.MyLength() == to.MyLength(),
                dealii::ExcMessage("GhostExchange::copy: vectors of "
                                   "different layouts"));
    Assert(from.Map().SameAs(to.Map()),
           dealii::ExcMessage("GhostExchange::copy: vectors of different "
                              "layouts"));
    std::copy(from[0], from[0] + from.MyLength(), to[0]);
  }


  void
  GhostExchange::copy(const BlockVector &source, BlockVector &destination)
  {
    AssertDimension(source.n_blocks(), destination.n_blocks());
    for (unsigned int b = 0; b < source.n_blocks(); ++b)
      copy(source.block(b), destination.block(b));
  }
} // namespace ImmersedGrains
