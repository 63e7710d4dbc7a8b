#include <deal.II/base/utilities.h>
#include <deal.II/grid/filtered_iterator.h>
#include <deal.II/grid/grid_tools.h>
#include <deal.II/numerics/rtree.h>

#include <immersed_grains/grains/grains.h>
#include <immersed_grains/io/statistics.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <iomanip>
#include <limits>
#include <sstream>

namespace ImmersedGrains
{
  template <int dim>
  GrainPropertyLayout
  make_grain_property_layout(const GrainParameters<dim> &prm,
                             const bool                  with_fluid,
                             const bool                  straight_paths)
  {
    using namespace dealii::DataComponentInterpretation;
    GrainPropertyLayout l;
    const auto          add =
      [&](const std::string &name, const unsigned int n, const bool vector)
    {
      const unsigned int first = l.n_properties;
      for (unsigned int c = 0; c < n; ++c)
      {
        l.names.push_back(name);
        l.interpretations.push_back(vector ? component_is_part_of_vector :
                                             component_is_scalar);
      }
      l.n_properties += n;
      return first;
    };
    l.velocity = add("velocity", dim, true);
    l.radius   = add("radius", 1, false);
    if (prm.contacts_enabled && prm.contact.friction > 0)
      l.angular_velocity = add("angular_velocity", dim == 2 ? 1 : 3, dim == 3);
    if (with_fluid)
    {
      l.fluid_force   = add("fluid_force", dim, true);
      l.drag_force    = add("drag_force", dim, true);
      l.self_velocity = add("self_velocity", dim, true);
      l.exchange_owed = add("exchange_owed", dim, true);
    }
    if (with_fluid && prm.contacts_enabled)
    {
      l.contact_impulse   = add("contact_impulse", dim, true);
      l.predicted_impulse = add("predicted_impulse", dim, true);
    }
    if (prm.has_fixed_region)
      l.fixed = add("fixed", 1, false);
    if (straight_paths)
    {
      l.path_velocity  = add("path_velocity", dim, true);
      l.path_deviation = add("path_deviation", dim, true);
    }
    return l;
  }


  template <int dim>
  Grains<dim>::Grains(
    const GrainParameters<dim>                              &parameters,
    const Geometry<dim>                                     &geometry,
    const dealii::parallel::distributed::Triangulation<dim> &tria,
    const bool                                               with_fluid,
    dealii::TimerOutput                                     &timer,
    const bool                                               straight_paths)
      : parameters(parameters)
      , geometry(geometry)
      , triangulation(tria)
      , comm(tria.get_communicator())
      , timer(timer)
      , properties(
          make_grain_property_layout(parameters, with_fluid, straight_paths))
      , mapping(geometry.mapping())
      , particles(tria, mapping, properties.n_properties)
      , vertex_cache(tria, mapping)
  {
    if (parameters.contacts_enabled)
      contacts = std::make_unique<DistributedContacts<dim>>(geometry,
                                                            parameters.contact,
                                                            comm);
    if (contacts && parameters.sweep_along_gravity &&
        parameters.gravity.norm() > 0)
      contacts->set_sweep_direction(-parameters.gravity /
                                    parameters.gravity.norm());
    particles.signals.particle_lost.connect(
      [this](const auto &particle, const auto &cell)
      { rescue_lost_grain(particle, cell); });
    update_partition();
  }


  template <int dim>
  void
  Grains<dim>::rescue_lost_grain(
    const typename dealii::Particles::ParticleHandler<dim>::particle_iterator
                                                                    &particle,
    const typename dealii::Triangulation<dim>::active_cell_iterator &cell)
  {
    // The owned cells around the old one's vertices: where a grain that
    // moved less than the cell bound of stable_time_step() can be.
    const dealii::Point<dim> x           = particle->get_location();
    const auto [target, reference, best] = closest_owned_cell_around(cell, x);
    // Far below any motion the contact step resolves (a grain resting on a
    // face moves by round-off of the contact solve, 1e-11 m was seen), far
    // above the position error it leaves.
    if (best > 1e-8)
      return;
    const auto props = particle->get_properties();
    rescued.push_back(
      {target,
       x,
       dealii::GeometryInfo<dim>::project_to_unit_cell(reference),
       particle->get_id(),
       std::vector<double>(props.begin(), props.end())});
  }


  template <int dim>
  dealii::Point<dim>
  Grains<dim>::reference_point(
    const typename dealii::Triangulation<dim>::active_cell_iterator &cell,
    const dealii::Point<dim>                                        &x) const
  {
    try
    {
      return mapping.transform_real_to_unit_cell(cell, x);
    }
    catch (const typename dealii::Mapping<dim>::ExcTransformationFailed &)
    {
      // MappingQ1's Newton iteration fails for points far outside a
      // curved or skewed cell: such a point is in none of its cells.
      dealii::Point<dim> far;
      for (unsigned int d = 0; d < dim; ++d)
        far[d] = std::numeric_limits<double>::max();
      return far;
    }
  }


  template <int dim>
  std::tuple<typename dealii::Triangulation<dim>::active_cell_iterator,
             dealii::Point<dim>,
             double>
  Grains<dim>::closest_owned_cell_around(
    const typename dealii::Triangulation<dim>::active_cell_iterator &cell,
    const dealii::Point<dim>                                        &x) const
  {
    const auto &around = vertex_cache.get_vertex_to_cell_map();
    double      best   = std::numeric_limits<double>::infinity();
    typename dealii::Triangulation<dim>::active_cell_iterator target;
    dealii::Point<dim>                                        reference;
    for (const unsigned int v : cell->vertex_indices())
      for (const auto &candidate : around[cell->vertex_index(v)])
      {
        if (!candidate->is_locally_owned())
          continue;
        const dealii::Point<dim> p = reference_point(candidate, x);
        const double             distance =
          dealii::GeometryInfo<dim>::distance_to_unit_cell(p);
        if (distance < best)
        {
          best      = distance;
          target    = candidate;
          reference = p;
          if (distance == 0)
            return {target, reference, best};
        }
      }
    return {target, reference, best};
  }


  template <int dim>
  void
  Grains<dim>::reinsert(const std::vector<StoredGrain> &grains)
  {
    for (const StoredGrain &g : grains)
      particles.insert_particle(g.location,
                                g.reference,
                                g.id,
                                g.cell,
                                dealii::ArrayView<const double>(
                                  g.properties.data(), g.properties.size()));
  }


