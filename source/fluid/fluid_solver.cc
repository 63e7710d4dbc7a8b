#include <algorithm>
#include <array>
#include <limits>
#include <set>
#include <sstream>

#include <deal.II/base/qprojector.h>
#include <deal.II/base/quadrature_lib.h>
#include <deal.II/dofs/dof_renumbering.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_q.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/lac/sparsity_tools.h>
#include <deal.II/lac/trilinos_sparsity_pattern.h>
#include <deal.II/numerics/data_postprocessor.h>
#include <deal.II/numerics/vector_tools.h>

#include <immersed_grains/fluid/assembly_terms.h>
#include <immersed_grains/fluid/block_preconditioner.h>
#include <immersed_grains/fluid/cell_gather.h>
#include <immersed_grains/fluid/cell_scatter.h>
#include <immersed_grains/fluid/coarse_schur_correction.h>
#include <immersed_grains/fluid/fluid_solver.h>
#include <immersed_grains/io/statistics.h>
#include <immersed_grains/parameters.h>

namespace ImmersedGrains
{
  namespace
  {
    // A velocity function as the first dim components of a (u, p) field.
    template <int dim>
    class VelocityOfSystem : public dealii::Function<dim>
    {
    public:
      explicit VelocityOfSystem(const dealii::Function<dim> &velocity)
          : dealii::Function<dim>(dim + 1)
          , velocity(velocity)
      {
      }

      double
      value(const dealii::Point<dim> &p, const unsigned int c) const override
      {
        return c < dim ? velocity.value(p, c) : 0.0;
      }

    private:
      const dealii::Function<dim> &velocity;
    };


    // Renumbers the Taylor-Hood DoFs in the Cuthill-McKee order of the
    // scalar Q2 nodes, each node's velocity components (and pressure, at a
    // vertex) together. This is the order a Cuthill-McKee numbering of the
    // whole system gives, which the velocity block's ILU and AMG need (3D
    // cloud, first steps: 14, 12, 8, 7, 6 outer iterations against 17, 15,
    // 10, 8, 8 unordered and 16, 15, 9, 8, 7 with the cells ordered by their
    // face graph), from a graph about ten times smaller: the graph of the
    // whole system held all components' couplings, about 400 entries per
    // row in 3D, and its reordering was a fifth of the 3D cloud's first
    // steps.
    template <int dim>
    void
    renumber_by_node_cuthill_mckee(dealii::DoFHandler<dim> &dof_handler)
    {
      using dealii::types::global_dof_index;
      const auto &fe = dof_handler.get_fe();
      Assert(fe.n_base_elements() == 2 && fe.base_element(0).degree == 2,
             dealii::ExcInternalError());
      dealii::DoFHandler<dim> nodes(dof_handler.get_triangulation());
      nodes.distribute_dofs(fe.base_element(0));
      std::vector<global_dof_index> node_number(nodes.n_locally_owned_dofs());
      dealii::DoFRenumbering::compute_Cuthill_McKee(node_number, nodes);
      const dealii::IndexSet &owned_nodes = nodes.locally_owned_dofs();

      // Sorted by (node's number, component); a DoF whose node another rank
      // owns (not expected: both handlers give a DoF to the same cell's
      // owner) goes last, in its old order.
      const dealii::IndexSet &owned = dof_handler.locally_owned_dofs();
      std::vector<std::pair<global_dof_index, global_dof_index>> keys(
        owned.n_elements());
      for (unsigned int i = 0; i < keys.size(); ++i)
        keys[i] = {std::numeric_limits<global_dof_index>::max(), i};
      std::vector<global_dof_index> dofs(fe.n_dofs_per_cell()),
        node_dofs(nodes.get_fe().n_dofs_per_cell());
      for (const auto &cell : dof_handler.active_cell_iterators())
        if (cell->is_locally_owned())
        {
          cell->get_dof_indices(dofs);
          typename dealii::DoFHandler<dim>::active_cell_iterator(
            &cell->get_triangulation(), cell->level(), cell->index(), &nodes)
            ->get_dof_indices(node_dofs);
          for (unsigned int i = 0; i < dofs.size(); ++i)
          {
            if (!owned.is_element(dofs[i]))
              continue;
            // Q1 and Q2 both number their vertex functions first, vertex
            // by vertex, so a pressure function's index is its vertex's.
            const auto [component, node] = fe.system_to_component_index(i);
            if (!owned_nodes.is_element(node_dofs[node]))
              continue;
            keys[owned.index_within_set(dofs[i])].first =
              node_number[owned_nodes.index_within_set(node_dofs[node])] *
                (dim + 1) +
              component;
          }
        }
      std::sort(keys.begin(), keys.end());
      std::vector<global_dof_index> new_numbers(keys.size());
      for (unsigned int k = 0; k < keys.size(); ++k)
        new_numbers[keys[k].second] = owned.nth_index_in_set(k);
      dof_handler.renumber_dofs(new_numbers);
    }


    // Evaluates the mixture fields at output points, so that what is written
    // is what the solver used.
    template <int dim>
    class MixtureFieldsOutput : public dealii::DataPostprocessor<dim>
    {
    public:
      MixtureFieldsOutput(const MixtureFields<dim>   &fields,
                          const double                time,
                          const dealii::Mapping<dim> &mapping)
          : fields(fields)
          , time(time)
          , mapping(mapping)
      {
      }

      void
      evaluate_vector_field(
        const dealii::DataPostprocessorInputs::Vector<dim> &inputs,
        std::vector<dealii::Vector<double>> &computed) const override
      {
        const auto                      cell = inputs.template get_cell<dim>();
        MixtureValues<dim>              values;
        std::vector<dealii::Point<dim>> reference(
          inputs.evaluation_points.size());
        for (unsigned int q = 0; q < reference.size(); ++q)
          reference[q] =
            mapping.transform_real_to_unit_cell(cell,
                                                inputs.evaluation_points[q]);
        fields.evaluate(
          cell, inputs.evaluation_points, reference, time, values);
        for (unsigned int q = 0; q < computed.size(); ++q)
        {
          computed[q](0) = values.fluid_fraction[q];
          computed[q](1) = values.drag_coefficient[q];
        }
      }

      std::vector<std::string>
      get_names() const override
      {
        return {"fluid_fraction", "drag_coefficient"};
      }

      dealii::UpdateFlags
      get_needed_update_flags() const override
      {
        return dealii::update_quadrature_points;
      }

    private:
      const MixtureFields<dim>   &fields;
      const double                time;
      const dealii::Mapping<dim> &mapping;
    };
  } // namespace


