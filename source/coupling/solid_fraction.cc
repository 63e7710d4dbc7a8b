#include <deal.II/base/quadrature_lib.h>

#include <deal.II/fe/fe_values.h>


#include <immersed_grains/coupling/solid_fraction.h>

#include <algorithm>
#include <limits>

namespace ImmersedGrains
{
  template <int dim>
  void
  SolidFraction<dim>::Parameters::declare_parameters(
    dealii::ParameterHandler &prm)
  {
    using namespace dealii::Patterns;
    prm.declare_entry("Solid fraction projection",
                      "consistent",
                      Selection("consistent|lumped"),
                      "Mass matrix of the projection of grain volumes onto "
                      "the Q1 solid fraction (both conserve the volume).");
    prm.declare_entry("Smoothing length",
                      "0",
                      Double(0),
                      "Length l [m] of the Helmholtz filter (M + l^2 K) "
                      "phi_s = b that makes the solid fraction independent of "
                      "the mesh once cells are smaller than grains; 0: none. "
                      "A grain diameter or two is typical.");
    prm.declare_entry(
      "Minimum fluid fraction",
      "0.3",
      Double(0.01, 1),
      "The drag closure reads at least this porosity, and the fluid at "
      "least the fluid fraction that maps onto it (the same number unless "
      "'Closure porosity in 2D' maps it); where the grains pack denser the "
      "log warns, phi is clamped and the grains' volume in the mixture is "
      "scaled to 1 - phi, so that the mixture still fills the space.");
    prm.declare_entry(
      "Closure porosity in 2D",
      "area fraction",
      Selection("area fraction|sphere packing"),
      "The porosity the drag law reads in a 2D scene: 'area fraction' the "
      "fluid's area fraction phi (the seed's choice; dilute clouds); "
      "'sphere packing' the porosity of the sphere packing with the same "
      "gap-to-radius ratio, 1 - 0.8574 (1 - phi)^{3/2} (hexagonal onto "
      "FCC, random close onto random close: dense beds; doc/theory.md). "
      "Ignored in 3D.");
  }


  template <int dim>
  void
  SolidFraction<dim>::Parameters::parse_parameters(
    dealii::ParameterHandler &prm,
    const std::string &)
  {
    lumped             = prm.get("Solid fraction projection") == "lumped";
    smoothing_length   = prm.get_double("Smoothing length");
    min_fluid_fraction = prm.get_double("Minimum fluid fraction");
    closure_porosity.sphere_packing =
      dim == 2 && prm.get("Closure porosity in 2D") == "sphere packing";
  }


  template <int dim>
  SolidFraction<dim>::SolidFraction(
    const Parameters                                        &parameters,
    const Geometry<dim>                                     &geometry,
    const dealii::parallel::distributed::Triangulation<dim> &tria)
      : parameters(parameters)
      , filter(tria, geometry)
      , shapes(filter.get_fe())
  {
  }


  template <int dim>
  void
  SolidFraction<dim>::setup()
  {
    // The felt fraction (project()) needs the mass matrix.
    filter.setup(parameters.lumped,
                 parameters.smoothing_length,
                 parameters.smoothing_length > 0);
    fraction = filter.make_ghosted_vector();
    // Projected again for each step (project_sink()) in this layout: one
    // kept from the old mesh (assigning {} only zeroes it) imports the
    // ghost entries of the old partition, and reads 0 where the new one
    // has other ghosts (0.15 % of the sink lost in a two-rank silo).
    sink      = filter.make_ghosted_vector();
    sink_rate = 0;
    if (parameters.smoothing_length > 0)
      felt = filter.make_ghosted_vector();
    for (auto &f : flux)
      f = filter.make_ghosted_vector();
    if (parameters.with_mean_diameter)
    {
      surface = filter.make_ghosted_vector();
      if (parameters.smoothing_length > 0)
        felt_surface = filter.make_ghosted_vector();
    }
  }