  template <int dim>
  void
  Grains<dim>::update_partition()
  {
    // One box around this rank's cells (compute_mesh_predicate_bounding_box
    // of deal.II 9.4 crashed on our meshes): coarser than a union of boxes,
    // so possibly more ghosts, never fewer.
    std::vector<dealii::BoundingBox<dim>> local;
    for (const auto &cell : triangulation.active_cell_iterators())
      if (cell->is_locally_owned())
      {
        if (local.empty())
          local.push_back(cell->bounding_box());
        else
          local[0].merge_with(cell->bounding_box());
      }
    rank_boxes = dealii::Utilities::MPI::all_gather(comm, local);
    double h   = std::numeric_limits<double>::max();
    for (const auto &cell : triangulation.active_cell_iterators())
      if (cell->is_locally_owned())
        h = std::min(h, cell->minimum_vertex_distance());
    min_cell_size = dealii::Utilities::MPI::min(h, comm);
    if (contacts)
      contacts->set_partition(rank_boxes, make_contact_halo());
  }


  template <int dim>
  typename DistributedContacts<dim>::PartitionHalo
  Grains<dim>::make_contact_halo() const
  {
    typename DistributedContacts<dim>::PartitionHalo halo;
    if (dealii::Utilities::MPI::n_mpi_processes(comm) == 1)
      return halo;
    // The ghost cells, found near each owned cell through a tree of their
    // boxes, the owned cell's box moved by a period where it lies within
    // reach of a periodic face.
    std::vector<std::pair<dealii::BoundingBox<dim>, unsigned int>> ghosts;
    for (const auto &cell : triangulation.active_cell_iterators())
      if (cell->is_ghost())
        ghosts.emplace_back(cell->bounding_box(), cell->subdomain_id());
    const auto   tree  = dealii::pack_rtree(ghosts);
    const double reach = min_cell_size;
    halo.reach_limit   = reach;
    halo.offsets.assign(triangulation.n_active_cells() + 1, 0);
    std::vector<std::pair<dealii::BoundingBox<dim>, unsigned int>> found;
    for (const auto &cell : triangulation.active_cell_iterators())
    {
      const unsigned int c = cell->active_cell_index();
      halo.offsets[c + 1]  = halo.offsets[c];
      if (!cell->is_locally_owned())
        continue;
      auto corners = cell->bounding_box().get_boundary_points();
      for (unsigned int d = 0; d < dim; ++d)
      {
        corners.first[d] -= reach;
        corners.second[d] += reach;
      }
      // Every combination of periods on the periodic axes (0: none): a
      // cell that reaches below the lower face looks for ghosts one period
      // up, and the other way round.
      std::vector<dealii::Tensor<1, dim>> shifts(1);
      for (unsigned int d = 0; d < dim; ++d)
        if (geometry.is_periodic(d))
        {
          const double L = geometry.upper_corner[d] - geometry.lower_corner[d];
          const std::size_t n = shifts.size();
          for (const double sign : {1., -1.})
            if ((sign > 0 && corners.first[d] < geometry.lower_corner[d]) ||
                (sign < 0 && corners.second[d] > geometry.upper_corner[d]))
              for (std::size_t k = 0; k < n; ++k)
              {
                auto t = shifts[k];
                t[d]   = sign * L;
                shifts.push_back(t);
              }
        }
      for (const auto &shift : shifts)
      {
        found.clear();
        const dealii::BoundingBox<dim> query(
          std::make_pair(corners.first + shift, corners.second + shift));
        tree.query(boost::geometry::index::intersects(query),
                   std::back_inserter(found));
        for (const auto &[box, rank] : found)
        {
          // Into this cell's frame: a grain here measures its distance to
          // the box without images.
          const auto &[lo, hi] = box.get_boundary_points();
          halo.cells.emplace_back(rank,
                                  dealii::BoundingBox<dim>(
                                    std::make_pair(lo - shift, hi - shift)));
          ++halo.offsets[c + 1];
        }
      }
    }
    return halo;
  }


  template <int dim>
  void
  Grains<dim>::prepare_for_mesh_change()
  {
    // The departed grains' cells may not survive.
    keep_departed_as_positions();
    particles.prepare_for_coarsening_and_refinement();
  }


  template <int dim>
  void
  Grains<dim>::finish_mesh_change()
  {
    dealii::TimerOutput::Scope scope(timer, "grains: setup");
    particles.unpack_after_coarsening_and_refinement();
    update_partition();
  }


  template <int dim>
  void
  Grains<dim>::prepare_for_serialization()
  {
    particles.prepare_for_serialization();
  }


  template <int dim>
  void
  Grains<dim>::deserialize()
  {
    dealii::TimerOutput::Scope scope(timer, "grains: setup");
    particles.deserialize();
    particles.update_cached_numbers();
    update_partition();
  }


  template <int dim>
  void
  Grains<dim>::save_contact_memory(std::ostream &out) const
  {
    if (contacts)
      contacts->contact_solver().save_warm_start(out);
  }


  template <int dim>
  void
  Grains<dim>::load_contact_memory(std::istream &in)
  {
    if (contacts)
      contacts->contact_solver().load_warm_start(in);
  }


  template <int dim>
  void
  Grains<dim>::initialize(const std::vector<GrainSeed<dim>> &seeds)
  {
    dealii::TimerOutput::Scope scope(timer, "grains: setup");
    // Rank 0 hands every grain in; insert_global_particles sends each to
    // the rank owning its cell and numbers them in rank 0's order, so that
    // grain k gets id k. Properties are set afterwards from the seed list
    // every rank holds: deal.II 9.4 hangs when only some ranks pass
    // properties or ids to insert_global_particles.
    std::vector<dealii::Point<dim>> positions;
    if (dealii::Utilities::MPI::this_mpi_process(comm) == 0)
      for (const auto &seed : seeds)
        positions.push_back(seed.position);
    particles.insert_global_particles(positions, rank_boxes);
    particles.update_cached_numbers();
    for (auto &p : particles)
    {
      const auto k = p.get_id();
      AssertThrow(k < seeds.size() &&
                    (p.get_location() - seeds[k].position).norm() <=
                      1e-12 * (1 + seeds[k].position.norm()),
                  dealii::ExcMessage("Grains: particle ids do not follow "
                                     "the order of insertion."));
      auto       props = p.get_properties();
      const bool fixed = parameters.fixed_at_placement(seeds[k].position);
      for (unsigned int d = 0; d < dim; ++d)
        props[properties.velocity + d] = fixed ? 0 : seeds[k].velocity[d];
      props[properties.radius] = seeds[k].radius;
      if (properties.fixed != GrainPropertyLayout::absent)
        props[properties.fixed] = fixed ? 1 : 0;
    }
    reset_straight_paths();
    AssertThrow(particles.n_global_particles() == seeds.size(),
                dealii::ExcMessage(
                  "Grains: " +
                  std::to_string(seeds.size() -
                                 particles.n_global_particles()) +
                  " grains could not be located in the mesh."));
  }


  template <int dim>
  double
  Grains<dim>::mass(const double radius) const
  {
    return parameters.density * grain_volume<dim>(radius);
  }