  template <int dim>
  FluidSolver<dim>::FluidSolver(
    const FluidParameters<dim>                        &parameters,
    const Geometry<dim>                               &geometry,
    dealii::parallel::distributed::Triangulation<dim> &triangulation,
    dealii::TimerOutput                               &timer,
    dealii::ConditionalOStream                        &pcout)
      : parameters(parameters)
      , geometry(geometry)
      , triangulation(triangulation)
      , timer(timer)
      , pcout(pcout)
      , mpi_communicator(triangulation.get_communicator())
      , fe(dealii::FE_Q<dim>(2), dim, dealii::FE_Q<dim>(1), 1)
      , dof_handler(triangulation)
      , mapping(geometry.mapping())
      , velocity_shapes(fe.base_element(0))
      , pressure_shapes(fe.base_element(1))
      , forcing(
          [&]() -> std::shared_ptr<dealii::Function<dim>>
          {
            if (!parameters.forcing_is_constant)
              return parameters.forcing;
            dealii::Vector<double> value(dim);
            parameters.forcing->vector_value(dealii::Point<dim>(), value);
            return std::make_shared<dealii::Functions::ConstantFunction<dim>>(
              value);
          }())
      , boundary_velocity(parameters.boundary_velocity)
  {
    {
      const dealii::QGauss<dim> quadrature(fe.degree + 1);
      const auto               &scalar = fe.base_element(0);
      cell_mean_weights.assign(scalar.n_dofs_per_cell(), 0.0);
      for (unsigned int i = 0; i < scalar.n_dofs_per_cell(); ++i)
        for (unsigned int q = 0; q < quadrature.size(); ++q)
          cell_mean_weights[i] +=
            quadrature.weight(q) * scalar.shape_value(i, quadrature.point(q));
    }
    if (parameters.forcing_is_constant)
    {
      dealii::Vector<double> value(dim);
      forcing->vector_value(dealii::Point<dim>(), value);
      forcing_is_zero = value.linfty_norm() == 0;
    }
    mixture_fields = std::make_shared<PrescribedMixtureFields<dim>>(
      parameters.fluid_fraction,
      parameters.drag_coefficient,
      parameters.grain_velocity);
  }


  template <int dim>
  FluidSolver<dim>::~FluidSolver() = default;


  template <int dim>
  void
  FluidSolver<dim>::set_mixture_fields(
    std::shared_ptr<const MixtureFields<dim>> fields,
    const bool                                solid_crosses_boundaries)
  {
    mixture_fields                 = fields;
    fields_prescribed              = false;
    this->solid_crosses_boundaries = solid_crosses_boundaries;
  }


  template <int dim>
  void
  FluidSolver<dim>::set_point_drag_source(
    std::shared_ptr<const PointDragSource<dim>> source,
    const bool                                  cell_averaged)
  {
    point_drag_source  = source;
    cell_averaged_drag = cell_averaged;
  }


  template <int dim>
  std::vector<typename FluidSolver<dim>::PointValues>
  FluidSolver<dim>::point_values(
    const typename dealii::Triangulation<dim>::active_cell_iterator &tria_cell,
    const std::vector<dealii::Point<dim>> &reference_locations) const
  {
    const typename dealii::DoFHandler<dim>::active_cell_iterator cell(
      &triangulation, tria_cell->level(), tria_cell->index(), &dof_handler);
    // The cell's coefficients, read once (each read through the global
    // index is a look-up in Epetra's map).
    std::vector<double> local(fe.n_dofs_per_cell());
    if (!cell_gather->gather(cell, solution, local))
    {
      std::vector<dealii::types::global_dof_index> indices(
        fe.n_dofs_per_cell());
      cell->get_dof_indices(indices);
      for (unsigned int i = 0; i < indices.size(); ++i)
        local[i] = solution(indices[i]);
    }
    // The scalar Q2 (velocity) and Q1 (pressure) functions at the points:
    // one pass over each, no FEValues set up per call. With the cell drag
    // the velocity is the cell mean, the same at every point.
    const bool at_points = !cell_averaged_drag;
    if (at_points)
      velocity_shapes.reinit(cell, reference_locations, false);
    pressure_shapes.reinit(cell, reference_locations, true);
    std::vector<PointValues> values(reference_locations.size());
    dealii::Tensor<1, dim>   mean;
    for (unsigned int i = 0; i < fe.n_dofs_per_cell(); ++i)
    {
      const double coefficient      = local[i];
      const auto [component, index] = fe.system_to_component_index(i);
      if (component == dim)
        for (unsigned int q = 0; q < values.size(); ++q)
          values[q].pressure_gradient +=
            coefficient * pressure_shapes.gradient(index, q);
      else if (at_points)
        for (unsigned int q = 0; q < values.size(); ++q)
          values[q].velocity[component] +=
            coefficient * velocity_shapes.value(index, q);
      else
        mean[component] += coefficient * cell_mean_weights[index];
    }
    if (!at_points)
      for (auto &v : values)
        v.velocity = mean;
    return values;
  }


  template <int dim>
  std::vector<std::pair<typename dealii::DoFHandler<dim>::active_cell_iterator,
                        dealii::Point<dim>>>
  FluidSolver<dim>::owned_cells_around(const dealii::Point<dim> &point) const
  {
    // Through the mapping with a tolerance, not CellAccessor::point_inside():
    // that tests the exact unit cell after MappingQ1's inverse, which
    // refuses a point on a vertex or a face of a curved or skewed cell from
    // every side (a probe there read 0).
    std::vector<
      std::pair<typename dealii::DoFHandler<dim>::active_cell_iterator,
                dealii::Point<dim>>>
      around;
    for (const auto &cell : dof_handler.active_cell_iterators())
      if (cell->is_locally_owned())
      {
        if (!cell_search_box(*cell).point_inside(point))
          continue;
        try
        {
          const dealii::Point<dim> reference =
            mapping.transform_real_to_unit_cell(cell, point);
          if (dealii::GeometryInfo<dim>::is_inside_unit_cell(reference, 1e-10))
            around.emplace_back(cell, reference);
        }
        catch (const typename dealii::Mapping<dim>::ExcTransformationFailed &)
        {
          // Far outside this cell.
        }
      }
    return around;
  }