  template <int dim>
  void
  SolidFraction<dim>::project(
    const std::function<
      void(const typename dealii::Triangulation<dim>::active_cell_iterator &,
           std::vector<GrainSample<dim>> &)> &samples,
    const bool                                with_flux,
    const bool                                with_rate)
  {
    flux_for_fluid   = with_flux;
    flux_for_rate    = with_rate;
    auto volume_rhs  = filter.make_owned_vector();
    auto surface_rhs = parameters.with_mean_diameter ?
                         filter.make_owned_vector() :
                         typename HelmholtzFilter<dim>::Vector();
    std::array<typename HelmholtzFilter<dim>::Vector, dim> flux_rhs;
    for (auto &f : flux_rhs)
      f = filter.make_owned_vector();

    const auto                                  &fe = filter.get_fe();
    const unsigned int                           n  = fe.n_dofs_per_cell();
    std::vector<dealii::types::global_dof_index> indices(n);
    std::vector<GrainSample<dim>>                grains;
    dealii::Vector<double> cell_volume(n), cell_surface(n);
    double smallest = std::numeric_limits<double>::max(), largest = 0;
    std::array<dealii::Vector<double>, dim> cell_flux;
    for (auto &c : cell_flux)
      c.reinit(n);

    for (const auto &cell : filter.get_dof_handler().active_cell_iterators())
      if (cell->is_locally_owned())
      {
        grains.clear();
        samples(cell, grains);
        if (grains.empty())
          continue;
        cell_volume  = 0;
        cell_surface = 0;
        for (auto &c : cell_flux)
          c = 0;
        for (const auto &g : grains)
        {
          // Only a law that reads the mean diameter pays for its field.
          const double surface =
            parameters.with_mean_diameter ? g.volume / g.diameter : 0.0;
          const auto shape =
            HelmholtzFilter<dim>::shape_values(g.reference_location);
          for (unsigned int j = 0; j < n; ++j)
          {
            const double N = shape[j];
            cell_volume(j) += g.volume * N;
            cell_surface(j) += surface * N;
            for (unsigned int d = 0; d < dim; ++d)
              cell_flux[d](j) += g.volume * g.velocity[d] * N;
          }
          smallest = std::min(smallest, g.diameter);
          largest  = std::max(largest, g.diameter);
        }
        filter.add_cell_contribution(cell, cell_volume, indices, volume_rhs);
        if (parameters.with_mean_diameter)
          filter.add_cell_contribution(cell,
                                       cell_surface,
                                       indices,
                                       surface_rhs);
        for (unsigned int d = 0; d < dim; ++d)
          filter.add_cell_contribution(cell,
                                       cell_flux[d],
                                       indices,
                                       flux_rhs[d]);
      }
    volume_rhs.compress(dealii::VectorOperation::add);
    if (parameters.with_mean_diameter)
    {
      surface_rhs.compress(dealii::VectorOperation::add);
      const MPI_Comm comm = filter.get_dof_handler().get_communicator();
      smallest_diameter   = dealii::Utilities::MPI::min(smallest, comm);
      largest_diameter    = dealii::Utilities::MPI::max(largest, comm);
    }
    for (auto &f : flux_rhs)
      f.compress(dealii::VectorOperation::add);

    std::vector<const typename HelmholtzFilter<dim>::Vector *> rhs{&volume_rhs};
    std::vector<typename HelmholtzFilter<dim>::Vector *> fields{&fraction};
    for (unsigned int d = 0; d < dim; ++d)
      if (with_flux || with_rate)
      {
        rhs.push_back(&flux_rhs[d]);
        fields.push_back(&flux[d]);
      }
      else
        flux[d] = 0;
    // The surface only where the grains differ in size: with one size the
    // mean is that size (mean_diameter()).
    const bool with_surface =
      parameters.with_mean_diameter && largest_diameter > smallest_diameter;
    if (with_surface)
    {
      rhs.push_back(&surface_rhs);
      fields.push_back(&surface);
    }
    filter.solve(rhs, fields);

    if (parameters.smoothing_length > 0)
    {
      // (N_j, phi_s): the filter's consistent mass matrix applied.
      auto felt_rhs = filter.make_owned_vector();
      filter.mass_product(fraction, felt_rhs);
      filter.solve(felt_rhs, felt);
      if (with_surface)
      {
        filter.mass_product(surface, felt_rhs);
        filter.solve(felt_rhs, felt_surface);
      }
    }

    unsigned int local_clamped = 0;
    const double bound         = parameters.fluid_fraction_bound();
    for (const auto i : filter.locally_owned_dofs())
      if (1 - fraction[i] < bound)
        ++local_clamped;
    clamped =
      dealii::Utilities::MPI::sum(local_clamped,
                                  filter.get_dof_handler().get_communicator());
  }