  template <int dim>
  bool
  Grains<dim>::is_fixed(
    const dealii::Particles::ParticleAccessor<dim> &particle) const
  {
    return parameters.fixed ||
           (properties.fixed != GrainPropertyLayout::absent &&
            particle.get_properties()[properties.fixed] != 0);
  }


  template <int dim>
  double
  Grains<dim>::stable_time_step(const double max_step) const
  {
    double v_max = 0, r_min = std::numeric_limits<double>::max();
    for (const auto &p : particles)
    {
      const auto             props = p.get_properties();
      dealii::Tensor<1, dim> v;
      for (unsigned int d = 0; d < dim; ++d)
        v[d] = props[properties.velocity + d];
      v_max = std::max(v_max, v.norm());
      r_min = std::min(r_min, props[properties.radius]);
    }
    // In vacuum gravity adds up to |g| dt within the step; in a fluid the
    // implicit drag bounds the change of velocity, and the current speed
    // is the scale.
    v_max = dealii::Utilities::MPI::max(v_max, comm) +
            (parameters.fixed ||
                 properties.fluid_force != GrainPropertyLayout::absent ?
               0 :
               parameters.gravity.norm() * max_step);
    r_min = dealii::Utilities::MPI::min(r_min, comm);
    if (v_max <= 0 || parameters.fixed)
      return max_step;
    return std::min(max_step, longest_step(v_max, r_min));
  }


  template <int dim>
  double
  Grains<dim>::max_speed() const
  {
    double v_max = 0;
    for (const auto &p : particles)
    {
      const auto             props = p.get_properties();
      dealii::Tensor<1, dim> v;
      for (unsigned int d = 0; d < dim; ++d)
        v[d] = props[properties.velocity + d];
      v_max = std::max(v_max, v.norm());
    }
    return dealii::Utilities::MPI::max(v_max, comm);
  }


  template <int dim>
  double
  Grains<dim>::longest_step(const double v_max, const double r_min) const
  {
    // The ParticleHandler looks for a moved grain in the cells around its
    // old cell; under MPI those are the owned and ghost cells, so a grain
    // that moves farther in one step is lost (move_and_scatter() stops the
    // run). Half the shortest cell edge keeps every grain within them, with
    // room for distorted cells; a collision can speed a light grain up to
    // (1 + e) times the speed of the grain that hits it.
    const double cell_bound =
      0.5 * min_cell_size / ((1 + parameters.contact.restitution) * v_max);
    return std::min(parameters.max_displacement * r_min / v_max, cell_bound);
  }


  template <int dim>
  GrainStepReport
  Grains<dim>::advance(const double dt)
  {
    forget_departed();
    gather();
    compute_free_velocities(dt);
    GrainStepReport report = resolve_contacts(dt);
    report.removed         = move_and_scatter(dt);
    return report;
  }


  template <int dim>
  void
  Grains<dim>::gather()
  {
    dealii::TimerOutput::Scope scope(timer, "grains: gather");
    const unsigned int         n = particles.n_locally_owned_particles();
    const bool                 friction =
      properties.angular_velocity != GrainPropertyLayout::absent;
    auto &c = arrays.contact;
    arrays.position.resize(n);
    arrays.mass.resize(n);
    const bool cells =
      contacts && dealii::Utilities::MPI::n_mpi_processes(comm) > 1;
    arrays.cell.resize(cells ? n : 0);
    arrays.fixed.resize(n);
    c.velocity.resize(n);
    c.start_velocity.resize(n);
    c.inverse_mass.resize(n);
    c.radius.resize(n);
    c.id.resize(n);
    c.angular_velocity.resize(friction ? n : 0);
    c.inverse_inertia.resize(friction ? n : 0);
    arrays.external_force.clear();
    arrays.drag_coefficient.clear();
    arrays.drag_velocity.clear();
    const bool impulses =
      properties.contact_impulse != GrainPropertyLayout::absent;
    arrays.contact_impulse.resize(impulses ? n : 0);
    arrays.predicted_impulse.resize(impulses ? n : 0);
    const bool drags = properties.drag_force != GrainPropertyLayout::absent;
    arrays.drag_force.resize(drags ? n : 0);
    arrays.self_velocity.resize(drags ? n : 0);
    arrays.exchange_owed.resize(drags ? n : 0);

    unsigned int i = 0;
    for (const auto &p : particles)
    {
      const auto props   = p.get_properties();
      arrays.position[i] = p.get_location();
      if (cells)
        arrays.cell[i] = p.get_surrounding_cell()->active_cell_index();
      for (unsigned int d = 0; d < dim; ++d)
        c.velocity[i][d] = props[properties.velocity + d];
      c.radius[i]     = props[properties.radius];
      c.id[i]         = p.get_id();
      arrays.mass[i]  = mass(c.radius[i]);
      arrays.fixed[i] = is_fixed(p);
      if (friction)
        for (unsigned int d = 0; d < (dim == 2 ? 1 : 3); ++d)
          c.angular_velocity[i][d] = props[properties.angular_velocity + d];
      if (impulses)
        for (unsigned int d = 0; d < dim; ++d)
        {
          arrays.contact_impulse[i][d] = props[properties.contact_impulse + d];
          arrays.predicted_impulse[i][d] =
            props[properties.predicted_impulse + d];
        }
      if (drags)
        for (unsigned int d = 0; d < dim; ++d)
        {
          arrays.drag_force[i][d]    = props[properties.drag_force + d];
          arrays.self_velocity[i][d] = props[properties.self_velocity + d];
          arrays.exchange_owed[i][d] = props[properties.exchange_owed + d];
        }
      ++i;
    }
    c.start_velocity = c.velocity;
  }


  template <int dim>
  void
  Grains<dim>::compute_free_velocities(const double dt)
  {
    dealii::TimerOutput::Scope scope(timer, "grains: free velocities");
    // Implicit drag (hooks): m (v' - v) = dt (m g + F + beta (u - v')), so
    // v' = (m v + dt (m g + F + beta u)) / (m + dt beta), and the contact
    // solver sees the same effective mass m + dt beta.
    auto              &c        = arrays.contact;
    const bool         force    = !arrays.external_force.empty();
    const bool         drag     = !arrays.drag_coefficient.empty();
    const bool         friction = !c.inverse_inertia.empty();
    const unsigned int n        = c.velocity.size();
    for (unsigned int i = 0; i < n; ++i)
    {
      const double m = arrays.mass[i];
      if (arrays.fixed[i])
      {
        c.velocity[i]     = 0;
        c.inverse_mass[i] = 0;
        if (friction)
        {
          c.angular_velocity[i] = 0;
          c.inverse_inertia[i]  = 0;
        }
        continue;
      }
      dealii::Tensor<1, dim> momentum =
        m * (c.start_velocity[i] + dt * parameters.gravity);
      double m_eff = m;
      if (force)
        momentum += dt * arrays.external_force[i];
      if (drag)
      {
        momentum += dt * arrays.drag_coefficient[i] * arrays.drag_velocity[i];
        m_eff += dt * arrays.drag_coefficient[i];
      }
      c.velocity[i]     = momentum / m_eff;
      c.inverse_mass[i] = 1 / m_eff;
      if (friction)
        c.inverse_inertia[i] = 1 / (m * inertia_per_mass<dim>(c.radius[i]));
    }
  }