  template <int dim>
  double
  FluidSolver<dim>::pressure_at(const dealii::Point<dim> &point) const
  {
    double sum = 0, count = 0;
    for (const auto &[cell, reference] : owned_cells_around(point))
    {
      const dealii::Quadrature<dim> one_point(reference);
      dealii::FEValues<dim>         fe_values(mapping,
                                      fe,
                                      one_point,
                                      dealii::update_values);
      fe_values.reinit(cell);
      std::vector<double> value(1);
      fe_values[dealii::FEValuesExtractors::Scalar(dim)].get_function_values(
        solution, value);
      sum += value[0];
      count += 1;
    }
    sum   = dealii::Utilities::MPI::sum(sum, mpi_communicator);
    count = dealii::Utilities::MPI::sum(count, mpi_communicator);
    return count > 0 ? sum / count : 0.0;
  }


  template <int dim>
  double
  FluidSolver<dim>::fluid_fraction_at(const dealii::Point<dim> &point) const
  {
    double             sum = 0, count = 0;
    MixtureValues<dim> values;
    for (const auto &[cell, reference] : owned_cells_around(point))
    {
      mixture_fields->evaluate(cell, {point}, {reference}, time, values);
      sum += values.fluid_fraction[0];
      count += 1;
    }
    sum   = dealii::Utilities::MPI::sum(sum, mpi_communicator);
    count = dealii::Utilities::MPI::sum(count, mpi_communicator);
    return count > 0 ? sum / count : 1.0;
  }


  template <int dim>
  void
  FluidSolver<dim>::integrate_over_boundary(
    const dealii::types::boundary_id                       id,
    const dealii::UpdateFlags                              flags,
    const std::function<void(const dealii::FEFaceValues<dim> &,
                             const MixtureValues<dim> &)> &add_face) const
  {
    const dealii::QGauss<dim - 1> face_quadrature(fe.degree + 1);
    dealii::FEFaceValues<dim>     fe_face_values(
      mapping,
      fe,
      face_quadrature,
      flags | dealii::update_normal_vectors | dealii::update_JxW_values |
        dealii::update_quadrature_points);
    std::vector<dealii::Point<dim>> reference(face_quadrature.size());
    MixtureValues<dim>              mixture;
    for (const auto &cell : dof_handler.active_cell_iterators())
      if (cell->is_locally_owned() && cell->at_boundary())
        for (const unsigned int f : cell->face_indices())
          if (cell->at_boundary(f) && cell->face(f)->boundary_id() == id)
          {
            fe_face_values.reinit(cell, f);
            // The face's points in the cell's reference coordinates, for
            // the fluid fraction there.
            const auto on_face = dealii::QProjector<dim>::project_to_face(
              dealii::ReferenceCells::get_hypercube<dim>(), face_quadrature, f);
            for (unsigned int q = 0; q < reference.size(); ++q)
              reference[q] = on_face.point(q);
            mixture_fields->evaluate(cell,
                                     fe_face_values.get_quadrature_points(),
                                     reference,
                                     time,
                                     mixture);
            add_face(fe_face_values, mixture);
          }
  }


  template <int dim>
  std::vector<dealii::Tensor<1, dim>>
  FluidSolver<dim>::boundary_forces(
    const std::vector<dealii::types::boundary_id> &ids)
  {
    // The residual's rows are -R(u_h; v), and for v a face's shape
    // function R(u_h; v) is the integral of phi sigma n . v over the faces
    // (the term the weak form leaves out where the velocity is given):
    // the reaction, with the sign of the force on the boundary. Where the
    // id's faces meet another boundary whose velocity is given, the DoFs
    // of the corners carry that boundary's reaction too (3 % of the force
    // on the floor of tilted_channel_poiseuille_2d): there the traction is
    // integrated.
    const dealii::FEValuesExtractors::Vector velocities(0);
    const dealii::ComponentMask          mask = fe.component_mask(velocities);
    std::set<dealii::types::boundary_id> given;
    for (const auto type :
         {BoundaryType::wall, BoundaryType::slip, BoundaryType::velocity})
      for (const auto id : geometry.boundary_ids(type))
        given.insert(id);
    std::vector<dealii::Tensor<1, dim>> forces(ids.size());
    BoundaryReactions                   reactions;
    std::vector<unsigned int>           by_reaction;
    for (unsigned int k = 0; k < ids.size(); ++k)
    {
      dealii::IndexSet on_id =
        dealii::DoFTools::extract_boundary_dofs(dof_handler, mask, {ids[k]});
      std::set<dealii::types::boundary_id> others = given;
      others.erase(ids[k]);
      const bool meets_others =
        !others.empty() &&
        dealii::Utilities::MPI::max(
          static_cast<int>(!(on_id & dealii::DoFTools::extract_boundary_dofs(
                                       dof_handler, mask, others))
                              .is_empty()),
          mpi_communicator) > 0;
      if (meets_others)
        forces[k] = traction_force(ids[k]);
      else
      {
        reactions.dofs.push_back(std::move(on_id));
        by_reaction.push_back(k);
      }
    }
    if (!by_reaction.empty())
    {
      reactions.sums.resize(by_reaction.size());
      assemble_system(false, &reactions);
      for (unsigned int j = 0; j < by_reaction.size(); ++j)
        forces[by_reaction[j]] = reactions.sums[j];
    }
    return forces;
  }


  template <int dim>
  dealii::Tensor<1, dim>
  FluidSolver<dim>::traction_force(const dealii::types::boundary_id id) const
  {
    const dealii::FEValuesExtractors::Vector velocities(0);
    const dealii::FEValuesExtractors::Scalar pressure(dim);
    const double                             mu = parameters.viscosity;
    std::vector<dealii::Tensor<2, dim>>      grad_u;
    std::vector<double>                      p;
    dealii::Tensor<1, dim>                   force;
    integrate_over_boundary(
      id,
      dealii::update_values | dealii::update_gradients,
      [&](const dealii::FEFaceValues<dim> &values,
          const MixtureValues<dim>        &mixture)
      {
        grad_u.resize(values.n_quadrature_points);
        p.resize(values.n_quadrature_points);
        values[velocities].get_function_gradients(solution, grad_u);
        values[pressure].get_function_values(solution, p);
        for (unsigned int q = 0; q < values.n_quadrature_points; ++q)
        {
          const auto stress = -p[q] * dealii::unit_symmetric_tensor<dim>() +
                              mu * (grad_u[q] + transpose(grad_u[q]));
          force -= mixture.fluid_fraction[q] *
                   (stress * values.normal_vector(q)) * values.JxW(q);
        }
      });
    return dealii::Utilities::MPI::sum(force, mpi_communicator);
  }


