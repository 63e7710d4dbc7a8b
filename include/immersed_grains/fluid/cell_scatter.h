#ifndef immersed_grains_fluid_cell_scatter_h
#define immersed_grains_fluid_cell_scatter_h

#include <deal.II/base/table.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/full_matrix.h>
#include <deal.II/lac/trilinos_block_sparse_matrix.h>
#include <deal.II/lac/trilinos_parallel_block_vector.h>
#include <deal.II/lac/vector.h>

#include <array>
#include <cstdint>
#include <vector>

namespace ImmersedGrains
{
  /**
   * Adds cell matrices and right-hand sides into the fluid's Trilinos
   * block system through the positions of their entries in Epetra's rows,
   * found once per mesh, instead of AffineConstraints::
   * distribute_local_to_global, which looks every entry up in the row
   * (a binary search and a map from global to local column) at every
   * assembly: half of the cell loop's time in 3D (doc/performance.md).
   *
   * A cell qualifies when all its DoFs are owned by this rank (on several
   * ranks, see below) and each is either free or fixed to zero by a
   * constraint without entries (walls, slip on faces normal to an axis):
   * there distribute_local_to_global adds the free rows' entries in free
   * columns, the absolute diagonal entry (or the mean absolute diagonal
   * where it is zero) on each fixed row, and nothing else, which add()
   * repeats entry by entry in the same order, so that the assembled system
   * is the same to the last bit.
   *
   * A cell with hanging-node or periodic constraints qualifies too when
   * every row it writes (its free DoFs, the masters of its constrained
   * ones, and the constrained ones' own diagonals) is owned by this rank:
   * its matrix is condensed in the cell, C^T K C with C the constraints'
   * weights from the cell's DoFs to those rows, and added at positions
   * found once per mesh; the constrained rows get the diagonal entry
   * AffineConstraints gives them. The sums are the same as
   * distribute_local_to_global's, in another order (round-off).
   *
   * On several ranks a cell next to another rank's cells writes rows that
   * rank owns (a quarter of the cells of a 3D cloud on two ranks, all on
   * the higher rank: deal.II gives a DoF on the rank boundary to the lower
   * one). Such a cell takes the direct or the condensed path as above for
   * its owned rows, and the other rank's rows go by the exchange below.
   * Where some constraint is inhomogeneous the exchange is not used: such
   * a cell is then condensed, and the other rank's rows go through the
   * matrix's and vector's non-local buffers by global index, as
   * distribute_local_to_global would, summed on their owner at
   * compress(). Only cells with inhomogeneous constraints keep the
   * general path.
   *
   * Where no cell on any rank takes the general path, the other ranks'
   * rows do not go through deal.II either: each rank sums its entries of
   * them into one array (a slot per entry, found once per mesh, which
   * the cells' visits add to in their order), sends each owner its part
   * in one message per assembly (compress_system()), and the owner adds
   * them at positions found once per mesh. deal.II's compress() of the four
   * blocks and of the vector, and the compress() in its zeroing of the matrix,
   * each export through Epetra with collective checks and look-ups of every
   * entry (a tenth of the 2D cloud's run on two ranks, doc/performance.md
   * "Two ranks"). The sums are the same as Epetra's.
   */
  template <int dim>
  class CellScatter
  {
  public:
    using MatrixType = dealii::TrilinosWrappers::BlockSparseMatrix;
    using VectorType = dealii::TrilinosWrappers::MPI::BlockVector;

    /**
     * Finds the entries of every qualifying locally owned cell in
     * @p matrix (built with @p coupling between the components and
     * @p constraints) and in @p vector. Both must keep their storage until
     * the next call: add() writes into it.
     */
    void
    reinit(const dealii::DoFHandler<dim>                      &dof_handler,
           const dealii::Table<2, dealii::DoFTools::Coupling> &coupling,
           const dealii::AffineConstraints<double>            &constraints,
           MatrixType                                         &matrix,
           VectorType                                         &vector);

    void
    clear();