  template <int dim>
  unsigned int
  Grains<dim>::substeps(const double dt) const
  {
    if (parameters.fixed)
      return 1;
    const auto &c     = arrays.contact;
    double      v_max = 0, r_min = std::numeric_limits<double>::max();
    for (unsigned int i = 0; i < c.velocity.size(); ++i)
    {
      v_max =
        std::max({v_max, c.velocity[i].norm(), c.start_velocity[i].norm()});
      r_min = std::min(r_min, c.radius[i]);
    }
    v_max = dealii::Utilities::MPI::max(v_max, comm);
    r_min = dealii::Utilities::MPI::min(r_min, comm);
    if (v_max <= 0)
      return 1;
    // The bounds of stable_time_step(), with the velocities of this step.
    return std::max(1.,
                    std::ceil(dt / longest_step(v_max, r_min) * (1 - 1e-12)));
  }


  void
  GrainStepReport::add_substep(const GrainStepReport &later)
  {
    contacts.iterations += later.contacts.iterations;
    contacts.converged = contacts.converged && later.contacts.converged;
    contacts.residual  = std::max(contacts.residual, later.contacts.residual);
    contacts.max_overlap =
      std::max(contacts.max_overlap, later.contacts.max_overlap);
    contacts.n_contacts = later.contacts.n_contacts;
    contacts.n_active   = later.contacts.n_active;
    max_contact_force   = std::max(max_contact_force, later.max_contact_force);
    alert_distance      = std::max(alert_distance, later.alert_distance);
    removed += later.removed;
  }


  std::vector<std::string>
  GrainStepReport::column_names()
  {
    return {"max_overlap",
            "contacts",
            "contact_iterations",
            "contact_residual",
            "contact_converged",
            "max_contact_force",
            "alert_distance"};
  }


  void
  GrainStepReport::set_statistics(Statistics &statistics) const
  {
    statistics.set("max_overlap", contacts.max_overlap);
    statistics.set("contacts", contacts.n_active);
    statistics.set("contact_iterations", contacts.iterations);
    statistics.set("contact_residual", contacts.residual);
    statistics.set("contact_converged", contacts.converged);
    statistics.set("max_contact_force", max_contact_force);
    statistics.set("alert_distance", alert_distance);
  }


  template <int dim>
  std::vector<std::string>
  GrainStatistics<dim>::column_names()
  {
    const char              *axes[] = {"x", "y", "z"};
    std::vector<std::string> c      = {"particles", "solid_volume"};
    for (unsigned int d = 0; d < dim; ++d)
      c.push_back(std::string("centroid_") + axes[d]);
    for (unsigned int d = 0; d < dim; ++d)
      c.push_back(std::string("mean_velocity_") + axes[d]);
    for (const char *name :
         {"max_speed", "kinetic_energy", "packing_fraction", "grains_removed"})
      c.emplace_back(name);
    for (unsigned int d = 0; d < dim; ++d)
      c.push_back(std::string("grains_max_") + axes[d]);
    c.emplace_back("fixed_particles");
    for (unsigned int d = 0; d < dim; ++d)
      c.push_back(std::string("fixed_centroid_") + axes[d]);
    return c;
  }


  template <int dim>
  std::vector<std::string>
  GrainStatistics<dim>::class_column_names(const unsigned int n_classes)
  {
    const char              *axes[] = {"x", "y", "z"};
    std::vector<std::string> c;
    for (unsigned int k = 0; k < n_classes; ++k)
    {
      const std::string prefix = "class" + std::to_string(k) + "_";
      c.push_back(prefix + "particles");
      for (unsigned int d = 0; d < dim; ++d)
        c.push_back(prefix + "mean_velocity_" + axes[d]);
      for (unsigned int d = 0; d < dim; ++d)
        c.push_back(prefix + "centroid_" + axes[d]);
    }
    return c;
  }


  template <int dim>
  void
  GrainStatistics<dim>::set_statistics(Statistics &statistics,
                                       const bool  without_fluid) const
  {
    const char *axes[] = {"x", "y", "z"};
    statistics.set("particles", n_grains);
    if (without_fluid)
      statistics.set("solid_volume", solid_volume);
    for (unsigned int d = 0; d < dim; ++d)
    {
      statistics.set(std::string("centroid_") + axes[d], centroid[d]);
      statistics.set(std::string("mean_velocity_") + axes[d], mean_velocity[d]);
    }
    statistics.set("fixed_particles", n_fixed);
    for (unsigned int d = 0; d < dim; ++d)
      statistics.set(std::string("fixed_centroid_") + axes[d],
                     fixed_centroid[d]);
    statistics.set("max_speed", max_speed);
    statistics.set("kinetic_energy", kinetic_energy);
    statistics.set("packing_fraction", packing_fraction);
    statistics.set("grains_removed", n_removed);
    for (unsigned int d = 0; d < dim; ++d)
      statistics.set(std::string("grains_max_") + axes[d], max_position[d]);
    for (unsigned int k = 0; k < class_grains.size(); ++k)
    {
      const std::string prefix = "class" + std::to_string(k) + "_";
      statistics.set(prefix + "particles", class_grains[k]);
      for (unsigned int d = 0; d < dim; ++d)
      {
        statistics.set(prefix + "mean_velocity_" + axes[d],
                       class_mean_velocity[k][d]);
        statistics.set(prefix + "centroid_" + axes[d], class_centroid[k][d]);
      }
    }
  }