  template <int dim>
  double
  FluidSolver<dim>::boundary_flux(const dealii::types::boundary_id id) const
  {
    const dealii::FEValuesExtractors::Vector velocities(0);
    std::vector<dealii::Tensor<1, dim>>      u;
    double                                   flux = 0;
    integrate_over_boundary(
      id,
      dealii::update_values,
      [&](const dealii::FEFaceValues<dim> &values,
          const MixtureValues<dim>        &mixture)
      {
        u.resize(values.n_quadrature_points);
        values[velocities].get_function_values(solution, u);
        for (unsigned int q = 0; q < values.n_quadrature_points; ++q)
          flux += mixture.fluid_fraction[q] * (u[q] * values.normal_vector(q)) *
                  values.JxW(q);
      });
    return dealii::Utilities::MPI::sum(flux, mpi_communicator);
  }


  template <int dim>
  void
  FluidSolver<dim>::set_forcing(std::shared_ptr<dealii::Function<dim>> f)
  {
    forcing         = f;
    forcing_is_zero = false;
  }


  template <int dim>
  void
  FluidSolver<dim>::set_boundary_velocity(
    std::shared_ptr<dealii::Function<dim>> velocity)
  {
    boundary_velocity = velocity;
  }


  template <int dim>
  void
  FluidSolver<dim>::setup_dofs()
  {
    dealii::TimerOutput::Scope scope(timer, "fluid: setup");
    // The preconditioner refers to the matrices about to be rebuilt.
    preconditioner.reset();
    coarse_schur.reset();

    dof_handler.distribute_dofs(fe);
    renumber_by_node_cuthill_mckee(dof_handler);
    std::vector<unsigned int> block_component(dim + 1, 0);
    block_component[dim] = 1;
    dealii::DoFRenumbering::component_wise(dof_handler, block_component);

    const auto dofs_per_block =
      dealii::DoFTools::count_dofs_per_fe_block(dof_handler, block_component);
    const auto n_u = dofs_per_block[0], n_p = dofs_per_block[1];

    const dealii::IndexSet owned = dof_handler.locally_owned_dofs();
    dealii::IndexSet       relevant;
    dealii::DoFTools::extract_locally_relevant_dofs(dof_handler, relevant);
    owned_partitioning    = {owned.get_view(0, n_u),
                             owned.get_view(n_u, n_u + n_p)};
    relevant_partitioning = {relevant.get_view(0, n_u),
                             relevant.get_view(n_u, n_u + n_p)};

    make_constraints();

    // The system couples everything (pressure with pressure through the
    // grains' pressure mobility, doc/theory.md 3); the preconditioner's
    // pressure mass matrix only pressure with pressure.
    dealii::Table<2, dealii::DoFTools::Coupling> system_coupling;
    const auto                                   make_matrix =
      [&](const bool                               pressure_only,
          const dealii::AffineConstraints<double> &constraints,
          MatrixType                              &matrix)
    {
      // Velocity components couple only with themselves except through
      // Newton's derivative of the advection term (slip constraints that
      // tie components together are added by make_sparsity_pattern): the
      // entries between different components would be stored zeros, a
      // third of the velocity block in 2D and two thirds in 3D, which every
      // product, ILU sweep and AMG set-up would carry.
      const bool cross_components = velocity_components_coupled();
      dealii::Table<2, dealii::DoFTools::Coupling> coupling(dim + 1, dim + 1);
      for (unsigned int c = 0; c < dim + 1; ++c)
        for (unsigned int d = 0; d < dim + 1; ++d)
        {
          const bool coupled = pressure_only ? (c == dim && d == dim) :
                                               (c == dim || d == dim ||
                                                c == d || cross_components);
          coupling[c][d] =
            coupled ? dealii::DoFTools::always : dealii::DoFTools::none;
        }
      if (!pressure_only)
        system_coupling = coupling;
      dealii::TrilinosWrappers::BlockSparsityPattern sp(owned_partitioning,
                                                        owned_partitioning,
                                                        relevant_partitioning,
                                                        mpi_communicator);
      dealii::DoFTools::make_sparsity_pattern(
        dof_handler,
        coupling,
        sp,
        constraints,
        false,
        dealii::Utilities::MPI::this_mpi_process(mpi_communicator));
      sp.compress();
      matrix.reinit(sp);
    };
    make_matrix(false, update_constraints, system_matrix);
    make_matrix(true, pressure_mass_constraints, pressure_mass_matrix);

    solution.reinit(owned_partitioning,
                    relevant_partitioning,
                    mpi_communicator);
    old_solution.reinit(solution);
    old_old_solution.reinit(solution);
    system_rhs.reinit(owned_partitioning, mpi_communicator);
    reaction_diagonal.reinit(owned_partitioning, mpi_communicator);
    // The two share Epetra's maps with the exchange's import, so that
    // Epetra recognises them at once.
    step_iterate.reinit(owned_partitioning, mpi_communicator);
    newton_update.reinit(step_iterate);
    residual_force.reinit(step_iterate);
    ignore_non_local_entries(residual_force);
    krylov_vectors.clear();
    ghost_exchange.reinit(step_iterate, solution);
    cell_scatter = std::make_unique<CellScatter<dim>>();
    cell_scatter->reinit(dof_handler,
                         system_coupling,
                         update_constraints,
                         system_matrix,
                         system_rhs);
    cell_gather = std::make_unique<CellGather<dim>>();
    cell_gather->reinit(dof_handler, solution);
    {
      // The velocity block's rows of constrained DoFs hold only their
      // diagonal; a slip wall constrains only some components of a node.
      const Epetra_Map &rows =
        system_matrix.block(0, 0).trilinos_matrix().RowMap();
      std::vector<bool> fixed(rows.NumMyElements());
      for (int l = 0; l < rows.NumMyElements(); ++l)
        fixed[l] = update_constraints.is_constrained(rows.GID(l));
      velocity_block = std::make_unique<ComponentBlock>();
      if (!velocity_block->reinit(system_matrix.block(0, 0), dim, fixed))
        velocity_block.reset();
    }

    {
      // Every pressure DoF's own integral, hanging ones included: the
      // pressure vectors hold their distributed values, and the mean is
      // taken over what the cells see.
      dealii::TrilinosWrappers::MPI::Vector integrals;
      integrals.reinit(owned_partitioning[1],
                       relevant_partitioning[1],
                       mpi_communicator,
                       true);
      const dealii::QGauss<dim>                    quadrature(fe.degree + 1);
      dealii::FEValues<dim>                        fe_values(mapping,
                                      fe,
                                      quadrature,
                                      dealii::update_values |
                                        dealii::update_JxW_values);
      std::vector<dealii::types::global_dof_index> indices(
        fe.n_dofs_per_cell());
      double measure = 0;
      for (const auto &cell : dof_handler.active_cell_iterators())
        if (cell->is_locally_owned())
        {
          fe_values.reinit(cell);
          cell->get_dof_indices(indices);
          for (unsigned int q = 0; q < quadrature.size(); ++q)
            measure += fe_values.JxW(q);
          for (unsigned int i = 0; i < fe.n_dofs_per_cell(); ++i)
            if (fe.system_to_component_index(i).first == dim)
              for (unsigned int q = 0; q < quadrature.size(); ++q)
                integrals(indices[i] - n_u) +=
                  fe_values.shape_value(i, q) * fe_values.JxW(q);
        }
      integrals.compress(dealii::VectorOperation::add);
      pressure_shape_integrals.reinit(owned_partitioning[1], mpi_communicator);
      pressure_shape_integrals = integrals;
      domain_measure = dealii::Utilities::MPI::sum(measure, mpi_communicator);
    }
    pcout << "  fluid: "
          << dealii::Utilities::MPI::min(cell_scatter->direct_fraction(),
                                         mpi_communicator) *
               100
          << "% of the cells assembled directly (the lowest rank)" << std::endl;
    preconditioner.reset();
    schur_diagonal_matrix.clear();
  }


