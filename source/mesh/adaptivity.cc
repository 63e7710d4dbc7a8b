#include <deal.II/base/quadrature_lib.h>
#include <deal.II/distributed/grid_refinement.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_dgq.h>
#include <deal.II/fe/fe_values_extractors.h>
#include <deal.II/grid/grid_tools.h>
#include <deal.II/lac/la_parallel_vector.h>
#include <deal.II/numerics/error_estimator.h>

#include <immersed_grains/fluid/fluid_solver.h>
#include <immersed_grains/grains/grain_parameters.h>
#include <immersed_grains/mesh/adaptivity.h>
#include <immersed_grains/mesh/geometry.h>
#include <immersed_grains/parameters.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>

namespace ImmersedGrains
{
  namespace
  {
    // For each vertex on a periodic face of the domain (a face of its
    // bounding box), the vertices that periodicity identifies with it: its
    // image across that face and, where periodic faces meet, across their
    // edges and corners. Cells around either touch through the periodic
    // boundary. Empty without periodicity. A vertex within 1e-10 of the
    // extent of a face is on it and is taken to lie there exactly; the
    // coordinates along the face compare exactly (a box mesh computes them
    // the same way on both faces, a Gmsh mesh's periodic nodes are copies
    // shifted along the axis, and refinement keeps both so).
    template <int dim>
    std::vector<std::vector<unsigned int>>
    periodic_vertex_images(const dealii::Triangulation<dim> &triangulation,
                           const Geometry<dim>              &geometry)
    {
      std::vector<std::vector<unsigned int>> images;
      std::array<bool, dim>                  periodic{};
      bool                                   any = false;
      for (unsigned int d = 0; d < dim; ++d)
      {
        periodic[d] = geometry.is_periodic(d);
        any |= periodic[d];
      }
      if (!any)
        return images;

      const auto              &vertices = triangulation.get_vertices();
      const std::vector<bool> &used     = triangulation.get_used_vertices();
      const auto              &low      = geometry.lower_corner;
      const auto              &high     = geometry.upper_corner;
      // -1 below, +1 on the upper face, 0 off the faces of axis d.
      const auto side = [&](const double x, const unsigned int d)
      {
        const double tol = 1e-10 * (high[d] - low[d]);
        return !periodic[d]                 ? 0 :
               std::abs(x - low[d]) <= tol  ? -1 :
               std::abs(x - high[d]) <= tol ? 1 :
                                              0;
      };

      std::map<std::array<double, dim>, unsigned int> on_faces;
      for (unsigned int v = 0; v < vertices.size(); ++v)
        if (used[v])
        {
          std::array<double, dim> x;
          bool                    on_face = false;
          for (unsigned int d = 0; d < dim; ++d)
          {
            const int s = side(vertices[v][d], d);
            x[d]        = s < 0 ? low[d] : s > 0 ? high[d] : vertices[v][d];
            on_face |= s != 0;
          }
          if (on_face)
            on_faces.emplace(x, v);
        }

      images.resize(vertices.size());
      for (const auto &[x, v] : on_faces)
        for (unsigned int directions = 1; directions < (1u << dim);
             ++directions)
        {
          std::array<double, dim> image = x;
          bool                    valid = true;
          for (unsigned int d = 0; d < dim && valid; ++d)
            if (directions & (1u << d))
            {
              const int s = side(x[d], d);
              valid       = s != 0;
              image[d]    = s < 0 ? high[d] : low[d];
            }
          if (!valid)
            continue;
          const auto found = on_faces.find(image);
          if (found != on_faces.end())
            images[v].push_back(found->second);
        }
      return images;
    }
  } // namespace