  template <int dim>
  GrainStepReport
  Grains<dim>::resolve_contacts(const double dt, const bool add_to_step_impulse)
  {
    GrainStepReport report;
    if (!contacts)
      return report;
    dealii::TimerOutput::Scope scope(timer, "grains: contacts");
    auto                      &c = arrays.contact;
    // Maxima of the speed and the radius, and minus the smallest radius,
    // reduced together.
    double maxima[3] = {0, 0, -std::numeric_limits<double>::max()};
    for (unsigned int i = 0; i < c.velocity.size(); ++i)
    {
      maxima[0] = std::max(maxima[0], c.velocity[i].norm());
      maxima[1] = std::max(maxima[1], c.radius[i]);
      maxima[2] = std::max(maxima[2], -c.radius[i]);
    }
    dealii::Utilities::MPI::max(dealii::ArrayView<const double>(maxima, 3),
                                comm,
                                dealii::ArrayView<double>(maxima, 3));
    const double v_max = maxima[0], r_max = maxima[1], r_min = -maxima[2];
    // Two grains close at most 2 v_max dt within the step (NSCD's
    // candidates are fixed at its start); the margin covers speed gained
    // in collisions.
    report.alert_distance = parameters.alert_distance > 0 ?
                              parameters.alert_distance :
                              0.1 * r_min + 3 * v_max * dt;
    // The neighbour search needs a periodic axis at least twice the reach
    // of a contact; a step whose grains outrun that says why, not where.
    const auto number = [](const double x)
    {
      std::ostringstream s;
      s << std::setprecision(3) << x;
      return s.str();
    };
    for (unsigned int d = 0; d < dim; ++d)
      if (geometry.is_periodic(d))
      {
        const double length =
          geometry.upper_corner[d] - geometry.lower_corner[d];
        AssertThrow(
          length >= 2 * (2 * r_max + report.alert_distance),
          dealii::ExcMessage(
            "the grains' contact candidates reach " +
            number(2 * r_max + report.alert_distance) + " m, more than half " +
            "the periodic box's " + number(length) + " m: " +
            (parameters.alert_distance > 0 ?
               std::string("lower Contacts/Alert distance (") +
                 number(parameters.alert_distance) + " m)" :
               "its alert distance is three times the fastest grain's " +
                 number(v_max) + " m/s over the step of " + number(dt) +
                 " s; shorten the step or keep Coupling/Grain sub-steps on "
                 "(if the grains are accelerating without bound, the run "
                 "has diverged)")));
      }
    std::vector<dealii::Tensor<1, dim>> free_velocity;
    if (!arrays.contact_impulse.empty())
      free_velocity = c.velocity;
    report.contacts = contacts->solve(
      arrays.position, c, dt, report.alert_distance, arrays.cell);
    if (record_boundary_impulses)
    {
      if (!add_to_step_impulse)
      {
        step_boundary_impulse.clear();
        step_boundary_time = 0;
      }
      contacts->add_boundary_impulses(step_boundary_impulse);
      step_boundary_time += dt;
    }
    for (unsigned int i = 0; i < free_velocity.size(); ++i)
      arrays.contact_impulse[i] =
        (add_to_step_impulse ? arrays.contact_impulse[i] :
                               dealii::Tensor<1, dim>()) +
        (c.inverse_mass[i] > 0 ?
           (c.velocity[i] - free_velocity[i]) / c.inverse_mass[i] :
           dealii::Tensor<1, dim>());
    report.max_contact_force = contacts->max_contact_force();
    AssertThrow(report.contacts.converged || !parameters.stop_on_failure,
                dealii::ExcMessage(
                  "the contact solver did not converge within " +
                  std::to_string(report.contacts.iterations) +
                  " iterations (residual " +
                  std::to_string(report.contacts.residual) +
                  "); Contacts/Stop on failure is set"));
    return report;
  }