  template <int dim>
  void
  FluidSolver<dim>::make_constraints()
  {
    dealii::IndexSet relevant;
    dealii::DoFTools::extract_locally_relevant_dofs(dof_handler, relevant);
    const dealii::FEValuesExtractors::Vector velocities(0);
    const auto velocity_mask = fe.component_mask(velocities);

    std::set<dealii::types::boundary_id> slip_faces;
    for (const auto id : geometry.boundary_ids(BoundaryType::slip))
      slip_faces.insert(id);

    boundary_velocity->set_time(time);
    const VelocityOfSystem<dim>                prescribed(*boundary_velocity);
    const dealii::Functions::ZeroFunction<dim> zero(dim + 1);

    // Same structure, two right-hand sides: the solution carries the
    // boundary data, the update is zero wherever the solution is fixed.
    for (const bool homogeneous : {false, true})
    {
      auto &c = homogeneous ? update_constraints : solution_constraints;
      c.clear();
      c.reinit(relevant);
      dealii::DoFTools::make_hanging_node_constraints(dof_handler, c);
      for (unsigned int d = 0; d < dim; ++d)
        if (geometry.is_periodic(d))
          dealii::DoFTools::make_periodicity_constraints(
            dof_handler,
            geometry.periodic_boundary_ids(d).first,
            geometry.periodic_boundary_ids(d).second,
            d,
            c);
      for (const auto &[f, type] : geometry.boundary_types)
      {
        if (type == BoundaryType::wall)
          dealii::VectorTools::interpolate_boundary_values(
            mapping, dof_handler, f, zero, c, velocity_mask);
        else if (type == BoundaryType::velocity)
          dealii::VectorTools::interpolate_boundary_values(
            mapping,
            dof_handler,
            f,
            homogeneous ? static_cast<const dealii::Function<dim> &>(zero) :
                          prescribed,
            c,
            velocity_mask);
      }
      if (!homogeneous && parameters.superficial_inflow)
        divide_inflow_by_fluid_fraction(c);
      if (!slip_faces.empty())
        dealii::VectorTools::compute_no_normal_flux_constraints(
          dof_handler, 0, slip_faces, c, mapping);
      c.close();
      if (!homogeneous)
        for (const auto &line : c.get_lines())
          max_boundary_speed =
            std::max(max_boundary_speed, std::abs(line.inhomogeneity));
    }

    // The pressure mass matrix only needs the constraints that tie pressure
    // DoFs together.
    pressure_mass_constraints.clear();
    pressure_mass_constraints.reinit(relevant);
    dealii::DoFTools::make_hanging_node_constraints(dof_handler,
                                                    pressure_mass_constraints);
    for (unsigned int d = 0; d < dim; ++d)
      if (geometry.is_periodic(d))
        dealii::DoFTools::make_periodicity_constraints(
          dof_handler,
          geometry.periodic_boundary_ids(d).first,
          geometry.periodic_boundary_ids(d).second,
          d,
          pressure_mass_constraints);
    pressure_mass_constraints.close();
  }


  template <int dim>
  void
  FluidSolver<dim>::divide_inflow_by_fluid_fraction(
    dealii::AffineConstraints<double> &constraints) const
  {
    const auto inflow_ids = geometry.boundary_ids(BoundaryType::velocity);
    const std::vector<dealii::Point<dim>> &unit_points =
      fe.get_unit_support_points();
    std::vector<dealii::types::global_dof_index> dofs(fe.n_dofs_per_cell());
    std::vector<unsigned int>                    on_face;
    std::vector<dealii::Point<dim>>              points, reference;
    MixtureValues<dim>                           mixture;
    std::set<dealii::types::global_dof_index>    divided;
    // Every cell whose DoFs this rank constrains, ghosts included, so that
    // the ranks sharing a DoF divide it by the same (continuous) phi.
    for (const auto &cell : dof_handler.active_cell_iterators())
      if (!cell->is_artificial() && cell->at_boundary())
        for (const unsigned int f : cell->face_indices())
          if (cell->at_boundary(f) &&
              std::find(inflow_ids.begin(),
                        inflow_ids.end(),
                        cell->face(f)->boundary_id()) != inflow_ids.end())
          {
            cell->get_dof_indices(dofs);
            on_face.clear();
            points.clear();
            reference.clear();
            for (unsigned int i = 0; i < dofs.size(); ++i)
              if (fe.system_to_component_index(i).first < dim &&
                  fe.has_support_on_face(i, f) &&
                  constraints.is_inhomogeneously_constrained(dofs[i]) &&
                  constraints.get_constraint_entries(dofs[i])->empty() &&
                  divided.count(dofs[i]) == 0)
              {
                on_face.push_back(i);
                reference.push_back(unit_points[i]);
                points.push_back(
                  mapping.transform_unit_to_real_cell(cell, unit_points[i]));
              }
            if (on_face.empty())
              continue;
            mixture_fields->evaluate(cell, points, reference, time, mixture);
            for (unsigned int k = 0; k < on_face.size(); ++k)
            {
              const auto dof = dofs[on_face[k]];
              constraints.set_inhomogeneity(dof,
                                            constraints.get_inhomogeneity(dof) /
                                              mixture.fluid_fraction[k]);
              divided.insert(dof);
            }
          }
  }