  template <int dim>
  void
  Adaptivity<dim>::Parameters::declare_parameters(dealii::ParameterHandler &prm)
  {
    using namespace dealii::Patterns;
    prm.enter_subsection("Adaptivity");
    {
      prm.declare_entry("Enabled",
                        "false",
                        Bool(),
                        "Refine the mesh around the grains (and where the "
                        "criteria ask) and coarsen it elsewhere as they "
                        "move.");
      prm.declare_entry("Min level",
                        "2",
                        Integer(0, 12),
                        "Coarsest refinement level of the coarse mesh "
                        "(Mesh/Subdivisions) that cells are coarsened to.");
      prm.declare_entry("Max level",
                        "5",
                        Integer(0, 12),
                        "Finest refinement level, reached around the grains.");
      prm.declare_entry(
        "Every steps",
        "auto",
        Anything(),
        "auto: adapt the mesh before the step in which the fastest grain "
        "could have travelled half the band (Band width / 2 of the finest "
        "cells) since the last adaptation, counting the step about to be "
        "taken: the grains stay inside the band whatever the time step, and "
        "the mesh is left alone while they are slow (with Criteria = "
        "velocity, also every 5 steps). With Band lookahead, not before the "
        "lookahead runs out or a grain may have strayed half the band from "
        "its straight path. A number N: adapt before every N-th fluid step "
        "(0: only before the first).");
      prm.declare_entry(
        "Criteria",
        "grains",
        MultipleSelection("grains|velocity"),
        "grains: every cell holding a grain and Band width layers of cells "
        "around it at Max level, the rest coarsened towards Min level. "
        "velocity: the Kelly estimator of the fluid velocity refines "
        "Refine fraction and coarsens Coarsen fraction of the cells (by "
        "number) between the two levels, for wakes.");
      prm.declare_entry(
        "Band width",
        "auto",
        Anything(),
        "Layers of cells (sharing a vertex) around the cells that hold "
        "grains (and their paths, with Band lookahead) that are refined with "
        "them, 0 to 20. auto: 1 where the band looks ahead along the grains' "
        "paths (Band lookahead > 0 with Every steps = auto and Criteria = "
        "grains: the path gives the band its length where the grains go, "
        "and one layer is the margin for their deviation from it), 2 "
        "otherwise.");
      prm.declare_entry("Refine fraction",
                        "0.1",
                        Double(0, 1),
                        "Criteria = velocity: the share of cells refined.");
      prm.declare_entry("Coarsen fraction",
                        "0.3",
                        Double(0, 1),
                        "Criteria = velocity: the share of cells coarsened.");
      prm.declare_entry(
        "Minimum solid fraction",
        "0",
        Double(0, 1),
        "Criteria = grains: the grains in a cell start the band only where "
        "they fill at least this fraction of the volume (area in 2D) of a "
        "cell of the finest size within it; 0: any grain. Above 0, grains "
        "that have left a cloud one by one (the tail of its wake) stay on "
        "the coarse mesh, where they settle in the flow the cloud makes, "
        "and the fine mesh stays on the cloud (doc/adaptivity.md). One grain "
        "of diameter d in a cell of edge h fills (pi/6)(d/h)^3 of it in 3D, "
        "(pi/4)(d/h)^2 in 2D.");
      prm.declare_entry(
        "Band lookahead",
        "2",
        Double(0, 64),
        "Criteria = grains with Every steps = auto: the band also covers "
        "each grain's straight path along its velocity, the fastest grain's "
        "this many finest cells ahead (the others' as far as they go in the "
        "same time), and the mesh is adapted again when that time is over "
        "or a grain may have strayed half the band from its path (each "
        "grain carries its deviation). Grains that move together (a "
        "falling cloud) then cross several cells between adaptations "
        "instead of one, for a band a few cells longer; one adaptation "
        "refines the cells ahead in as many passes as they lack levels. "
        "0: the band around the grains only (doc/adaptivity.md). The "
        "default, with Band width = auto (1), was measured on the falling "
        "clouds: 20-40 % less wall time than the band of 2 layers without "
        "it, the clouds within a few micrometres of where they were.");
      prm.declare_entry(
        "Minimum cell size",
        "2",
        Double(0),
        "No cell is refined into children smaller than this many diameters "
        "of the largest grain: the drag closures hold for a grain inside a "
        "cell larger than itself (the cell is the averaging volume), and "
        "were validated from 2 diameters up (doc/theory.md).");
    }
    prm.leave_subsection();
  }