  template <int dim>
  unsigned long
  Grains<dim>::move_and_scatter(const double dt)
  {
    dealii::TimerOutput::Scope scope(timer, "grains: move and sort");
    using particle_iterator =
      typename dealii::Particles::ParticleHandler<dim>::particle_iterator;
    const auto &c        = arrays.contact;
    const bool  friction = !c.angular_velocity.empty();
    const auto &lo       = geometry.lower_corner;
    const auto &hi       = geometry.upper_corner;
    // Fixed grains keep their location bit for bit and are never sorted
    // again: deal.II 9.4 re-sorts a grain whose reference coordinates
    // are outside [0, 1] by round-off, and one sitting exactly on a mesh
    // vertex was lost so. Where other grains move, the fixed ones leave
    // the ParticleHandler during the sort and return to their cells.
    std::vector<particle_iterator> leaving, taken_out;
    // A grain that left its cell for an owned cell around it is moved
    // there directly; the library's sort (every grain's cell tested again,
    // a collective exchange) only runs where one went elsewhere: to
    // another rank, through a periodic boundary, or past the cells around
    // its old one. On the 2D cloud's sub-steps a few of 321 grains change
    // cell and the sort was most of this phase.
    std::vector<StoredGrain>       crossed;
    std::vector<particle_iterator> crossing;
    unsigned long                  n_fixed = 0, n_elsewhere = 0;
    unsigned int                   i = 0;
    // With straight paths: the largest deviation and velocity change.
    const bool paths = properties.path_deviation != GrainPropertyLayout::absent;
    double     largest[2] = {0, 0};
    for (auto p = particles.begin(); p != particles.end(); ++p, ++i)
    {
      const bool         fixed = arrays.fixed[i];
      dealii::Point<dim> x     = arrays.position[i] + dt * c.velocity[i];
      if (!c.position_correction.empty())
        x += c.position_correction[i];
      if (paths && !fixed)
      {
        auto                   props = p->get_properties();
        dealii::Tensor<1, dim> v0, deviation;
        for (unsigned int d = 0; d < dim; ++d)
        {
          v0[d]        = props[properties.path_velocity + d];
          deviation[d] = props[properties.path_deviation + d];
        }
        deviation += dt * (c.velocity[i] - v0);
        if (!c.position_correction.empty())
          deviation += c.position_correction[i];
        for (unsigned int d = 0; d < dim; ++d)
          props[properties.path_deviation + d] = deviation[d];
        largest[0] = std::max(largest[0], deviation.norm());
        largest[1] = std::max(largest[1], (c.velocity[i] - v0).norm());
      }
      bool left = false;
      for (unsigned int d = 0; d < dim && !fixed; ++d)
      {
        const double L = hi[d] - lo[d];
        if (geometry.is_periodic(d))
        {
          x[d] = geometry.wrap(d, x[d]);
          continue;
        }
        // A mesh's walls and open boundaries: below.
        if (!geometry.is_box())
          continue;
        for (unsigned int side = 0; side < 2; ++side)
        {
          const bool beyond = side == 0 ? x[d] < lo[d] : x[d] > hi[d];
          if (!beyond)
            continue;
          if (geometry.boundary_type(2 * d + side) == BoundaryType::open)
            left = true;
          else
            // The centre went through a wall (a grain overlapping it by
            // more than its radius): keep it just inside, the next
            // contact step pushes it out, rather than losing it.
            x[d] = side == 0 ? lo[d] + 1e-9 * L : hi[d] - 1e-9 * L;
        }
      }
      if (left)
      {
        leaving.push_back(p);
        continue;
      }
      bool in_cell = true;
      if (!fixed)
      {
        p->set_location(x);
        const dealii::Point<dim> reference =
          reference_point(p->get_surrounding_cell(), x);
        in_cell = dealii::GeometryInfo<dim>::is_inside_unit_cell(reference);
        if (in_cell)
          p->set_reference_location(reference);
        // A mesh's open boundary: a centre outside the domain has left.
        else if (!geometry.is_box() && geometry.has_open_boundary() &&
                 !geometry.contains(x))
        {
          leaving.push_back(p);
          continue;
        }
      }
      auto props = p->get_properties();
      for (unsigned int d = 0; d < dim; ++d)
        props[properties.velocity + d] = c.velocity[i][d];
      if (!arrays.contact_impulse.empty())
        for (unsigned int d = 0; d < dim; ++d)
        {
          props[properties.contact_impulse + d] = arrays.contact_impulse[i][d];
          props[properties.predicted_impulse + d] =
            arrays.predicted_impulse[i][d];
        }
      if (!arrays.drag_coefficient.empty() && !arrays.external_force.empty() &&
          properties.fluid_force != GrainPropertyLayout::absent)
      {
        // What the fluid exerted over the step: the forces other than
        // gravity and the implicit drag with the end-of-step velocity.
        const dealii::Tensor<1, dim> force =
          arrays.external_force[i] +
          arrays.drag_coefficient[i] *
            (arrays.drag_velocity[i] - c.velocity[i]);
        for (unsigned int d = 0; d < dim; ++d)
          props[properties.fluid_force + d] = force[d];
        const dealii::Tensor<1, dim> drag =
          arrays.drag_coefficient[i] *
          (arrays.drag_velocity[i] - c.velocity[i]);
        for (unsigned int d = 0; d < dim; ++d)
        {
          props[properties.drag_force + d]    = drag[d];
          props[properties.self_velocity + d] = arrays.self_velocity[i][d];
          props[properties.exchange_owed + d] = arrays.exchange_owed[i][d];
        }
      }
      if (friction)
        for (unsigned int d = 0; d < (dim == 2 ? 1 : 3); ++d)
          props[properties.angular_velocity + d] = c.angular_velocity[i][d];
      if (!in_cell)
      {
        const auto [target, reference, distance] =
          closest_owned_cell_around(p->get_surrounding_cell(), x);
        if (distance == 0)
        {
          crossed.push_back({target,
                             x,
                             reference,
                             p->get_id(),
                             std::vector<double>(props.begin(), props.end())});
          crossing.push_back(p);
        }
        else
          ++n_elsewhere;
      }
      if (fixed)
      {
        ++n_fixed;
        if (parameters.has_fixed_region)
          taken_out.push_back(p);
      }
    }
    if (paths)
    {
      dealii::Utilities::MPI::max(dealii::ArrayView<const double>(largest, 2),
                                  comm,
                                  dealii::ArrayView<double>(largest, 2));
      drift = {largest[0], largest[1]};
    }

    const unsigned long n_leaving      = leaving.size();
    double              volume_leaving = 0;
    for (const auto &p : leaving)
    {
      const double volume =
        grain_volume<dim>(p->get_properties()[properties.radius]);
      volume_leaving += volume;
      // Its cell and reference location are still those before the move.
      // It crosses its own diameter at its speed: so long does its volume
      // take to leave the mixture.
      const auto   props = p->get_properties();
      const double r     = props[properties.radius];
      double       speed = 0;
      for (unsigned int d = 0; d < dim; ++d)
        speed +=
          dealii::Utilities::fixed_power<2>(props[properties.velocity + d]);
      speed = std::sqrt(speed);
      departed_grains.push_back({p->get_surrounding_cell(),
                                 p->get_reference_location(),
                                 volume,
                                 volume * std::max(speed, 1e-12) / (2 * r),
                                 2 * r});
    }
    // Owned grains that stay, and the fixed ones among them, on all ranks.
    std::vector<unsigned long> before = {
      particles.n_locally_owned_particles() - n_leaving, n_fixed, n_elsewhere};
    dealii::Utilities::MPI::sum(before, comm, before);
    if (before[1] == before[0])
      // Nothing moves: no sort at all (Grains/Fixed = true).
      particles.remove_particles(leaving);
    else if (before[2] == 0)
    {
      leaving.insert(leaving.end(), crossing.begin(), crossing.end());
      particles.remove_particles(leaving);
      reinsert(crossed);
      particles.update_cached_numbers();
    }
    else
    {
      // Copied only here: where no grain left its neighbourhood the fixed
      // ones stay in the ParticleHandler.
      std::vector<StoredGrain> held;
      for (const auto &p : taken_out)
      {
        const auto props = p->get_properties();
        held.push_back({p->get_surrounding_cell(),
                        p->get_location(),
                        p->get_reference_location(),
                        p->get_id(),
                        std::vector<double>(props.begin(), props.end())});
      }
      leaving.insert(leaving.end(), taken_out.begin(), taken_out.end());
      particles.remove_particles(leaving);
      rescued.clear();
      particles.sort_particles_into_subdomains_and_cells();
      reinsert(held);
      reinsert(rescued);
      // Collective (global counts): on every rank, held grains or not.
      particles.update_cached_numbers();
    }
    // A grain the ParticleHandler cannot place went through a wall or, under
    // MPI, farther than the ghost layer in one step: never drop it quietly.
    const unsigned long lost_now =
      before[0] - dealii::Utilities::MPI::sum<unsigned long>(
                    particles.n_locally_owned_particles(), comm);
    AssertThrow(lost_now == 0,
                dealii::ExcMessage(
                  std::to_string(lost_now) +
                  " grain(s) moved out of the mesh or beyond the neighbouring "
                  "cells in one step (dt = " +
                  std::to_string(dt) +
                  " s); reduce Time step or set Adaptive time step = true."));
    const unsigned long removed =
      dealii::Utilities::MPI::sum<unsigned long>(n_leaving, comm);
    removed_total += removed;
    if (removed > 0)
      removed_volume_total += dealii::Utilities::MPI::sum(volume_leaving, comm);
    return removed;
  }


  template <int dim>
  void
  Grains<dim>::reset_straight_paths()
  {
    if (properties.path_deviation == GrainPropertyLayout::absent)
      return;
    for (auto &p : particles)
    {
      auto props = p.get_properties();
      for (unsigned int d = 0; d < dim; ++d)
      {
        props[properties.path_velocity + d]  = props[properties.velocity + d];
        props[properties.path_deviation + d] = 0;
      }
    }
    drift = StraightPathDrift();
  }


  template <int dim>
  GrainStepArrays<dim> &
  Grains<dim>::step_arrays()
  {
    return arrays;
  }


  template <int dim>
  const GrainStepArrays<dim> &
  Grains<dim>::step_arrays() const
  {
    return arrays;
  }