  template <int dim>
  void
  SolidFraction<dim>::project_sink(
    const std::vector<
      std::pair<typename dealii::Triangulation<dim>::active_cell_iterator,
                GrainSample<dim>>> &grains,
    const double                    dt)
  {
    const MPI_Comm comm = filter.get_dof_handler().get_communicator();
    sink_rate           = 0;
    if (dealii::Utilities::MPI::sum(grains.size(), comm) == 0)
      return;
    auto               rhs = filter.make_owned_vector();
    const unsigned int n   = filter.get_fe().n_dofs_per_cell();
    std::vector<dealii::types::global_dof_index> indices(n);
    dealii::Vector<double>                       cell_volume(n);
    for (const auto &[cell, g] : grains)
    {
      const auto shape =
        HelmholtzFilter<dim>::shape_values(g.reference_location);
      for (unsigned int j = 0; j < n; ++j)
        cell_volume(j) = g.volume * shape[j];
      filter.add_cell_contribution(filter.dof_cell(cell),
                                   cell_volume,
                                   indices,
                                   rhs);
    }
    rhs.compress(dealii::VectorOperation::add);
    filter.solve(rhs, sink);
    sink_rate = 1 / dt;
  }


  template <int dim>
  double
  SolidFraction<dim>::integral() const
  {
    return filter.integral(fraction);
  }


  template <int dim>
  double
  SolidFraction<dim>::fluid_volume() const
  {
    // phi is the Q1 field of the clamped node values (evaluate()), so its
    // integral is exact node by node.
    const auto &weights = filter.shape_integrals();
    auto        solid   = filter.make_owned_vector();
    solid               = fraction;
    double sum          = 0;
    for (unsigned int k = 0; k < solid.locally_owned_size(); ++k)
      sum += weights.begin()[k] * clamped_fluid_fraction(solid.begin()[k]);
    return dealii::Utilities::MPI::sum(
      sum, filter.get_dof_handler().get_communicator());
  }


  template <int dim>
  unsigned int
  SolidFraction<dim>::n_clamped() const
  {
    return clamped;
  }


  template <int dim>
  void
  SolidFraction<dim>::evaluate(
    const typename dealii::Triangulation<dim>::active_cell_iterator &tria_cell,
    const std::vector<dealii::Point<dim>> &,
    const std::vector<dealii::Point<dim>> &reference_points,
    const double,
    MixtureValues<dim> &values) const
  {
    const unsigned int n_points = reference_points.size();
    values.resize(n_points);
    const auto         cell = filter.dof_cell(tria_cell);
    const unsigned int n    = filter.get_fe().n_dofs_per_cell();
    std::vector<dealii::types::global_dof_index> indices(n);
    cell->get_dof_indices(indices);
    std::vector<double> local(n);

    shapes.reinit(tria_cell, reference_points, true);
    std::vector<double> field_values(n_points);
    // Fills local (the cell's coefficients) and field_values.
    auto evaluate_field = [&](const dealii::TrilinosWrappers::MPI::Vector &v)
    {
      for (unsigned int i = 0; i < n; ++i)
        local[i] = v[indices[i]];
      for (unsigned int q = 0; q < n_points; ++q)
        field_values[q] = shapes.value_of(local, q);
    };

    evaluate_field(fraction);
    // The fluid fraction is clamped node by node, so that it stays a Q1
    // field whose gradient the quadrature integrates exactly: clamped point
    // by point, max(1 - phi_s, bound) has a kink inside the cells at the
    // edge of a packed region, and the continuity equation
    // phi div u + grad phi . u, integrated by Gauss points across the kink,
    // lost up to 60 % of the flux through a packed bed.
    const std::vector<double> solid = field_values;
    std::vector<double>       phi_local(n);
    for (unsigned int i = 0; i < n; ++i)
      phi_local[i] = clamped_fluid_fraction(local[i]);
    for (unsigned int q = 0; q < n_points; ++q)
    {
      values.fluid_fraction[q]          = shapes.value_of(phi_local, q);
      values.fluid_fraction_gradient[q] = shapes.gradient_of(phi_local, q);
      values.solid_scale[q]      = scale(solid[q], values.fluid_fraction[q]);
      values.drag_coefficient[q] = 0;
      values.mass_source[q]      = 0;
    }
    if (sink_rate > 0)
    {
      evaluate_field(sink);
      for (unsigned int q = 0; q < n_points; ++q)
        values.mass_source[q] = -sink_rate * field_values[q];
    }
    for (unsigned int d = 0; d < dim; ++d)
    {
      evaluate_field(flux[d]);
      for (unsigned int q = 0; q < n_points; ++q)
      {
        values.solid_flux[q][d] =
          flux_for_fluid ? values.solid_scale[q] * field_values[q] : 0.0;
        values.grain_velocity[q][d] =
          flux_for_fluid && solid[q] > 1e-12 ? field_values[q] / solid[q] : 0.0;
        if (flux_for_rate)
          values.solid_flux_divergence[q] += shapes.gradient_of(local, q)[d];
      }
    }
  }