  template <int dim>
  void
  Adaptivity<dim>::Parameters::parse_parameters(dealii::ParameterHandler &prm,
                                                const std::string        &file,
                                                const bool fluid_enabled)
  {
    const InputLocation where{file, "Adaptivity"};
    prm.enter_subsection("Adaptivity");
    {
      enabled   = prm.get_bool("Enabled");
      min_level = prm.get_integer("Min level");
      max_level = prm.get_integer("Max level");
      // "auto" or a whole number from 0 to @p largest (then in @p value).
      const auto auto_or_count = [&](const std::string &entry,
                                     const unsigned int largest,
                                     const std::string &what,
                                     unsigned int      &value)
      {
        const std::string text = prm.get(entry);
        if (text == "auto")
          return true;
        char      *end    = nullptr;
        const long number = std::strtol(text.c_str(), &end, 10);
        where.require(!text.empty() && end != nullptr && *end == '\0' &&
                        number >= 0 && number <= static_cast<long>(largest),
                      entry,
                      text,
                      "is neither auto nor " + what);
        value = static_cast<unsigned int>(number);
        return false;
      };
      follow_grains = auto_or_count("Every steps",
                                    std::numeric_limits<int>::max(),
                                    "a number of steps (0 or more)",
                                    every_steps);
      const auto criteria =
        dealii::Utilities::split_string_list(prm.get("Criteria"));
      around_grains =
        std::find(criteria.begin(), criteria.end(), "grains") != criteria.end();
      velocity_kelly =
        std::find(criteria.begin(), criteria.end(), "velocity") !=
        criteria.end();
      refine_fraction    = prm.get_double("Refine fraction");
      coarsen_fraction   = prm.get_double("Coarsen fraction");
      min_cell_size      = prm.get_double("Minimum cell size");
      min_solid_fraction = prm.get_double("Minimum solid fraction");
      band_lookahead     = prm.get_double("Band lookahead");
      if (auto_or_count("Band width",
                        20,
                        "a number of cell layers from 0 to 20",
                        band_width))
        band_width = looks_ahead() ? 1 : 2;
      if (enabled)
      {
        where.require(min_level <= max_level,
                      "Min level",
                      prm.get("Min level"),
                      "is above Max level (" + prm.get("Max level") + ")");
        where.require(fluid_enabled,
                      "Enabled",
                      prm.get("Enabled"),
                      "needs a fluid (Fluid/Enabled = true): the mesh only "
                      "carries the fluid and the coupling");
        where.require(refine_fraction + coarsen_fraction <= 1,
                      "Refine fraction",
                      prm.get("Refine fraction"),
                      "plus Coarsen fraction (" + prm.get("Coarsen fraction") +
                        ") exceeds 1");
      }
    }
    prm.leave_subsection();
  }


  template <int dim>
  Adaptivity<dim>::Adaptivity(
    const Parameters                                  &parameters,
    const Geometry<dim>                               &geometry,
    dealii::parallel::distributed::Triangulation<dim> &tria,
    const double                                       smallest_cell)
      : parameters(parameters)
      , geometry(geometry)
      , triangulation(tria)
      , smallest_cell(smallest_cell)
  {
    if (!geometry.is_box())
    {
      // Buckets about a coarse cell wide over the bounding box, each with
      // the coarse cells whose boxes reach into it.
      for (const auto &cell : triangulation.cell_iterators_on_level(0))
      {
        coarse.push_back(cell);
        coarse_boxes.push_back(cell->bounding_box());
      }
      coarse_buckets.reinit(geometry.lower_corner,
                            geometry.upper_corner,
                            std::pow(geometry.volume() / coarse.size(),
                                     1.0 / dim),
                            coarse_boxes);
      return;
    }
    // The coarse mesh is the box's Subdivisions (Geometry), whatever the
    // order in which the triangulation holds its coarse cells.
    unsigned int n = 1;
    for (unsigned int d = 0; d < dim; ++d)
      n *= geometry.subdivisions[d];
    coarse.resize(n, triangulation.end());
    for (const auto &cell : triangulation.cell_iterators_on_level(0))
    {
      const dealii::Point<dim> c = cell->center();
      unsigned int             k = 0, stride = 1;
      for (unsigned int d = 0; d < dim; ++d)
      {
        const double width =
          (geometry.upper_corner[d] - geometry.lower_corner[d]) /
          geometry.subdivisions[d];
        k += stride * static_cast<unsigned int>(
                        std::floor((c[d] - geometry.lower_corner[d]) / width));
        stride *= geometry.subdivisions[d];
      }
      Assert(k < n && coarse[k] == triangulation.end(),
             dealii::ExcInternalError());
      coarse[k] = cell;
    }
  }