  template <int dim>
  GrainStatistics<dim>
  Grains<dim>::compute_statistics() const
  {
    // Sums over owned grains: count, volume, sum x, sum v, kinetic energy,
    // volume-weighted height along gravity, fixed grains' count and sum x;
    // then one reduction. Fixed grains count in the means with v = 0.
    const bool friction =
      properties.angular_velocity != GrainPropertyLayout::absent;
    const dealii::Tensor<1, dim> down =
      parameters.gravity.norm() > 0 ?
        parameters.gravity / parameters.gravity.norm() :
        dealii::Tensor<1, dim>();
    unsigned int axis = 0;
    for (unsigned int d = 1; d < dim; ++d)
      if (std::abs(down[d]) > std::abs(down[axis]))
        axis = d;
    const double       floor = down[axis] < 0 ? geometry.lower_corner[axis] :
                                                geometry.upper_corner[axis];
    const unsigned int fixed_sums = 3 + 2 * dim + 1;
    // Then per class: count, sum x, sum v.
    const unsigned int  class_sums = fixed_sums + 1 + dim;
    const unsigned int  n_classes  = parameters.n_classes();
    std::vector<double> sums(class_sums + n_classes * (1 + 2 * dim), 0.);
    // The largest speed and the largest centre coordinates, reduced
    // together.
    std::vector<double> maxima(1 + dim, std::numeric_limits<double>::lowest());
    maxima[0] = 0;
    for (const auto &p : particles)
    {
      const auto             props = p.get_properties();
      const double           r     = props[properties.radius];
      const double           V     = grain_volume<dim>(r);
      const double           m     = mass(r);
      dealii::Tensor<1, dim> v;
      for (unsigned int d = 0; d < dim; ++d)
        v[d] = props[properties.velocity + d];
      double rotation = 0;
      if (friction)
        for (unsigned int d = 0; d < (dim == 2 ? 1 : 3); ++d)
          rotation += dealii::Utilities::fixed_power<2>(
            props[properties.angular_velocity + d]);
      sums[0] += 1;
      sums[1] += V;
      sums[2] += 0.5 * m * (v * v + inertia_per_mass<dim>(r) * rotation);
      for (unsigned int d = 0; d < dim; ++d)
      {
        sums[3 + d] += p.get_location()[d];
        sums[3 + dim + d] += v[d];
      }
      // Height above the floor the grains rest on (the face gravity points
      // to), weighted by volume.
      sums[3 + 2 * dim] += V * std::abs(p.get_location()[axis] - floor);
      maxima[0] = std::max(maxima[0], v.norm());
      for (unsigned int d = 0; d < dim; ++d)
        maxima[1 + d] = std::max(maxima[1 + d], p.get_location()[d]);
      if (is_fixed(p))
      {
        sums[fixed_sums] += 1;
        for (unsigned int d = 0; d < dim; ++d)
          sums[fixed_sums + 1 + d] += p.get_location()[d];
      }
      if (const int k = parameters.class_of(r); k >= 0)
      {
        double *class_sum = &sums[class_sums + k * (1 + 2 * dim)];
        class_sum[0] += 1;
        for (unsigned int d = 0; d < dim; ++d)
        {
          class_sum[1 + d] += p.get_location()[d];
          class_sum[1 + dim + d] += v[d];
        }
      }
    }
    dealii::Utilities::MPI::sum(sums, comm, sums);

    GrainStatistics<dim> s;
    s.n_grains       = sums[0];
    s.solid_volume   = sums[1];
    s.kinetic_energy = sums[2];
    dealii::Utilities::MPI::max(maxima, comm, maxima);
    s.max_speed = maxima[0];
    if (s.n_grains > 0)
      for (unsigned int d = 0; d < dim; ++d)
      {
        s.centroid[d]      = sums[3 + d] / s.n_grains;
        s.mean_velocity[d] = sums[3 + dim + d] / s.n_grains;
        s.max_position[d]  = maxima[1 + d];
      }
    s.n_fixed = sums[fixed_sums];
    if (s.n_fixed > 0)
      for (unsigned int d = 0; d < dim; ++d)
        s.fixed_centroid[d] = sums[fixed_sums + 1 + d] / s.n_fixed;
    // Bulk packing fraction of a bed resting on the floor: its volume over
    // the cross-section times twice the volume-weighted centroid height
    // (exact for a uniform bed with a flat top).
    if (down.norm() > 0 && s.solid_volume > 0)
    {
      double section = 1;
      for (unsigned int d = 0; d < dim; ++d)
        if (d != axis)
          section *= geometry.upper_corner[d] - geometry.lower_corner[d];
      const double height = sums[3 + 2 * dim] / s.solid_volume;
      s.packing_fraction =
        height > 0 ? s.solid_volume / (section * 2 * height) : 0;
    }
    s.n_removed = removed_total;
    s.class_grains.assign(n_classes, 0.);
    s.class_centroid.assign(n_classes, dealii::Point<dim>());
    s.class_mean_velocity.assign(n_classes, dealii::Tensor<1, dim>());
    for (unsigned int k = 0; k < n_classes; ++k)
    {
      const double *class_sum = &sums[class_sums + k * (1 + 2 * dim)];
      s.class_grains[k]       = class_sum[0];
      if (class_sum[0] > 0)
        for (unsigned int d = 0; d < dim; ++d)
        {
          s.class_centroid[k][d]      = class_sum[1 + d] / class_sum[0];
          s.class_mean_velocity[k][d] = class_sum[1 + dim + d] / class_sum[0];
        }
    }
    return s;
  }


  template <int dim>
  const dealii::Particles::ParticleHandler<dim> &
  Grains<dim>::particle_handler() const
  {
    return particles;
  }


  template <int dim>
  const GrainPropertyLayout &
  Grains<dim>::layout() const
  {
    return properties;
  }


  template <int dim>
  std::vector<ContactForce>
  Grains<dim>::contact_forces() const
  {
    return contacts ? contacts->contact_forces() : std::vector<ContactForce>();
  }


  template <int dim>
  std::pair<unsigned long, unsigned long>
  Grains<dim>::neighbour_searches() const
  {
    unsigned long counts[2] = {0, 0};
    if (contacts)
    {
      counts[0] = contacts->neighbour_list().n_calls();
      counts[1] = contacts->neighbour_list().n_searches();
    }
    dealii::Utilities::MPI::max(dealii::ArrayView<const unsigned long>(counts,
                                                                       2),
                                comm,
                                dealii::ArrayView<unsigned long>(counts, 2));
    return {counts[0], counts[1]};
  }


  template <int dim>
  void
  Grains<dim>::record_boundary_contact_forces()
  {
    record_boundary_impulses = true;
  }


