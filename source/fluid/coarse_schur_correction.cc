#include <deal.II/base/mpi.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/dofs/dof_renumbering.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/grid/grid_generator.h>
#include <deal.II/grid/tria.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/trilinos_index_access.h>
#include <deal.II/lac/trilinos_sparsity_pattern.h>

#include <immersed_grains/fluid/coarse_schur_correction.h>
#include <immersed_grains/fluid/trilinos_rows.h>
#include <immersed_grains/mesh/geometry.h>

#include <EpetraExt_MatrixMatrix.h>
#include <EpetraExt_Transpose_RowMatrix.h>
#include <Epetra_CrsMatrix.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <memory>

namespace ImmersedGrains
{
  namespace
  {
    // The coarse DoFs: all on rank 0, where the coarse system is factorised.
    dealii::IndexSet
    owned_by_root(const dealii::types::global_dof_index n, MPI_Comm comm)
    {
      dealii::IndexSet owned(n);
      if (dealii::Utilities::MPI::this_mpi_process(comm) == 0)
        owned.add_range(0, n);
      owned.compress();
      return owned;
    }

    struct Entry
    {
      dealii::types::global_dof_index row, column;
      double                          value;
    };

    // A matrix of the given rows (owned here) and columns from its entries.
    void
    fill(dealii::TrilinosWrappers::SparseMatrix &matrix,
         const dealii::IndexSet                 &rows,
         const dealii::IndexSet                 &columns,
         const std::vector<Entry>               &entries,
         MPI_Comm                                comm)
    {
      dealii::TrilinosWrappers::SparsityPattern pattern(rows, columns, comm);
      for (const Entry &e : entries)
        pattern.add(e.row, e.column);
      pattern.compress();
      matrix.reinit(pattern);
      for (const Entry &e : entries)
        matrix.add(e.row, e.column, e.value);
      matrix.compress(dealii::VectorOperation::add);
    }

    // The rows of @p interpolation where @p weight is not zero: the
    // weighted interpolation diag(W) P without its empty rows, so that the
    // products with it cost only where it has entries. @p interpolation
    // itself where the weight keeps every row.
    const dealii::TrilinosWrappers::SparseMatrix *
    restrict_rows(dealii::TrilinosWrappers::SparseMatrix       &restricted,
                  const dealii::TrilinosWrappers::SparseMatrix &interpolation,
                  const dealii::TrilinosWrappers::MPI::Vector  &weight,
                  MPI_Comm                                      comm)
    {
      bool every_row = true;
      for (const auto i : weight.locally_owned_elements())
        every_row = every_row && weight[i] != 0;
      if (!dealii::Utilities::MPI::logical_or(!every_row, comm))
        return &interpolation;
      std::vector<Entry> entries;
      for_each_owned_row(interpolation.trilinos_matrix(),
                         [&](const auto    row,
                             const auto   &columns,
                             const double *values)
                         {
                           if (weight[row] != 0)
                             for (unsigned int k = 0; k < columns.size(); ++k)
                               entries.push_back({row, columns[k], values[k]});
                         });
      fill(restricted,
           interpolation.locally_owned_range_indices(),
           interpolation.locally_owned_domain_indices(),
           entries,
           comm);
      return &restricted;
    }
  } // namespace