  template <int dim>
  void
  FluidSolver<dim>::set_initial_condition()
  {
    VectorType owned(owned_partitioning, mpi_communicator);
    parameters.initial_velocity->set_time(0);
    dealii::VectorTools::interpolate(mapping,
                                     dof_handler,
                                     VelocityOfSystem<dim>(
                                       *parameters.initial_velocity),
                                     owned);
    solution_constraints.distribute(owned);
    solution          = owned;
    old_solution      = solution;
    old_old_solution  = solution;
    time              = 0;
    steps_done        = 0;
    max_initial_speed = owned.block(0).linfty_norm();
  }


  template <int dim>
  bool
  FluidSolver<dim>::velocity_components_coupled() const
  {
    return parameters.newton && parameters.advection;
  }


  template <int dim>
  bool
  FluidSolver<dim>::pressure_has_null_space() const
  {
    return !geometry.has_open_boundary();
  }


  template <int dim>
  void
  FluidSolver<dim>::normalize_pressure(VectorType &vector) const
  {
    if (!pressure_has_null_space())
      return;
    const double mean =
      (pressure_shape_integrals * vector.block(1)) / domain_measure;
    vector.block(1).add(-mean);
  }


  template <int dim>
  void
  FluidSolver<dim>::prepare_for_mesh_change()
  {
    transfer = std::make_unique<
      dealii::parallel::distributed::SolutionTransfer<dim, VectorType>>(
      dof_handler);
    transfer->prepare_for_coarsening_and_refinement(
      std::vector<const VectorType *>{&solution,
                                      &old_solution,
                                      &old_old_solution});
  }


  template <int dim>
  void
  FluidSolver<dim>::finish_mesh_change()
  {
    Assert(transfer, dealii::ExcMessage("prepare_for_mesh_change() first"));
    setup_dofs();
    std::array<VectorType, 3> owned;
    for (auto &v : owned)
      v.reinit(owned_partitioning, mpi_communicator);
    std::vector<VectorType *> targets = {&owned[0], &owned[1], &owned[2]};
    transfer->interpolate(targets);
    transfer.reset();
    // Only the new hanging nodes: interpolation keeps the boundary values
    // each state had at its own time.
    dealii::IndexSet relevant;
    dealii::DoFTools::extract_locally_relevant_dofs(dof_handler, relevant);
    dealii::AffineConstraints<double> hanging(relevant);
    dealii::DoFTools::make_hanging_node_constraints(dof_handler, hanging);
    hanging.close();
    for (auto &v : owned)
      hanging.distribute(v);
    solution         = owned[0];
    old_solution     = owned[1];
    old_old_solution = owned[2];
  }


  template <int dim>
  void
  FluidSolver<dim>::prepare_for_serialization()
  {
    // Kept until the triangulation is saved: it refers to this object.
    transfer = std::make_unique<
      dealii::parallel::distributed::SolutionTransfer<dim, VectorType>>(
      dof_handler);
    transfer->prepare_for_serialization(std::vector<const VectorType *>{
      &solution, &old_solution, &old_old_solution});
  }


  template <int dim>
  void
  FluidSolver<dim>::deserialize()
  {
    std::array<VectorType, 3> owned;
    for (auto &v : owned)
      v.reinit(owned_partitioning, mpi_communicator);
    std::vector<VectorType *> targets = {&owned[0], &owned[1], &owned[2]};
    dealii::parallel::distributed::SolutionTransfer<dim, VectorType> loader(
      dof_handler);
    loader.deserialize(targets);
    solution         = owned[0];
    old_solution     = owned[1];
    old_old_solution = owned[2];
  }


  template <int dim>
  void
  FluidSolver<dim>::save_state(std::ostream &out) const
  {
    out << std::hexfloat << time << ' ' << dt << ' ' << old_dt << ' '
        << std::dec << steps_done << '\n';
  }


  template <int dim>
  void
  FluidSolver<dim>::load_state(std::istream &in)
  {
    std::string t, d, o;
    in >> t >> d >> o >> steps_done;
    time   = std::strtod(t.c_str(), nullptr);
    dt     = std::strtod(d.c_str(), nullptr);
    old_dt = std::strtod(o.c_str(), nullptr);
  }


  template <int dim>
  typename FluidSolver<dim>::StepStatistics
  FluidSolver<dim>::solve_time_step(const double new_time, const double step)
  {
    // What a failed step gives back: three vector copies, a small part of
    // the step's cost, bought every step so that a failure can be retried.
    const VectorType before = solution, old_before = old_solution,
                     older_before = old_old_solution;
    const double time_before = time, dt_before = dt, old_dt_before = old_dt;
    const unsigned int steps_before = steps_done;
    try
    {
      return advance(new_time, step);
    }
    catch (const std::exception &failure)
    {
      std::string what = failure.what();
      if (const auto *e = dynamic_cast<const dealii::ExceptionBase *>(&failure))
      {
        std::ostringstream info;
        e->print_info(info);
        what = one_line(info.str());
      }
      solution         = before;
      old_solution     = old_before;
      old_old_solution = older_before;
      time             = time_before;
      dt               = dt_before;
      old_dt           = old_dt_before;
      steps_done       = steps_before;
      // Its preconditioner was built for the failed step.
      rebuild_requested = true;
      if (geometry.has_velocity_boundary())
        make_constraints();
      throw FluidStepFailure(what);
    }
  }