  template <int dim>
  typename dealii::Triangulation<dim>::active_cell_iterator
  Adaptivity<dim>::active_cell_at(dealii::Point<dim> point) const
  {
    for (unsigned int d = 0; d < dim; ++d)
      if (geometry.is_periodic(d))
        point[d] = geometry.wrap(d, point[d]);
    if (!geometry.is_box())
      return mesh_cell_at(point);
    const auto  &lo = geometry.lower_corner;
    const auto  &hi = geometry.upper_corner;
    unsigned int k = 0, stride = 1;
    for (unsigned int d = 0; d < dim; ++d)
    {
      const double length = hi[d] - lo[d];
      if (point[d] < lo[d] || point[d] > hi[d])
        return triangulation.end();
      const unsigned int n = geometry.subdivisions[d];
      k += stride * std::min(n - 1,
                             static_cast<unsigned int>(
                               std::floor((point[d] - lo[d]) / length * n)));
      stride *= n;
    }
    // Down the tree: a child's number has bit d set where it lies on the
    // upper side along axis d (deal.II's numbering of a box's children).
    typename dealii::Triangulation<dim>::cell_iterator cell = coarse[k];
    while (cell->has_children())
    {
      const dealii::Point<dim> centre = cell->center();
      unsigned int             child  = 0;
      for (unsigned int d = 0; d < dim; ++d)
        if (point[d] >= centre[d])
          child |= 1u << d;
      cell = cell->child(child);
    }
    return typename dealii::Triangulation<dim>::active_cell_iterator(cell);
  }


  template <int dim>
  typename dealii::Triangulation<dim>::active_cell_iterator
  Adaptivity<dim>::mesh_cell_at(const dealii::Point<dim> &point) const
  {
    // The bucket of the point, then its coarse cells one by one, then
    // down the tree of the one that holds it. Axis-parallel cells are their
    // boxes, taken half-open as on a box (a point on a face belongs to the
    // cell above it), and their children are numbered as a box's.
    const auto &lo = geometry.lower_corner;
    const auto &hi = geometry.upper_corner;
    for (unsigned int d = 0; d < dim; ++d)
      if (point[d] < lo[d] || point[d] > hi[d])
        return triangulation.end();
    const bool cartesian = geometry.is_cartesian();
    const auto holds     = [&](const dealii::BoundingBox<dim> &box)
    {
      const auto &[a, b] = box.get_boundary_points();
      for (unsigned int d = 0; d < dim; ++d)
        if (point[d] < a[d] || point[d] > b[d] ||
            (point[d] == b[d] && b[d] < hi[d]))
          return false;
      return true;
    };
    for (const unsigned int k : coarse_buckets.at(point))
      if (holds(coarse_boxes[k]) &&
          (cartesian || coarse[k]->point_inside(point)))
      {
        typename dealii::Triangulation<dim>::cell_iterator cell = coarse[k];
        while (cell->has_children())
        {
          unsigned int child = 0;
          if (cartesian)
          {
            const dealii::Point<dim> centre = cell->center();
            for (unsigned int d = 0; d < dim; ++d)
              if (point[d] >= centre[d])
                child |= 1u << d;
          }
          else
            while (child + 1 < cell->n_children() &&
                   !cell->child(child)->point_inside(point))
              ++child;
          cell = cell->child(child);
        }
        return typename dealii::Triangulation<dim>::active_cell_iterator(cell);
      }
    return triangulation.end();
  }