  template <int dim>
  std::vector<dealii::Tensor<1, dim>>
  Grains<dim>::boundary_contact_forces(
    const std::vector<dealii::types::boundary_id> &ids) const
  {
    Assert(record_boundary_impulses, dealii::ExcInternalError());
    // Each contact is solved on one rank: the ranks' sums add up.
    std::vector<double> sums(ids.size() * dim, 0.);
    for (unsigned int k = 0; k < ids.size(); ++k)
    {
      const auto found = step_boundary_impulse.find(ids[k]);
      if (found != step_boundary_impulse.end())
        for (unsigned int d = 0; d < dim; ++d)
          sums[k * dim + d] = found->second[d];
    }
    dealii::Utilities::MPI::sum(sums, comm, sums);
    std::vector<dealii::Tensor<1, dim>> forces(ids.size());
    if (step_boundary_time > 0)
      for (unsigned int k = 0; k < ids.size(); ++k)
        for (unsigned int d = 0; d < dim; ++d)
          forces[k][d] = sums[k * dim + d] / step_boundary_time;
    return forces;
  }


  template <int dim>
  unsigned long
  Grains<dim>::n_removed() const
  {
    return removed_total;
  }


  template <int dim>
  void
  Grains<dim>::set_removed(const unsigned long n)
  {
    removed_total = n;
  }


  template <int dim>
  const std::vector<DepartedGrain<dim>> &
  Grains<dim>::departed()
  {
    if (!departed_need_cells)
      return departed_grains;
    departed_need_cells = false;
    // Every rank searches its cells for every position: the region a grain
    // left from may have moved to another rank with the mesh. The closest
    // cell wins (the unit cell's distance, 0 inside), ties to the lowest
    // rank, so that each grain is counted once.
    std::vector<std::pair<dealii::Point<dim>, std::vector<double>>> mine;
    for (const auto &g : departed_grains)
      mine.emplace_back(g.reference,
                        std::vector<double>{g.volume, g.rate, g.diameter});
    std::vector<std::pair<dealii::Point<dim>, std::vector<double>>> all;
    for (const auto &list : dealii::Utilities::MPI::all_gather(comm, mine))
      all.insert(all.end(), list.begin(), list.end());
    const std::size_t   n = all.size();
    std::vector<double> distance(n, std::numeric_limits<double>::max());
    departed_grains.assign(n, {});
    for (const auto &cell : triangulation.active_cell_iterators())
      if (cell->is_locally_owned())
      {
        const auto box = cell_search_box(*cell);
        for (std::size_t k = 0; k < n; ++k)
          if (box.point_inside(all[k].first))
          {
            const dealii::Point<dim> reference =
              reference_point(cell, all[k].first);
            const double d =
              dealii::GeometryInfo<dim>::distance_to_unit_cell(reference);
            if (d < distance[k])
            {
              distance[k]        = d;
              departed_grains[k] = {
                cell,
                dealii::GeometryInfo<dim>::project_to_unit_cell(reference),
                all[k].second[0],
                all[k].second[1],
                all[k].second[2]};
            }
          }
      }
    std::vector<double> closest(n);
    dealii::Utilities::MPI::min(dealii::ArrayView<const double>(distance),
                                comm,
                                dealii::ArrayView<double>(closest));
    const unsigned int  rank = dealii::Utilities::MPI::this_mpi_process(comm);
    const unsigned int  n_ranks = dealii::Utilities::MPI::n_mpi_processes(comm);
    std::vector<double> owner(n);
    for (std::size_t k = 0; k < n; ++k)
      owner[k] = distance[k] == closest[k] &&
                     closest[k] < std::numeric_limits<double>::max() ?
                   rank :
                   n_ranks;
    dealii::Utilities::MPI::min(dealii::ArrayView<const double>(owner),
                                comm,
                                dealii::ArrayView<double>(owner));
    std::vector<DepartedGrain<dim>> found;
    for (std::size_t k = 0; k < n; ++k)
      if (owner[k] == rank)
        found.push_back(departed_grains[k]);
    departed_grains = std::move(found);
    return departed_grains;
  }


  template <int dim>
  void
  Grains<dim>::keep_departed_as_positions()
  {
    if (!departed_need_cells)
      for (auto &g : departed_grains)
      {
        g.reference = mapping.transform_unit_to_real_cell(g.cell, g.reference);
        g.cell = typename dealii::Triangulation<dim>::active_cell_iterator();
      }
    departed_need_cells = true;
  }


  template <int dim>
  void
  Grains<dim>::save_departed(std::ostream &out) const
  {
    out << std::hexfloat;
    for (const auto &g : departed_grains)
    {
      const dealii::Point<dim> x =
        departed_need_cells ?
          g.reference :
          mapping.transform_unit_to_real_cell(g.cell, g.reference);
      for (unsigned int d = 0; d < dim; ++d)
        out << x[d] << ' ';
      out << g.volume << ' ' << g.rate << ' ' << g.diameter << '\n';
    }
  }


  template <int dim>
  void
  Grains<dim>::load_departed(std::istream &in)
  {
    keep_departed_as_positions();
    std::string line;
    while (std::getline(in, line))
    {
      std::istringstream fields(line);
      DepartedGrain<dim> g;
      std::string        word;
      for (unsigned int d = 0; d < dim; ++d)
      {
        fields >> word;
        g.reference[d] = std::strtod(word.c_str(), nullptr);
      }
      fields >> word;
      g.volume = std::strtod(word.c_str(), nullptr);
      fields >> word;
      g.rate = std::strtod(word.c_str(), nullptr);
      fields >> word;
      g.diameter = std::strtod(word.c_str(), nullptr);
      AssertThrow(fields,
                  dealii::ExcMessage("Checkpoint: a departed grain's line "
                                     "cannot be read: '" +
                                     line + "'"));
      departed_grains.push_back(g);
    }
  }


  template <int dim>
  void
  Grains<dim>::drain_departed(const double dt)
  {
    for (auto &g : departed_grains)
      g.volume -= g.drained(dt);
    departed_grains.erase(std::remove_if(departed_grains.begin(),
                                         departed_grains.end(),
                                         [](const DepartedGrain<dim> &g)
                                         { return g.volume <= 0; }),
                          departed_grains.end());
  }


  template <int dim>
  void
  Grains<dim>::forget_departed()
  {
    departed_grains.clear();
    departed_need_cells = false;
  }


  template <int dim>
  double
  Grains<dim>::removed_volume() const
  {
    return removed_volume_total;
  }


  template GrainPropertyLayout
  make_grain_property_layout(const GrainParameters<2> &, bool, bool);
  template GrainPropertyLayout
  make_grain_property_layout(const GrainParameters<3> &, bool, bool);
  template class Grains<2>;
  template class Grains<3>;
  template struct GrainStatistics<2>;
  template struct GrainStatistics<3>;
} // namespace ImmersedGrains