  template <int dim>
  CoarseSchurCorrection::CoarseSchurCorrection(
    const dealii::DoFHandler<dim, dim>      &dof_handler,
    const dealii::AffineConstraints<double> &constraints,
    const Geometry<dim>                     &geometry,
    const unsigned int                       coarse_refinement,
    const std::vector<dealii::IndexSet>     &owned_partitioning,
    MPI_Comm                                 mpi_communicator)
      : mpi_communicator(mpi_communicator)
      , solver_control(1, 0)
  {
    const auto &fe = dof_handler.get_fe();

    // The coarse mesh: the box's own, refined; numbered like the fine one
    // (velocity components, then the pressure).
    dealii::Triangulation<dim> coarse_mesh;
    std::vector<unsigned int>  cells(dim);
    dealii::Tensor<1, dim>     cell_size;
    for (unsigned int d = 0; d < dim; ++d)
    {
      cells[d] = geometry.subdivisions[d] << coarse_refinement;
      cell_size[d] =
        (geometry.upper_corner[d] - geometry.lower_corner[d]) / cells[d];
    }
    dealii::GridGenerator::subdivided_hyper_rectangle(coarse_mesh,
                                                      cells,
                                                      geometry.lower_corner,
                                                      geometry.upper_corner);
    dealii::DoFHandler<dim> coarse_dofs(coarse_mesh);
    coarse_dofs.distribute_dofs(fe);
    std::vector<unsigned int> block_component(dim + 1, 0);
    block_component[dim] = 1;
    dealii::DoFRenumbering::component_wise(coarse_dofs, block_component);
    const auto coarse_per_block =
      dealii::DoFTools::count_dofs_per_fe_block(coarse_dofs, block_component);
    n_coarse_velocities = coarse_per_block[0];
    n_coarse_pressures  = coarse_per_block[1];

    // Coarse cells by their position in the box.
    const auto index_of = [&](const dealii::Point<dim> &x)
    {
      unsigned int index = 0, stride = 1;
      for (unsigned int d = 0; d < dim; ++d)
      {
        const int i = static_cast<int>(
          std::floor((x[d] - geometry.lower_corner[d]) / cell_size[d]));
        index += stride * std::clamp(i, 0, static_cast<int>(cells[d]) - 1);
        stride *= cells[d];
      }
      return index;
    };
    std::vector<typename dealii::DoFHandler<dim>::active_cell_iterator>
      coarse_cell(coarse_mesh.n_active_cells());
    for (const auto &cell : coarse_dofs.active_cell_iterators())
      coarse_cell[index_of(cell->center())] = cell;

    const dealii::IndexSet coarse_velocity_owned =
      owned_by_root(n_coarse_velocities, mpi_communicator);
    const dealii::IndexSet coarse_pressure_owned =
      owned_by_root(n_coarse_pressures, mpi_communicator);
    const unsigned int per_cell = fe.n_dofs_per_cell();
    std::vector<Entry> velocity_entries, pressure_entries;

    // Each owned, unconstrained fine DoF once: the coarse shape functions
    // of its component at its support point.
    const dealii::types::global_dof_index n_u = owned_partitioning[0].size();
    const dealii::IndexSet owned = dof_handler.locally_owned_dofs();
    std::vector<bool>      done(owned.n_elements(), false);
    const auto            &unit_points = fe.get_unit_support_points();
    std::vector<dealii::types::global_dof_index> fine_indices(per_cell),
      coarse_indices(per_cell);
    std::map<std::array<long long, dim + 1>,
             std::vector<std::pair<unsigned int, double>>>
      shape_values;
    for (const auto &cell : dof_handler.active_cell_iterators())
    {
      if (!cell->is_locally_owned())
        continue;
      cell->get_dof_indices(fine_indices);
      for (const unsigned int v : cell->vertex_indices())
      {
        const auto p = cell->vertex_dof_index(v, dim);
        if (owned.is_element(p))
          pressure_vertex_velocity[p - n_u] = cell->vertex_dof_index(v, 0);
      }
      const dealii::Point<dim> corner = cell->vertex(0);
      const dealii::Point<dim> far    = cell->vertex((1 << dim) - 1);
      for (unsigned int k = 0; k < per_cell; ++k)
      {
        const auto g = fine_indices[k];
        if (!owned.is_element(g) || constraints.is_constrained(g))
          continue;
        const auto local = owned.index_within_set(g);
        if (done[local])
          continue;
        done[local] = true;

        dealii::Point<dim> x;
        for (unsigned int d = 0; d < dim; ++d)
          x[d] = corner[d] + unit_points[k][d] * (far[d] - corner[d]);
        const auto &coarse = coarse_cell[index_of(x)];
        coarse->get_dof_indices(coarse_indices);
        const dealii::Point<dim> coarse_corner = coarse->vertex(0);
        dealii::Point<dim>       xi;
        for (unsigned int d = 0; d < dim; ++d)
          xi[d] = (x[d] - coarse_corner[d]) / cell_size[d];

        // The same few points recur on every coarse cell: their values are
        // computed once.
        const unsigned int component = fe.system_to_component_index(k).first;
        std::array<long long, dim + 1> key;
        for (unsigned int d = 0; d < dim; ++d)
          key[d] = std::llround(xi[d] * (1 << 20));
        key[dim]   = component;
        auto known = shape_values.find(key);
        if (known == shape_values.end())
        {
          std::vector<std::pair<unsigned int, double>> values;
          for (unsigned int j = 0; j < per_cell; ++j)
            if (fe.system_to_component_index(j).first == component)
            {
              const double value = fe.shape_value(j, xi);
              if (std::abs(value) > 1e-12)
                values.emplace_back(j, value);
            }
          known = shape_values.emplace(key, std::move(values)).first;
        }
        for (const auto &[j, value] : known->second)
        {
          const auto J = coarse_indices[j];
          if (component < dim)
            velocity_entries.push_back({g, J, value});
          else
            pressure_entries.push_back(
              {g - n_u, J - n_coarse_velocities, value});
        }
      }
    }
    fill(velocity_interpolation,
         owned_partitioning[0],
         coarse_velocity_owned,
         velocity_entries,
         mpi_communicator);
    fill(pressure_interpolation,
         owned_partitioning[1],
         coarse_pressure_owned,
         pressure_entries,
         mpi_communicator);

    coarse_pressure.reinit(coarse_pressure_owned, mpi_communicator);
    coarse_velocity.reinit(coarse_velocity_owned, mpi_communicator);
    const dealii::IndexSet coarse_owned =
      owned_by_root(n_coarse_velocities + n_coarse_pressures, mpi_communicator);
    coarse_rhs.reinit(coarse_owned, mpi_communicator);
    coarse_solution.reinit(coarse_owned, mpi_communicator);
    fine_velocity.reinit(owned_partitioning[0], mpi_communicator);
    dealii::IndexSet needed(n_u);
    for (const auto &pair : pressure_vertex_velocity)
      needed.add_index(pair.second);
    needed.add_indices(owned_partitioning[0]);
    needed.compress();
    drag_share_ghosted.reinit(owned_partitioning[0], needed, mpi_communicator);
    viscous_weight.reinit(owned_partitioning[0], mpi_communicator);
    drag_weight.reinit(owned_partitioning[0], mpi_communicator);
    pressure_weight.reinit(owned_partitioning[1], mpi_communicator);
  }