    /** Whether the @p k-th locally owned cell (in the order of
     * DoFHandler::active_cell_iterators()) takes the direct path. */
    bool
    is_direct(unsigned int k) const;

    /** Adds the @p k-th locally owned cell's matrix and right-hand side. */
    void
    add(unsigned int                      k,
        const dealii::FullMatrix<double> &cell_matrix,
        const dealii::Vector<double>     &cell_rhs) const;

    /**
     * Zeroes @p matrix and @p vector, those given to reinit(), for an
     * assembly, and the sums of other ranks' rows.
     */
    void
    zero_system(MatrixType &matrix, VectorType &vector) const;

    /**
     * Completes an assembly: adds the entries of rows that other ranks own
     * on their owners, by the exchange above or by deal.II's compress().
     * Collective.
     */
    void
    compress_system(MatrixType &matrix, VectorType &vector) const;

    /** Whether the rows that other ranks own go by the exchange above
     * (the same on every rank). */
    bool
    exchanges_remote_rows() const;

    /** The direct cells' share of the locally owned cells. */
    double
    direct_fraction() const;

  private:
    static constexpr std::uint16_t skip = 0xffff;

    // A pair of local DoFs that the coupling table couples, with the
    // blocks of their rows and columns; the same for every cell.
    struct Pair
    {
      std::uint16_t i, j;
      std::uint8_t  row_block, column_block;
    };
    std::vector<Pair> pairs;
    // Each pair's entry in the cell matrix (i * dofs_per_cell + j), its
    // row pointer (2 i + column block), and its local DoF where it is a
    // diagonal entry (else dofs_per_cell), for add()'s loop over the cells
    // without another rank's rows.
    std::vector<std::uint32_t> pair_entries;
    std::vector<std::uint16_t> pair_row_pointers;
    std::vector<std::uint16_t> pair_diagonal_dof;
    mutable std::vector<char>  cell_fixed_dofs; // add()'s, per cell
    unsigned int               dofs_per_cell = 0;

    // Per locally owned cell: its number among the direct cells, or -1.
    std::vector<int> direct_index;
    // Per direct cell: where its entries of other ranks' rows start in
    // remote_slots, or no_remote.
    static constexpr std::size_t no_remote = std::size_t(-1);
    // Whether direct cells may write other ranks' rows (reinit()).
    bool                     remote_rows_by_exchange = false;
    std::vector<std::size_t> direct_remote_start;
    // Per locally owned cell: its number among the condensed cells, or -1.
    std::vector<int> condensed_index;

    // The condensed cells (hanging nodes, periodicity). Per cell: its
    // target rows (the rows it writes: free DoFs and masters), each with
    // block, Epetra row and component; each local DoF's targets with
    // weights; each constrained local DoF's own row and the position of
    // its diagonal; and, target row by target row, the coupled target
    // columns with their positions. Offsets per cell into flat arrays.
    // row: Epetra's local row, or -1 where another rank owns it; index:
    // the global index in its block (of its column, and of a row that
    // another rank owns).
    struct Target
    {
      int                             row;
      std::uint8_t                    block;
      std::uint16_t                   component;
      dealii::types::global_dof_index index;
    };
    struct Expansion
    {
      std::uint16_t target;
      double        weight;
    };
    struct Diagonal
    {
      std::uint16_t                   local_dof;
      std::uint16_t                   position; // skip: another rank's row
      int                             row;
      dealii::types::global_dof_index index; // in its block
    };
    struct Entry
    {
      std::uint16_t column; // target index
      std::uint16_t position;
    };
    std::vector<std::size_t> condensed_targets_start, condensed_entries_start,
      condensed_expansion_start, condensed_diagonals_start;
    std::vector<Target>        condensed_targets;
    std::vector<unsigned int>  condensed_expansion_offsets; // dofs + 1 per cell
    std::vector<Expansion>     condensed_expansion;
    std::vector<Diagonal>      condensed_diagonals;
    std::vector<std::uint16_t> condensed_row_lengths; // entries per target row
    std::vector<Entry>         condensed_entries;
    mutable std::vector<double> condensed_matrix, condensed_rhs;
    // Per condensed cell and local DoF: its one target if it is free, or -1.
    std::vector<int> condensed_single_targets;

