#include <deal.II/base/utilities.h>
#include <deal.II/grid/grid_generator.h>
#include <deal.II/grid/grid_tools.h>

#include <immersed_grains/mesh/geometry.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace ImmersedGrains
{
  std::string
  to_string(const BoundaryType type)
  {
    switch (type)
    {
      case BoundaryType::wall:
        return "wall";
      case BoundaryType::slip:
        return "slip";
      case BoundaryType::open:
        return "open";
      case BoundaryType::velocity:
        return "velocity";
      case BoundaryType::periodic:
        return "periodic";
    }
    return "?";
  }


  template <int dim>
  void
  Geometry<dim>::declare_parameters(dealii::ParameterHandler &prm)
  {
    using dealii::Patterns::Anything;
    using dealii::Patterns::Integer;
    prm.enter_subsection("Mesh");
    {
      prm.declare_entry("Lower corner",
                        dim == 2 ? "0, 0" : "0, 0, 0",
                        Anything(),
                        "Lower corner of the box domain (comma list, metres).");
      prm.declare_entry("Upper corner",
                        dim == 2 ? "1, 1" : "1, 1, 1",
                        Anything(),
                        "Upper corner of the box domain (comma list, metres).");
      prm.declare_entry("Subdivisions",
                        "1",
                        Anything(),
                        "Coarse cells per direction: one number for all "
                        "directions or one per direction (comma list).");
      prm.declare_entry("Initial refinement",
                        "3",
                        Integer(0, 12),
                        "Global refinements of the coarse mesh.");
      prm.declare_entry(
        "Boundary conditions",
        dim == 2 ? "wall, wall, wall, wall" :
                   "wall, wall, wall, wall, wall, wall",
        Anything(),
        "One entry per face in the order x-min, x-max, y-min, y-max[, z-min, "
        "z-max] (boundary ids 0..2dim-1): wall (no-slip), slip (no normal "
        "flow), open (traction-free, Fluid/Open boundary pressure), velocity "
        "(Fluid/Boundary velocity) or periodic (both faces of a direction).");
    }
    prm.leave_subsection();
  }


  template <int dim>
  void
  Geometry<dim>::parse_parameters(dealii::ParameterHandler &prm,
                                  const std::string        &file)
  {
    const InputLocation where{file, "Mesh"};
    prm.enter_subsection("Mesh");
    {
      lower_corner =
        parse_point<dim>(prm.get("Lower corner"), where, "Lower corner");
      upper_corner =
        parse_point<dim>(prm.get("Upper corner"), where, "Upper corner");
      for (unsigned int d = 0; d < dim; ++d)
        where.require(upper_corner[d] > lower_corner[d],
                      "Upper corner",
                      prm.get("Upper corner"),
                      "must be above Lower corner (" + prm.get("Lower corner") +
                        ") in every coordinate");

      const auto n =
        parse_double_list(prm.get("Subdivisions"), where, "Subdivisions");
      where.require(n.size() == 1 || n.size() == dim,
                    "Subdivisions",
                    prm.get("Subdivisions"),
                    "give one number or one per direction");
      subdivisions.clear();
      for (unsigned int d = 0; d < dim; ++d)
      {
        const double v = n.size() == 1 ? n[0] : n[d];
        where.require(v >= 1 && v == std::floor(v) && v < 1e6,
                      "Subdivisions",
                      prm.get("Subdivisions"),
                      "must be positive integers");
        subdivisions.push_back(static_cast<unsigned int>(v));
      }
      initial_refinement = prm.get_integer("Initial refinement");

      const std::string bc_text = prm.get("Boundary conditions");
      const auto        entries = dealii::Utilities::split_string_list(bc_text);
      where.require(entries.size() == 2 * dim,
                    "Boundary conditions",
                    bc_text,
                    "expected " + std::to_string(2 * dim) +
                      " entries, one per face, got " +
                      std::to_string(entries.size()));
      boundary_types.clear();
      for (const std::string &e : entries)
      {
        if (e == "wall")
          boundary_types.push_back(BoundaryType::wall);
        else if (e == "slip")
          boundary_types.push_back(BoundaryType::slip);
        else if (e == "open")
          boundary_types.push_back(BoundaryType::open);
        else if (e == "velocity")
          boundary_types.push_back(BoundaryType::velocity);
        else if (e == "periodic")
          boundary_types.push_back(BoundaryType::periodic);
        else
          where.fail("Boundary conditions",
                     bc_text,
                     "unknown type '" + e +
                       "' (wall, slip, open, velocity, periodic)");
      }
      for (unsigned int d = 0; d < dim; ++d)
        where.require((boundary_types[2 * d] == BoundaryType::periodic) ==
                        (boundary_types[2 * d + 1] == BoundaryType::periodic),
                      "Boundary conditions",
                      bc_text,
                      "periodic faces come in pairs (both faces of a "
                      "direction)");
    }
    prm.leave_subsection();
  }


  template <int dim>
  bool
  Geometry<dim>::is_periodic(const unsigned int direction) const
  {
    return boundary_types[2 * direction] == BoundaryType::periodic;
  }


  template <int dim>
  double
  Geometry<dim>::wrap(const unsigned int direction, const double x) const
  {
    const double lo = lower_corner[direction], hi = upper_corner[direction];
    const double L = hi - lo;
    const double y = lo + std::fmod(std::fmod(x - lo, L) + L, L);
    // (Round-off can land on the upper face itself.)
    return y >= hi ? lo : y;
  }


  template <int dim>
  bool
  Geometry<dim>::has_open_boundary() const
  {
    for (const auto t : boundary_types)
      if (t == BoundaryType::open)
        return true;
    return false;
  }


  template <int dim>
  double
  Geometry<dim>::shortest_side() const
  {
    double side = std::numeric_limits<double>::max();
    for (unsigned int d = 0; d < dim; ++d)
      side = std::min(side, upper_corner[d] - lower_corner[d]);
    return side;
  }


  template <int dim>
  double
  Geometry<dim>::longest_side() const
  {
    double side = 0;
    for (unsigned int d = 0; d < dim; ++d)
      side = std::max(side, upper_corner[d] - lower_corner[d]);
    return side;
  }


  template <int dim>
  double
  Geometry<dim>::wall_gap() const
  {
    const auto no_slip = [&](const unsigned int face)
    {
      return boundary_types[face] == BoundaryType::wall ||
             boundary_types[face] == BoundaryType::velocity;
    };
    double gap = std::numeric_limits<double>::max();
    for (unsigned int d = 0; d < dim; ++d)
    {
      const unsigned int walls =
        (no_slip(2 * d) ? 1 : 0) + (no_slip(2 * d + 1) ? 1 : 0);
      if (walls > 0)
        gap = std::min(gap,
                       (walls == 2 ? 1.0 : 2.0) *
                         (upper_corner[d] - lower_corner[d]));
    }
    return gap < std::numeric_limits<double>::max() ? gap : shortest_side();
  }


  template <int dim>
  double
  Geometry<dim>::shortest_cell_edge(const unsigned int level) const
  {
    double h = std::numeric_limits<double>::max();
    for (unsigned int d = 0; d < dim; ++d)
      h = std::min(h,
                   (upper_corner[d] - lower_corner[d]) / subdivisions[d] /
                     std::pow(2.0, level));
    return h;
  }


  template <int dim>
  void
  Geometry<dim>::create_mesh(
    dealii::parallel::distributed::Triangulation<dim> &tria) const
  {
    create_coarse_mesh(tria);
    tria.refine_global(initial_refinement);
  }


  template <int dim>
  void
  Geometry<dim>::create_coarse_mesh(
    dealii::parallel::distributed::Triangulation<dim> &tria) const
  {
    dealii::GridGenerator::subdivided_hyper_rectangle(
      tria, subdivisions, lower_corner, upper_corner, /*colorize=*/true);

    std::vector<dealii::GridTools::PeriodicFacePair<
      typename dealii::parallel::distributed::Triangulation<
        dim>::cell_iterator>>
      periodic_faces;
    for (unsigned int d = 0; d < dim; ++d)
      if (is_periodic(d))
        dealii::GridTools::collect_periodic_faces(
          tria, 2 * d, 2 * d + 1, d, periodic_faces);
    if (!periodic_faces.empty())
      tria.add_periodicity(periodic_faces);
  }


  template class Geometry<2>;
  template class Geometry<3>;
} // namespace ImmersedGrains