  template <int dim>
  typename FluidSolver<dim>::StepStatistics
  FluidSolver<dim>::advance(const double new_time, const double step)
  {
    old_dt = dt;
    dt     = step;
    time   = new_time;

    // BDF weights for (u^{n+1}, u^n, u^{n-1}) / dt, variable step for BDF2.
    const bool   second_order = parameters.bdf_order == 2 && steps_done > 0;
    const double omega        = second_order ? dt / old_dt : 0.0;
    if (!parameters.time_derivative)
      bdf = {{0, 0, 0}};
    else if (second_order)
      bdf = {{(1 + 2 * omega) / (1 + omega),
              -(1 + omega),
              omega * omega / (1 + omega)}};
    else
      bdf = {{1, -1, 0}};

    GhostExchange::copy(old_solution, old_old_solution);
    GhostExchange::copy(solution, old_solution);
    if (geometry.has_open_boundary())
      sample_open_pressure();

    // Start from the extrapolated state and the new boundary data (only
    // velocity faces carry data that depends on time).
    if (geometry.has_velocity_boundary())
    {
      dealii::TimerOutput::Scope scope(timer, "fluid: setup");
      make_constraints();
    }
    VectorType &iterate = step_iterate;
    ghost_exchange.to_owned(old_solution, iterate);
    if (second_order && parameters.time_derivative)
    {
      iterate *= (1 + omega);
      VectorType older(owned_partitioning, mpi_communicator);
      ghost_exchange.to_owned(old_old_solution, older);
      iterate.add(-omega, older);
    }
    ghost_exchange.distribute(solution_constraints, iterate, solution);

    StepStatistics     stats;
    const unsigned int builds_before = builds;
    // One Picard step from the extrapolated state is the semi-implicit
    // scheme: the Oseen operator advected by u* applied to the unknown
    // (the residual at u* is that operator's residual), solved once.
    const bool linear =
      !parameters.advection ||
      (parameters.extrapolated_advection && parameters.time_derivative);
    bool converged = false;
    for (unsigned int k = 0; k < parameters.max_nonlinear_iterations; ++k)
    {
      const bool fresh_preconditioner = preconditioner_due();
      assemble_system(fresh_preconditioner);
      const double residual = system_rhs.l2_norm();
      if (k == 0)
        stats.initial_residual = residual;
      stats.final_residual = residual;
      // A state that already satisfies its system as well as a solve from
      // zero would (Tolerance times the right-hand side b = A x + r) is
      // solved: what is left is round-off. Without this floor a steady
      // state, or a Stokes step whose extrapolation is already exact, was
      // iterated on noise (255 FGMRES iterations in settling_two_way_3d,
      // and the nonlinear iteration could never converge).
      const double rhs_norm = right_hand_side_norm(iterate);
      if (residual <= parameters.linear_tolerance * rhs_norm ||
          (k > 0 && residual <= parameters.nonlinear_tolerance *
                                  std::max(stats.initial_residual, 1e-300)))
      {
        converged = true;
        break;
      }

      stats.linear_iterations += solve_linear_system(
        std::max(0.1 * parameters.nonlinear_tolerance * stats.initial_residual,
                 0.1 * parameters.linear_tolerance * rhs_norm),
        fresh_preconditioner);
      ++stats.nonlinear_iterations;
      ghost_exchange.distribute(update_constraints, newton_update, solution);
      iterate.add(1.0, newton_update);
      ghost_exchange.to_ghosted(iterate, solution);
      if (linear)
      {
        converged = true;
        break;
      }
    }
    stats.drag_averaged_cells   = drag_averaged_cells;
    stats.preconditioner_builds = builds - builds_before;
    AssertThrow(converged,
                dealii::ExcMessage(
                  "Fluid: the nonlinear iteration did not converge in " +
                  std::to_string(parameters.max_nonlinear_iterations) +
                  " iterations (Fluid/Max nonlinear iterations); reduce the "
                  "time step or use Linearization = Newton."));

    normalize_pressure(iterate);
    ghost_exchange.to_ghosted(iterate, solution);
    ++steps_done;
    return stats;
  }


  template <int dim>
  double
  FluidSolver<dim>::mass_coefficient() const
  {
    return parameters.time_derivative && dt > 0 ? bdf[0] / dt : 0.0;
  }


  template <int dim>
  bool
  FluidSolver<dim>::preconditioner_due() const
  {
    if (parameters.direct_solver)
      return false;
    if (!preconditioner || rebuild_requested ||
        parameters.preconditioner_rebuild_ratio == 0)
      return true;
    // The mass term rho a0/dt enters A and both Schur terms; a step size
    // that changes it much makes the old hierarchy a poor one.
    const double now = mass_coefficient(), then = built_mass_coefficient;
    return std::abs(now - then) > 0.25 * std::max(now, then);
  }


  template <int dim>
  double
  FluidSolver<dim>::right_hand_side_norm(const VectorType &iterate) const
  {
    // b = A x + r on the unconstrained rows; a constrained row of the
    // update system holds only its diagonal, and A x there would be the
    // boundary data, not a force.
    VectorType &b = residual_force;
    SaddlePointOperator(system_matrix, velocity_block.get()).vmult(b, iterate);
    b += system_rhs;
    for (unsigned int block = 0; block < 2; ++block)
    {
      const auto offset = block == 0 ? 0 : owned_partitioning[0].size();
      for (const auto i : owned_partitioning[block])
        if (update_constraints.is_constrained(i + offset))
          b.block(block)[i] = 0;
    }
    b.compress(dealii::VectorOperation::insert);
    return b.l2_norm();
  }


  template <int dim>
  std::array<double, 3>
  FluidSolver<dim>::compute_errors(
    const dealii::Function<dim> &exact_solution) const
  {
    const dealii::QGauss<dim> quadrature(fe.degree + 3);

    // Pressure is compared up to its mean when the problem fixes it only
    // up to a constant (no open face): shift the exact one onto the
    // discrete mean.
    double exact_mean = 0, volume = 0;
    {
      dealii::FEValues<dim> fe_values(mapping,
                                      fe,
                                      quadrature,
                                      dealii::update_quadrature_points |
                                        dealii::update_JxW_values);
      for (const auto &cell : dof_handler.active_cell_iterators())
        if (cell->is_locally_owned())
        {
          fe_values.reinit(cell);
          for (unsigned int q = 0; q < quadrature.size(); ++q)
          {
            exact_mean +=
              exact_solution.value(fe_values.quadrature_point(q), dim) *
              fe_values.JxW(q);
            volume += fe_values.JxW(q);
          }
        }
      exact_mean = dealii::Utilities::MPI::sum(exact_mean, mpi_communicator);
      volume     = dealii::Utilities::MPI::sum(volume, mpi_communicator);
      exact_mean /= volume;
    }
    const double discrete_mean = dealii::VectorTools::compute_mean_value(
      mapping, dof_handler, quadrature, solution, dim);

    class Shifted : public dealii::Function<dim>
    {
    public:
      Shifted(const dealii::Function<dim> &f, const double shift)
          : dealii::Function<dim>(dim + 1)
          , f(f)
          , shift(shift)
      {
      }
      double
      value(const dealii::Point<dim> &p, const unsigned int c) const override
      {
        return f.value(p, c) + (c == dim ? shift : 0.0);
      }
      dealii::Tensor<1, dim>
      gradient(const dealii::Point<dim> &p, const unsigned int c) const override
      {
        return f.gradient(p, c);
      }

    private:
      const dealii::Function<dim> &f;
      const double                 shift;
    } shifted(exact_solution,
              pressure_has_null_space() ? discrete_mean - exact_mean : 0.0);

    const dealii::ComponentSelectFunction<dim> velocity_mask(
      std::make_pair(0, dim), dim + 1);
    const dealii::ComponentSelectFunction<dim> pressure_mask(dim, dim + 1);

    dealii::Vector<float> cellwise(triangulation.n_active_cells());
    std::array<double, 3> errors;
    dealii::VectorTools::integrate_difference(mapping,
                                              dof_handler,
                                              solution,
                                              shifted,
                                              cellwise,
                                              quadrature,
                                              dealii::VectorTools::L2_norm,
                                              &velocity_mask);
    errors[0] =
      dealii::VectorTools::compute_global_error(triangulation,
                                                cellwise,
                                                dealii::VectorTools::L2_norm);
    dealii::VectorTools::integrate_difference(mapping,
                                              dof_handler,
                                              solution,
                                              shifted,
                                              cellwise,
                                              quadrature,
                                              dealii::VectorTools::H1_seminorm,
                                              &velocity_mask);
    errors[1] = dealii::VectorTools::compute_global_error(
      triangulation, cellwise, dealii::VectorTools::H1_seminorm);
    dealii::VectorTools::integrate_difference(mapping,
                                              dof_handler,
                                              solution,
                                              shifted,
                                              cellwise,
                                              quadrature,
                                              dealii::VectorTools::L2_norm,
                                              &pressure_mask);
    errors[2] =
      dealii::VectorTools::compute_global_error(triangulation,
                                                cellwise,
                                                dealii::VectorTools::L2_norm);
    return errors;
  }