  template <int dim>
  bool
  Adaptivity<dim>::dense_enough(
    const typename dealii::Triangulation<dim>::active_cell_iterator &cell,
    const dealii::Particles::ParticleHandler<dim>                   &grains,
    const unsigned int radius_property) const
  {
    if (parameters.min_solid_fraction <= 0)
      return true;
    // The cell's finest descendants: halved while levels remain and the
    // children stay above the floor (as mark_cells() refines).
    unsigned int n    = 1;
    double       edge = cell->minimum_vertex_distance();
    for (unsigned int level = cell->level();
         level < parameters.max_level && edge >= 2 * smallest_cell;
         ++level, edge /= 2)
      n *= 2;
    const dealii::Point<dim> corner = cell->vertex(0);
    const dealii::Point<dim> far    = cell->vertex((1 << dim) - 1);
    const double             needed =
      parameters.min_solid_fraction * cell->measure() / std::pow(n, dim);
    // Up to 12 levels apart in 3D the bins number 2^36: 64-bit indices.
    std::map<std::uint64_t, double> filled;
    for (const auto &grain : grains.particles_in_cell(cell))
    {
      std::uint64_t bin = 0, stride = 1;
      for (unsigned int d = 0; d < dim; ++d)
      {
        const double xi =
          (grain.get_location()[d] - corner[d]) / (far[d] - corner[d]);
        bin += stride * std::min(n - 1,
                                 static_cast<unsigned int>(
                                   std::max(0.0, std::floor(xi * n))));
        stride *= n;
      }
      double &volume = filled[bin];
      volume += grain_volume<dim>(grain.get_properties()[radius_property]);
      if (volume >= needed)
        return true;
    }
    return false;
  }