    // Finds the cells' positions (reinit() without the exchange's set-up).
    void
    find_positions(const dealii::DoFHandler<dim> &dof_handler,
                   const dealii::Table<2, dealii::DoFTools::Coupling> &coupling,
                   const dealii::AffineConstraints<double> &constraints,
                   MatrixType                              &matrix,
                   VectorType                              &vector);

    // Records a cell for the condensed path; false if it does not qualify.
    bool
    add_condensed_cell(
      const std::vector<dealii::types::global_dof_index> &dofs,
      const dealii::AffineConstraints<double>            &constraints,
      const dealii::Table<2, dealii::DoFTools::Coupling> &coupling,
      const MatrixType                                   &matrix);

    // Decides with the other ranks whether the exchange below replaces
    // deal.II's, and finds its slots and targets. Collective.
    void
    setup_remote_exchange(const dealii::DoFHandler<dim> &dof_handler,
                          MatrixType                    &matrix,
                          VectorType                    &vector);

    // Adds a condensed cell's row that another rank owns (Target::row < 0).
    void
    add_to_remote_row(const Target &row,
                      const Entry  *entries,
                      unsigned int  n_entries,
                      const double *sums,
                      const Target *targets,
                      double        rhs) const;

    void
    add_condensed(unsigned int                      c,
                  const dealii::FullMatrix<double> &cell_matrix,
                  const dealii::Vector<double>     &cell_rhs) const;
    // Per direct cell: each local DoF's row in its block (Epetra's local
    // numbering) with a flag for a fixed DoF, and each pair's position in
    // that row (skip where the pair does not enter the matrix).
    std::vector<int>           rows;
    std::vector<bool>          fixed;
    std::vector<std::uint16_t> positions;

    // Local DoF -> block of its row, and its component.
    std::vector<std::uint8_t>  dof_block;
    std::vector<std::uint16_t> component_of;
    // The values of each local row of each block, its local column
    // indices and its length, and the values of each vector block.
    std::array<std::array<std::vector<double *>, 2>, 2> row_values;
    std::array<std::array<std::vector<int *>, 2>, 2>    row_indices;
    std::array<std::array<std::vector<int>, 2>, 2>      row_lengths;
    std::array<double *, 2>                             vector_values{};
    // The current cell's rows by local DoF and column block (add()).
    mutable std::vector<double *> row_pointers;

    // Where rows that other ranks own are added (add_condensed()).
    MatrixType *system_matrix = nullptr;
    VectorType *system_vector = nullptr;
    mutable std::array<std::vector<dealii::types::global_dof_index>, 2>
                                               remote_columns;
    mutable std::array<std::vector<double>, 2> remote_values;

    // The exchange of other ranks' rows (exchange_remote). An entry of such
    // a row: its kind (remote_code() in cell_scatter.cc) and block-local
    // row and column, recorded in the order add_condensed() visits them,
    // from condensed_remote_start[c] on for condensed cell c; each visit's
    // slot in send_values, where the slots of one owner are contiguous
    // (send_offsets, per send_ranks). The owner adds what it receives from
    // receive_ranks[i] at receive_targets[i].
    struct RemoteVisit
    {
      std::uint8_t                    code;
      dealii::types::global_dof_index row, column;
    };
    bool                                     exchange_remote = false;
    std::vector<RemoteVisit>                 remote_visits; // reinit() only
    std::vector<std::size_t>                 condensed_remote_start;
    std::vector<std::uint32_t>               remote_slots;
    std::vector<unsigned int>                send_ranks;
    std::vector<std::size_t>                 send_offsets;
    mutable std::vector<double>              send_values;
    std::vector<unsigned int>                receive_ranks;
    std::vector<std::vector<double *>>       receive_targets;
    mutable std::vector<std::vector<double>> receive_values;
  };
} // namespace ImmersedGrains

#endif