  CoarseSchurCorrection::~CoarseSchurCorrection() = default;


  void
  CoarseSchurCorrection::build(
    const dealii::TrilinosWrappers::BlockSparseMatrix &system_matrix,
    const dealii::TrilinosWrappers::MPI::Vector       &drag_share,
    const bool                                         pin_pressure)
  {
    pinned = pin_pressure;
    // A fine velocity belongs to the viscous part where mass and drag are
    // less than half of A's diagonal, to the drag part elsewhere.
    bool any_drag = false;
    for (const auto i : drag_share.locally_owned_elements())
    {
      const bool viscous = drag_share[i] < 0.5;
      viscous_weight[i]  = viscous ? 1.0 : 0.0;
      drag_weight[i]     = viscous ? 0.0 : 1.0;
      any_drag           = any_drag || !viscous;
    }
    viscous_weight.compress(dealii::VectorOperation::insert);
    drag_weight.compress(dealii::VectorOperation::insert);
    split_velocities =
      dealii::Utilities::MPI::logical_or(any_drag, mpi_communicator);
    n_velocity_rows = (split_velocities ? 2 : 1) * n_coarse_velocities;
    // A pressure node counts unless drag is more than 999 times the
    // viscous part of the diagonal at its vertex: there the pressure
    // is held by a mobility 1/beta far below the flow's around it, and
    // the coarse system's pressure modes inside such a region only add
    // error (doc/adaptivity.md).
    drag_share_ghosted = drag_share;
    for (const auto &pair : pressure_vertex_velocity)
      pressure_weight[pair.first] =
        drag_share_ghosted[pair.second] < 0.999 ? 1.0 : 0.0;
    pressure_weight.compress(dealii::VectorOperation::insert);

    // The coarse fields: the viscous part W P_u, the drag part
    // (I - W) P_u where there is drag, the pressure W_p P_p.
    velocity_part[0] = restrict_rows(restricted_velocity[0],
                                     velocity_interpolation,
                                     viscous_weight,
                                     mpi_communicator);
    if (split_velocities)
      velocity_part[1] = restrict_rows(restricted_velocity[1],
                                       velocity_interpolation,
                                       drag_weight,
                                       mpi_communicator);
    pressure_part = restrict_rows(restricted_pressure,
                                  pressure_interpolation,
                                  pressure_weight,
                                  mpi_communicator);
    struct Field
    {
      const dealii::TrilinosWrappers::SparseMatrix *interpolation;
      unsigned int                                  block;
      dealii::types::global_dof_index               offset;
    };
    std::vector<Field> fields = {{velocity_part[0], 0, 0}};
    if (split_velocities)
      fields.push_back({velocity_part[1], 0, n_coarse_velocities});
    fields.push_back({pressure_part, 1, n_velocity_rows});
    const dealii::IndexSet coarse_owned =
      owned_by_root(n_velocity_rows + n_coarse_pressures, mpi_communicator);
    if (coarse_rhs.size() != n_velocity_rows + n_coarse_pressures)
    {
      coarse_rhs.reinit(coarse_owned, mpi_communicator);
      coarse_solution.reinit(coarse_owned, mpi_communicator);
    }
    // The transposed interpolations, made explicitly. EpetraExt's product
    // with a transposed left factor, P^T (A P) with every coarse row on
    // rank 0, gave on two ranks row lengths that added up to more entries
    // than the result held (the last row's negative): the coarse drag
    // block was read from overlapping rows, 0.4 % off the serial one.
    std::vector<std::unique_ptr<EpetraExt::RowMatrix_Transpose>> transposers;
    std::vector<const Epetra_CrsMatrix *>                        transposed;
    for (const Field &f : fields)
    {
      transposers.push_back(std::make_unique<EpetraExt::RowMatrix_Transpose>());
      transposed.push_back(
        &dynamic_cast<const Epetra_CrsMatrix &>((*transposers.back())(
          const_cast<Epetra_CrsMatrix &>(f.interpolation->trilinos_matrix()))));
    }
    std::vector<Entry> entries;
    for (unsigned int a = 0; a < fields.size(); ++a)
      for (const Field &fj : fields)
      {
        const Field &fi = fields[a];
        // EpetraExt directly: deal.II's mmult copies the result into a new
        // matrix, which overran its storage on two ranks where the
        // restricted interpolation has no rows on one of them.
        const Epetra_CrsMatrix &fine =
          system_matrix.block(fi.block, fj.block).trilinos_matrix();
        const Epetra_CrsMatrix &left  = *transposed[a];
        const Epetra_CrsMatrix &right = fj.interpolation->trilinos_matrix();
        Epetra_CrsMatrix        product(Copy, fine.RowMap(), 0);
        Epetra_CrsMatrix        m(Copy, left.RowMap(), 0);
        AssertThrow(EpetraExt::MatrixMatrix::Multiply(
                      fine, false, right, false, product) == 0 &&
                      EpetraExt::MatrixMatrix::Multiply(
                        left, false, product, false, m) == 0,
                    dealii::ExcMessage("coarse correction: a sparse matrix "
                                       "product failed"));
        for_each_owned_row(
          m,
          [&](const auto row, const auto &columns, const double *values)
          {
            if (pin_pressure && row + fi.offset == n_velocity_rows)
              return;
            for (unsigned int k = 0; k < columns.size(); ++k)
              entries.push_back(
                {row + fi.offset, columns[k] + fj.offset, values[k]});
          });
      }
    // Coarse velocities without a function (no fine DoF sees them, or the
    // weight removed them: no diagonal), then pressures left without a
    // velocity or a diagonal of their own.
    empty.assign(n_velocity_rows + n_coarse_pressures, false);
    for (const auto i : coarse_owned)
      empty[i] = true;
    for (const Entry &e : entries)
      if (e.value != 0 && e.row == e.column && e.row < n_velocity_rows)
        empty[e.row] = false;
    for (const Entry &e : entries)
      if (e.value != 0 && e.row >= n_velocity_rows &&
          (e.row == e.column ||
           (e.column < n_velocity_rows && !empty[e.column])))
        empty[e.row] = false;
    // Where the weights leave more coarse pressures in a region than its
    // velocities can tell apart, S_H is singular: a shift of 10^-8 of a
    // local estimate of its diagonal, sum_j B_ij^2 / A_jj, on the pressure
    // block makes the system regular without touching the modes it does
    // resolve.
    std::vector<double> velocity_diagonal(n_velocity_rows, 0.0),
      schur_diagonal(n_coarse_pressures, 0.0);
    for (const Entry &e : entries)
      if (e.row == e.column && e.row < n_velocity_rows)
        velocity_diagonal[e.row] = e.value;
    // The weights can leave two coarse velocity functions the same fine
    // function (where they keep a single fine node of both): A_H is then
    // singular in a combination whose fine image is zero. A relative shift
    // of its diagonal makes it regular without changing any fine value.
    for (unsigned int i = 0; i < n_velocity_rows; ++i)
      if (velocity_diagonal[i] > 0)
        entries.push_back({i, i, 1e-6 * velocity_diagonal[i]});
    for (const Entry &e : entries)
      if (e.row >= n_velocity_rows && e.column < n_velocity_rows &&
          velocity_diagonal[e.column] > 0)
        schur_diagonal[e.row - n_velocity_rows] +=
          e.value * e.value / velocity_diagonal[e.column];
    for (unsigned int i = 0; i < n_coarse_pressures; ++i)
      if (schur_diagonal[i] > 0)
        entries.push_back({n_velocity_rows + i,
                           n_velocity_rows + i,
                           -1e-8 * schur_diagonal[i]});
    entries.erase(std::remove_if(entries.begin(),
                                 entries.end(),
                                 [&](const Entry &e)
                                 { return empty[e.row] || empty[e.column]; }),
                  entries.end());
    // Identity rows where a coarse DoF has no operator, and for the pinned
    // pressure.
    for (const auto i : coarse_owned)
      if (empty[i] || (pin_pressure && i == n_velocity_rows))
        entries.push_back({i, i, 1.0});
    fill(coarse_matrix, coarse_owned, coarse_owned, entries, mpi_communicator);

    coarse_solver = std::make_unique<dealii::TrilinosWrappers::SolverDirect>(
      solver_control,
      dealii::TrilinosWrappers::SolverDirect::AdditionalData(false,
                                                             "Amesos_Klu"));
    coarse_solver->initialize(coarse_matrix);
  }