  template <int dim>
  void
  FluidSolver<dim>::add_data_vectors(dealii::DataOut<dim> &data_out) const
  {
    std::vector<std::string> names(dim, "velocity");
    names.emplace_back("pressure");
    std::vector<
      dealii::DataComponentInterpretation::DataComponentInterpretation>
      interpretation(
        dim, dealii::DataComponentInterpretation::component_is_part_of_vector);
    interpretation.push_back(
      dealii::DataComponentInterpretation::component_is_scalar);
    data_out.add_data_vector(dof_handler, solution, names, interpretation);
    output_fields = std::make_unique<MixtureFieldsOutput<dim>>(*mixture_fields,
                                                               time,
                                                               mapping);
    data_out.add_data_vector(dof_handler, solution, *output_fields);
  }


  template <int dim>
  double
  FluidSolver<dim>::max_velocity() const
  {
    return solution.block(0).linfty_norm();
  }


  template <int dim>
  double
  FluidSolver<dim>::driven_speed() const
  {
    // The rank-local maxima in one reduction.
    std::array<double, 4> local = {{max_forcing,
                                    max_open_pressure,
                                    max_boundary_speed,
                                    max_prescribed_grain_speed}};
    dealii::Utilities::MPI::max(dealii::ArrayView<const double>(local),
                                mpi_communicator,
                                dealii::ArrayView<double>(local));
    const auto [F, P, boundary, prescribed] = local;
    const double L   = geometry.lower_corner.distance(geometry.upper_corner);
    const double rho = parameters.density, mu = parameters.viscosity;
    const double speeds[] = {max_initial_speed,
                             boundary,
                             prescribed,
                             std::sqrt(F * L / rho),
                             F * L * L / mu,
                             std::sqrt(2 * P / rho),
                             P * L / mu};
    return *std::max_element(std::begin(speeds), std::end(speeds));
  }


  template <int dim>
  void
  FluidSolver<dim>::sample_open_pressure()
  {
    auto &pressure = *parameters.open_boundary_pressure;
    pressure.set_time(time);
    for (const auto &cell : dof_handler.active_cell_iterators())
      if (cell->is_locally_owned() && cell->at_boundary())
        for (const unsigned int f : cell->face_indices())
          if (cell->at_boundary(f) &&
              geometry.boundary_type(cell->face(f)->boundary_id()) ==
                BoundaryType::open)
            for (const unsigned int v : cell->face(f)->vertex_indices())
              max_open_pressure =
                std::max(max_open_pressure,
                         std::abs(pressure.value(cell->face(f)->vertex(v))));
  }


  template <int dim>
  double
  FluidSolver<dim>::integrate_fluid_fraction(double *mesh_volume) const
  {
    const dealii::QGauss<dim> quadrature(3);
    dealii::FEValues<dim>     fe_values(mapping,
                                    fe,
                                    quadrature,
                                    dealii::update_quadrature_points |
                                      dealii::update_JxW_values);
    MixtureValues<dim>        values;
    double                    integral = 0, volume = 0;
    for (const auto &cell : dof_handler.active_cell_iterators())
      if (cell->is_locally_owned())
      {
        fe_values.reinit(cell);
        mixture_fields->evaluate(cell,
                                 fe_values.get_quadrature_points(),
                                 quadrature.get_points(),
                                 time,
                                 values);
        for (unsigned int q = 0; q < quadrature.size(); ++q)
        {
          integral += values.fluid_fraction[q] * fe_values.JxW(q);
          volume += fe_values.JxW(q);
        }
      }
    if (mesh_volume)
      *mesh_volume = dealii::Utilities::MPI::sum(volume, mpi_communicator);
    return dealii::Utilities::MPI::sum(integral, mpi_communicator);
  }


  template <int dim>
  dealii::types::global_dof_index
  FluidSolver<dim>::n_dofs() const
  {
    return dof_handler.n_dofs();
  }


  template <int dim>
  const dealii::DoFHandler<dim> &
  FluidSolver<dim>::get_dof_handler() const
  {
    return dof_handler;
  }


  template <int dim>
  const typename FluidSolver<dim>::VectorType &
  FluidSolver<dim>::get_solution() const
  {
    return solution;
  }


  template <int dim>
  const CellGather<dim> &
  FluidSolver<dim>::get_cell_gather() const
  {
    return *cell_gather;
  }


  template <int dim>
  double
  FluidSolver<dim>::get_time() const
  {
    return time;
  }


  template <int dim>
  std::vector<std::string>
  FluidSolver<dim>::StepStatistics::column_names()
  {
    return {"fluid_iterations",
            "fluid_nonlinear_iterations",
            "fluid_residual",
            "drag_averaged_cells",
            "preconditioner_builds"};
  }


  template <int dim>
  void
  FluidSolver<dim>::StepStatistics::set_statistics(
    Statistics        &statistics,
    const unsigned int builds_so_far) const
  {
    statistics.set("fluid_iterations", linear_iterations);
    statistics.set("fluid_nonlinear_iterations", nonlinear_iterations);
    statistics.set("fluid_residual", final_residual);
    statistics.set("drag_averaged_cells", drag_averaged_cells);
    statistics.set("preconditioner_builds", builds_so_far);
  }


  template class FluidSolver<2>;
  template class FluidSolver<3>;
} // namespace ImmersedGrains