  template <int dim>
  std::vector<unsigned int>
  Adaptivity<dim>::grain_band(
    const dealii::Particles::ParticleHandler<dim> &grains,
    const GrainProperties                         &properties,
    const double                                   shortest_edge,
    const bool                                     new_horizon)
  {
    const unsigned int radius_property = properties.radius;
    // One value per cell with ghosts: a DG0 field.
    dealii::DoFHandler<dim>   cells(triangulation);
    const dealii::FE_DGQ<dim> fe(0);
    cells.distribute_dofs(fe);
    dealii::IndexSet relevant;
    dealii::DoFTools::extract_locally_relevant_dofs(cells, relevant);
    dealii::LinearAlgebra::distributed::Vector<double> marked(
      cells.locally_owned_dofs(), relevant, triangulation.get_communicator());

    std::vector<dealii::types::global_dof_index> index(1);
    // The grains that start the band: where they are and how they move.
    const bool lookahead = parameters.looks_ahead();
    std::vector<std::pair<dealii::Point<dim>, dealii::Tensor<1, dim>>> paths;
    double fastest = 0;
    for (const auto &cell : cells.active_cell_iterators())
      if (cell->is_locally_owned() && grains.n_particles_in_cell(cell) > 0 &&
          dense_enough(cell, grains, radius_property))
      {
        cell->get_dof_indices(index);
        marked[index[0]] = 1;
        if (lookahead)
          for (const auto &grain : grains.particles_in_cell(cell))
          {
            dealii::Tensor<1, dim> v;
            for (unsigned int d = 0; d < dim; ++d)
              v[d] = grain.get_properties()[properties.velocity + d];
            paths.emplace_back(grain.get_location(), v);
            fastest = std::max(fastest, v.norm());
          }
      }

    if (lookahead)
    {
      if (new_horizon)
      {
        fastest = dealii::Utilities::MPI::max(fastest,
                                              triangulation.get_communicator());
        horizon =
          fastest > 0 ? parameters.band_lookahead * shortest_edge / fastest : 0;
      }
      // Each path is sampled every half finest cell; the cells of the
      // samples join the grains' cells. Paths that leave this rank's cells
      // go to every rank, which marks its own.
      const auto mark_path = [&](const dealii::Point<dim>     &start,
                                 const dealii::Tensor<1, dim> &reach)
      {
        const unsigned int n = static_cast<unsigned int>(
          std::ceil(reach.norm() / (0.5 * shortest_edge)));
        bool elsewhere = false;
        for (unsigned int k = 1; k <= n; ++k)
        {
          const auto cell = active_cell_at(start + (k / double(n)) * reach);
          if (cell == triangulation.end())
            continue; // beyond a wall
          if (!cell->is_locally_owned())
          {
            elsewhere = true;
            continue;
          }
          typename dealii::DoFHandler<dim>::active_cell_iterator(&triangulation,
                                                                 cell->level(),
                                                                 cell->index(),
                                                                 &cells)
            ->get_dof_indices(index);
          marked[index[0]] = 1;
        }
        return elsewhere;
      };
      std::vector<double> leaving;
      for (const auto &[x, v] : paths)
        if (mark_path(x, horizon * v))
          for (unsigned int d = 0; d < dim; ++d)
          {
            leaving.push_back(x[d]);
            leaving.push_back(horizon * v[d]);
          }
      const MPI_Comm comm = triangulation.get_communicator();
      if (dealii::Utilities::MPI::n_mpi_processes(comm) > 1)
      {
        const auto all = dealii::Utilities::MPI::all_gather(comm, leaving);
        for (unsigned int rank = 0; rank < all.size(); ++rank)
          if (rank != dealii::Utilities::MPI::this_mpi_process(comm))
            for (std::size_t i = 0; i + 2 * dim <= all[rank].size();
                 i += 2 * dim)
            {
              dealii::Point<dim>     x;
              dealii::Tensor<1, dim> reach;
              for (unsigned int d = 0; d < dim; ++d)
              {
                x[d]     = all[rank][i + 2 * d];
                reach[d] = all[rank][i + 2 * d + 1];
              }
              mark_path(x, reach);
            }
      }
    }

    // Whether a cell (of the triangulation or of `cells`) is in the band.
    std::vector<dealii::types::global_dof_index> other_index(1);
    const auto is_marked = [&](const auto &other)
    {
      if (other->is_artificial())
        return false;
      typename dealii::DoFHandler<dim>::active_cell_iterator(&triangulation,
                                                             other->level(),
                                                             other->index(),
                                                             &cells)
        ->get_dof_indices(other_index);
      return marked[other_index[0]] != 0;
    };
    const auto vertex_cells = dealii::GridTools::vertex_to_cell_map(
      static_cast<const dealii::Triangulation<dim> &>(triangulation));
    const auto periodic_images = periodic_vertex_images(
      static_cast<const dealii::Triangulation<dim> &>(triangulation), geometry);
    // One layer beyond the band: cells there are kept, not coarsened, or
    // a parent coarsened next to the band would reach into it and be
    // refined again at the next adaptation, and so on.
    for (unsigned int layer = 0; layer < parameters.band_width + 1; ++layer)
    {
      marked.update_ghost_values();
      std::vector<dealii::types::global_dof_index> grow;
      for (const auto &cell : cells.active_cell_iterators())
      {
        if (!cell->is_locally_owned())
          continue;
        cell->get_dof_indices(index);
        if (marked[index[0]] != 0)
          continue;
        // Cells touch through a shared vertex or, across a periodic
        // boundary, through one of its images (with p4est's 2:1 balance
        // across periodic faces every cell there has a vertex with one).
        const auto touches_band = [&](const unsigned int vertex)
        {
          for (const auto &other : vertex_cells[vertex])
            if (is_marked(other))
              return true;
          return false;
        };
        bool near = false;
        for (unsigned int v = 0; v < cell->n_vertices() && !near; ++v)
        {
          const unsigned int vertex = cell->vertex_index(v);
          near                      = touches_band(vertex);
          if (!periodic_images.empty())
            for (const unsigned int image : periodic_images[vertex])
              near = near || touches_band(image);
        }
        if (near)
          grow.push_back(index[0]);
      }
      marked.zero_out_ghost_values();
      for (const auto i : grow)
        marked[i] = layer + 2;
    }

    std::vector<unsigned int> band(triangulation.n_active_cells(), 0);
    for (const auto &cell : cells.active_cell_iterators())
      if (cell->is_locally_owned())
      {
        cell->get_dof_indices(index);
        band[cell->active_cell_index()] =
          static_cast<unsigned int>(marked[index[0]]);
      }
    return band;
  }


  template <int dim>
  bool
  Adaptivity<dim>::due(const unsigned int step,
                       const double       grain_reach,
                       const double       shortest_edge,
                       const bool         with_grains) const
  {
    if (!parameters.enabled)
      return false;
    if (!parameters.follow_grains)
      return parameters.every_steps > 0 && step % parameters.every_steps == 0;
    // The band moves with the grains; the velocity criterion keeps the
    // fixed rhythm it had (the wake does not announce its motion).
    const bool by_grains = parameters.around_grains && with_grains;
    const bool by_velocity =
      (parameters.velocity_kelly || !by_grains) && step % 5 == 0;
    return by_velocity || (by_grains && grain_reach > 0 &&
                           grain_reach >= travel_allowance(shortest_edge));
  }