  void
  CoarseSchurCorrection::vmult(
    dealii::TrilinosWrappers::MPI::BlockVector       &dst,
    const dealii::TrilinosWrappers::MPI::BlockVector &src) const
  {
    const unsigned int parts = split_velocities ? 2 : 1;
    for (unsigned int part = 0; part < parts; ++part)
    {
      velocity_part[part]->Tvmult(coarse_velocity, src.block(0));
      const auto offset = part * n_coarse_velocities;
      for (const auto i : coarse_velocity.locally_owned_elements())
        coarse_rhs[offset + i] = empty[offset + i] ? 0.0 : coarse_velocity[i];
    }
    pressure_part->Tvmult(coarse_pressure, src.block(1));
    for (const auto i : coarse_pressure.locally_owned_elements())
      coarse_rhs[n_velocity_rows + i] =
        empty[n_velocity_rows + i] || (pinned && i == 0) ? 0.0 :
                                                           coarse_pressure[i];
    coarse_rhs.compress(dealii::VectorOperation::insert);
    coarse_solver->solve(coarse_solution, coarse_rhs);
    for (unsigned int part = 0; part < parts; ++part)
    {
      const auto offset = part * n_coarse_velocities;
      for (const auto i : coarse_velocity.locally_owned_elements())
        coarse_velocity[i] = coarse_solution[offset + i];
      coarse_velocity.compress(dealii::VectorOperation::insert);
      if (part == 0)
        velocity_part[part]->vmult(dst.block(0), coarse_velocity);
      else
      {
        velocity_part[part]->vmult(fine_velocity, coarse_velocity);
        dst.block(0) += fine_velocity;
      }
    }
    for (const auto i : coarse_pressure.locally_owned_elements())
      coarse_pressure[i] = coarse_solution[n_velocity_rows + i];
    coarse_pressure.compress(dealii::VectorOperation::insert);
    pressure_part->vmult(dst.block(1), coarse_pressure);
  }


  template CoarseSchurCorrection::CoarseSchurCorrection(
    const dealii::DoFHandler<2, 2> &,
    const dealii::AffineConstraints<double> &,
    const Geometry<2> &,
    unsigned int,
    const std::vector<dealii::IndexSet> &,
    MPI_Comm);
  template CoarseSchurCorrection::CoarseSchurCorrection(
    const dealii::DoFHandler<3, 3> &,
    const dealii::AffineConstraints<double> &,
    const Geometry<3> &,
    unsigned int,
    const std::vector<dealii::IndexSet> &,
    MPI_Comm);
} // namespace ImmersedGrains