  template <int dim>
  double
  SolidFraction<dim>::clamped_fluid_fraction(const double solid) const
  {
    return std::max(1 - solid, parameters.fluid_fraction_bound());
  }


  template <int dim>
  double
  SolidFraction<dim>::scale(const double solid, const double fluid_fraction)
  {
    // Only where a clamp from below makes phi + phi_s exceed 1.
    return solid > 0 ? std::min(1.0, (1 - fluid_fraction) / solid) : 1.0;
  }


  template <int dim>
  std::vector<double>
  SolidFraction<dim>::solid_scale(
    const typename dealii::Triangulation<dim>::active_cell_iterator &tria_cell,
    const std::vector<dealii::Point<dim>> &reference_points) const
  {
    if (clamped == 0)
      return {};
    const auto         cell = filter.dof_cell(tria_cell);
    const unsigned int n    = filter.get_fe().n_dofs_per_cell();
    std::vector<dealii::types::global_dof_index> indices(n);
    cell->get_dof_indices(indices);
    std::vector<double> local(n), phi_local(n);
    for (unsigned int i = 0; i < n; ++i)
    {
      local[i]     = fraction[indices[i]];
      phi_local[i] = clamped_fluid_fraction(local[i]);
    }
    shapes.reinit(tria_cell, reference_points, false);
    std::vector<double> result(reference_points.size());
    for (unsigned int q = 0; q < result.size(); ++q)
      result[q] =
        scale(shapes.value_of(local, q), shapes.value_of(phi_local, q));
    return result;
  }


  template <int dim>
  std::vector<double>
  SolidFraction<dim>::felt_fluid_fraction(
    const typename dealii::Triangulation<dim>::active_cell_iterator &tria_cell,
    const std::vector<dealii::Point<dim>> &reference_points) const
  {
    const auto         cell = filter.dof_cell(tria_cell);
    const unsigned int n    = filter.get_fe().n_dofs_per_cell();
    std::vector<dealii::types::global_dof_index> indices(n);
    cell->get_dof_indices(indices);
    const auto &field = parameters.smoothing_length > 0 ? felt : fraction;
    std::vector<double> result;
    for (const auto &x : reference_points)
    {
      const auto shape = HelmholtzFilter<dim>::shape_values(x);
      double     phi_s = 0;
      for (unsigned int i = 0; i < n; ++i)
        phi_s += field[indices[i]] * shape[i];
      result.push_back(
        std::clamp(1 - phi_s, parameters.fluid_fraction_bound(), 1.0));
    }
    return result;
  }


  template <int dim>
  std::vector<double>
  SolidFraction<dim>::mean_diameter(
    const typename dealii::Triangulation<dim>::active_cell_iterator &tria_cell,
    const std::vector<dealii::Point<dim>> &reference_points) const
  {
    if (!parameters.with_mean_diameter)
      return {};
    if (!(largest_diameter > smallest_diameter))
      return std::vector<double>(reference_points.size(), largest_diameter);
    const auto         cell = filter.dof_cell(tria_cell);
    const unsigned int n    = filter.get_fe().n_dofs_per_cell();
    std::vector<dealii::types::global_dof_index> indices(n);
    cell->get_dof_indices(indices);
    const bool          smoothed = parameters.smoothing_length > 0;
    const auto         &volume   = smoothed ? felt : fraction;
    const auto         &area     = smoothed ? felt_surface : surface;
    std::vector<double> result;
    for (const auto &x : reference_points)
    {
      const auto shape = HelmholtzFilter<dim>::shape_values(x);
      double     v = 0, a = 0;
      for (unsigned int i = 0; i < n; ++i)
      {
        const double N = shape[i];
        v += volume[indices[i]] * N;
        a += area[indices[i]] * N;
      }
      // v / a lies within the diameters wherever both are positive sums of
      // the same grains; a consistent projection undershoots below zero
      // next to a cloud, where the ratio means nothing: 0 there, the
      // grain's own diameter (DragInput::mean_diameter).
      result.push_back(
        v > 0 && a > 0 ?
          std::clamp(v / a, smallest_diameter, largest_diameter) :
          0.0);
    }
    return result;
  }


  template <int dim>
  const dealii::DoFHandler<dim> &
  SolidFraction<dim>::get_dof_handler() const
  {
    return filter.get_dof_handler();
  }


  template <int dim>
  const dealii::TrilinosWrappers::MPI::Vector &
  SolidFraction<dim>::solid_fraction() const
  {
    return fraction;
  }


  template class SolidFraction<2>;
  template class SolidFraction<3>;
} // namespace ImmersedGrains