  template <int dim>
  bool
  Adaptivity<dim>::mark_cells(
    const dealii::Particles::ParticleHandler<dim> *grains,
    const GrainProperties                         &properties,
    const FluidSolver<dim>                        *fluid,
    const double                                   shortest_edge,
    const bool                                     refine_only)
  {
    for (const auto &cell : triangulation.active_cell_iterators())
      if (cell->is_locally_owned())
      {
        cell->clear_refine_flag();
        cell->clear_coarsen_flag();
      }

    if (parameters.velocity_kelly && fluid != nullptr && !refine_only)
    {
      dealii::Vector<float> indicators(triangulation.n_active_cells());
      const dealii::FEValuesExtractors::Vector velocities(0);
      dealii::KellyErrorEstimator<dim>::estimate(
        fluid->get_dof_handler(),
        dealii::QGauss<dim - 1>(3),
        std::map<dealii::types::boundary_id, const dealii::Function<dim> *>(),
        fluid->get_solution(),
        indicators,
        fluid->get_dof_handler().get_fe().component_mask(velocities),
        nullptr,
        dealii::numbers::invalid_unsigned_int,
        triangulation.locally_owned_subdomain());
      dealii::parallel::distributed::GridRefinement::
        refine_and_coarsen_fixed_number(triangulation,
                                        indicators,
                                        parameters.refine_fraction,
                                        parameters.coarsen_fraction);
    }

    std::vector<unsigned int> band;
    if (parameters.around_grains && grains != nullptr)
      band = grain_band(*grains, properties, shortest_edge, !refine_only);

    for (const auto &cell : triangulation.active_cell_iterators())
    {
      if (!cell->is_locally_owned())
        continue;
      const unsigned int level = cell->level();
      const unsigned int distance =
        band.empty() ? 0 : band[cell->active_cell_index()];
      const bool in_band =
        distance > 0 && distance <= parameters.band_width + 1;
      const bool beside_band = distance == parameters.band_width + 2;
      if (refine_only)
      {
        // Only what the band still lacks (the levels' limits as below).
        if (in_band && level < parameters.max_level &&
            cell->minimum_vertex_distance() >= 2 * smallest_cell)
          cell->set_refine_flag();
        continue;
      }
      if (in_band)
      {
        cell->clear_coarsen_flag();
        cell->set_refine_flag();
      }
      else if (beside_band)
        cell->clear_coarsen_flag();
      else if (!parameters.velocity_kelly)
        cell->set_coarsen_flag();
      // The levels and the cell-size floor overrule the criteria.
      if (level >= parameters.max_level ||
          cell->minimum_vertex_distance() < 2 * smallest_cell)
        cell->clear_refine_flag();
      if (level <= parameters.min_level)
        cell->clear_coarsen_flag();
      if (level < parameters.min_level)
        cell->set_refine_flag();
      if (level > parameters.max_level)
      {
        cell->clear_refine_flag();
        cell->set_coarsen_flag();
      }
      if ((in_band || beside_band) && cell->coarsen_flag_set() &&
          level <= parameters.max_level)
        cell->clear_coarsen_flag();
    }

    // Whether any owned cell carries a flag, on any rank.
    const auto flagged = [this]()
    {
      bool any = false;
      for (const auto &cell : triangulation.active_cell_iterators())
        if (cell->is_locally_owned() &&
            (cell->refine_flag_set() || cell->coarsen_flag_set()))
        {
          any = true;
          break;
        }
      return dealii::Utilities::MPI::logical_or(
        any, triangulation.get_communicator());
    };
    if (!flagged())
      return false;
    // The triangulation keeps a coarsen flag only where all siblings carry
    // one, and adds the refinements that keep neighbours within a level.
    triangulation.prepare_coarsening_and_refinement();
    return flagged();
  }


  template class Adaptivity<2>;
  template class Adaptivity<3>;
} // namespace ImmersedGrains
