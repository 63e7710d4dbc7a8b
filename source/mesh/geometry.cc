#include <deal.II/base/utilities.h>
#include <deal.II/fe/mapping_cartesian.h>
#include <deal.II/fe/mapping_q.h>
#include <deal.II/fe/mapping_q1.h>
#include <deal.II/grid/grid_generator.h>
#include <deal.II/grid/grid_in.h>
#include <deal.II/grid/grid_tools.h>
#include <deal.II/grid/grid_tools_cache.h>
#include <deal.II/grid/manifold_lib.h>

#include <immersed_grains/mesh/geometry.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <set>
#include <sstream>

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
      prm.declare_entry(
        "Geometry",
        "box",
        dealii::Patterns::Selection("box|gmsh"),
        "box: the box of Lower corner, Upper corner and Subdivisions; gmsh: "
        "the mesh of File (Gmsh .msh, format 2.2 or 4.1 ASCII, "
        "quadrilaterals in 2D, hexahedra in 3D, physical group ids as "
        "boundary ids).");
      prm.declare_entry("File",
                        "",
                        Anything(),
                        "The Gmsh mesh of Geometry = gmsh; a relative path is "
                        "read from the folder of the parameter file.");
      prm.declare_entry(
        "Manifolds",
        "",
        Anything(),
        "Curved boundaries of a Gmsh mesh, kept exact under refinement and "
        "met so by grains: 'id: cylinder x0, y0' (2D: a circle), 'id: "
        "cylinder x0, y0, z0, ax, ay, az' (3D: a point of the axis and its "
        "direction) or 'id: sphere x0, y0[, z0]', separated by ';'.");
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
        "A box: one entry per face in the order x-min, x-max, y-min, "
        "y-max[, z-min, z-max] (boundary ids 0..2dim-1). A Gmsh mesh: "
        "'id: type' pairs separated by commas, one for every boundary id "
        "of the mesh (e.g. '1: inflow, 2: open, 3: wall'). Types: wall "
        "(no-slip), slip (no normal flow), open (traction-free, "
        "Fluid/Open boundary pressure; grains leave), inflow or velocity "
        "(Fluid/Inflow velocity; grains meet it as a wall) or periodic "
        "(both faces of a box's direction; on a Gmsh mesh two ids on the "
        "two faces of its bounding box normal to an axis, their nodes "
        "matching by a shift along it).");
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
      box                       = prm.get("Geometry") == "box";
      initial_refinement        = prm.get_integer("Initial refinement");
      const std::string bc_text = prm.get("Boundary conditions");
      if (box)
      {
        where.require(prm.get("Manifolds").empty(),
                      "Manifolds",
                      prm.get("Manifolds"),
                      "curved boundaries need Geometry = gmsh");
        parse_box(prm, where);
        parse_box_conditions(where, bc_text);
      }
      else
      {
        where.require(!prm.get("File").empty(),
                      "File",
                      "",
                      "Geometry = gmsh needs the mesh's file");
        std::filesystem::path path(prm.get("File"));
        if (path.is_relative())
          path = std::filesystem::path(file).parent_path() / path;
        mesh_file = path.lexically_normal().string();
        read_mesh(where, prm.get("File"));
        parse_mesh_conditions(where, bc_text);
        parse_manifolds(where, prm.get("Manifolds"));
      }
    }
    prm.leave_subsection();
  }


  template <int dim>
  void
  Geometry<dim>::parse_box(dealii::ParameterHandler &prm,
                           const InputLocation      &where)
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
    domain_volume = 1;
    coarse_edge   = std::numeric_limits<double>::max();
    for (unsigned int d = 0; d < dim; ++d)
    {
      const double v = n.size() == 1 ? n[0] : n[d];
      where.require(v >= 1 && v == std::floor(v) && v < 1e6,
                    "Subdivisions",
                    prm.get("Subdivisions"),
                    "must be positive integers");
      subdivisions.push_back(static_cast<unsigned int>(v));
      domain_volume *= upper_corner[d] - lower_corner[d];
      coarse_edge =
        std::min(coarse_edge, (upper_corner[d] - lower_corner[d]) / v);
    }
    cartesian = true;
  }


  namespace
  {
    std::optional<BoundaryType>
    boundary_type_named(const std::string &name)
    {
      if (name == "wall")
        return BoundaryType::wall;
      if (name == "slip")
        return BoundaryType::slip;
      if (name == "open")
        return BoundaryType::open;
      if (name == "velocity" || name == "inflow")
        return BoundaryType::velocity;
      if (name == "periodic")
        return BoundaryType::periodic;
      return std::nullopt;
    }

    const char *const type_names = "wall, slip, open, inflow, periodic";

    std::string
    id_list(const std::set<unsigned int> &ids)
    {
      std::string text;
      for (const unsigned int id : ids)
        text += (text.empty() ? "" : ", ") + std::to_string(id);
      return text;
    }
  } // namespace


  template <int dim>
  void
  Geometry<dim>::parse_box_conditions(const InputLocation &where,
                                      const std::string   &bc_text)
  {
    const auto entries = dealii::Utilities::split_string_list(bc_text);
    boundary_types.clear();
    if (bc_text.find(':') != std::string::npos)
      parse_id_conditions(where, bc_text);
    else
    {
      where.require(entries.size() == 2 * dim,
                    "Boundary conditions",
                    bc_text,
                    "expected " + std::to_string(2 * dim) +
                      " entries, one per face, got " +
                      std::to_string(entries.size()));
      for (unsigned int f = 0; f < entries.size(); ++f)
      {
        const auto type = boundary_type_named(entries[f]);
        if (!type)
          where.fail("Boundary conditions",
                     bc_text,
                     "unknown type '" + entries[f] + "' (" + type_names + ")");
        boundary_types[f] = *type;
      }
    }
    std::set<unsigned int> named;
    for (const auto &[id, type] : boundary_types)
      named.insert(id);
    std::set<unsigned int> faces;
    for (unsigned int f = 0; f < 2 * dim; ++f)
      faces.insert(f);
    where.require(named == faces,
                  "Boundary conditions",
                  bc_text,
                  "a box's boundary ids are " + id_list(faces) +
                    ", one per face");
    for (unsigned int d = 0; d < dim; ++d)
    {
      where.require((boundary_types[2 * d] == BoundaryType::periodic) ==
                      (boundary_types[2 * d + 1] == BoundaryType::periodic),
                    "Boundary conditions",
                    bc_text,
                    "periodic faces come in pairs (both faces of a "
                    "direction)");
      periodic[d]     = boundary_types[2 * d] == BoundaryType::periodic;
      periodic_ids[d] = {2 * d, 2 * d + 1};
    }
  }


  template <int dim>
  void
  Geometry<dim>::parse_id_conditions(const InputLocation &where,
                                     const std::string   &bc_text)
  {
    for (const std::string &entry :
         dealii::Utilities::split_string_list(bc_text, ','))
    {
      const auto   pair = dealii::Utilities::split_string_list(entry, ':');
      unsigned int id   = 0;
      bool         ok   = pair.size() == 2 && !pair[0].empty() &&
                pair[0].find_first_not_of("0123456789") == std::string::npos &&
                pair[0].size() < 6;
      if (ok)
        id = std::stoi(pair[0]);
      if (!ok || id >= dealii::numbers::internal_face_boundary_id)
        where.fail("Boundary conditions",
                   bc_text,
                   "'" + entry + "' is not 'id: type' with id a boundary id");
      const auto type = boundary_type_named(pair[1]);
      if (!type)
        where.fail("Boundary conditions",
                   bc_text,
                   "unknown type '" + pair[1] + "' (" + type_names + ")");
      where.require(boundary_types.count(id) == 0,
                    "Boundary conditions",
                    bc_text,
                    "boundary id " + std::to_string(id) + " is named twice");
      boundary_types[id] = *type;
    }
  }


  template <int dim>
  void
  Geometry<dim>::parse_mesh_conditions(const InputLocation &where,
                                       const std::string   &bc_text)
  {
    std::set<unsigned int> on_mesh;
    for (const auto &cell : coarse_mesh->active_cell_iterators())
      for (const unsigned int f : cell->face_indices())
        if (cell->at_boundary(f))
          on_mesh.insert(cell->face(f)->boundary_id());
    where.require(bc_text.find(':') != std::string::npos,
                  "Boundary conditions",
                  bc_text,
                  "a Gmsh mesh needs 'id: type' pairs for its boundary ids " +
                    id_list(on_mesh));
    boundary_types.clear();
    parse_id_conditions(where, bc_text);
    for (const unsigned int id : on_mesh)
      where.require(
        boundary_types.count(id) == 1,
        "Boundary conditions",
        bc_text,
        "boundary id " + std::to_string(id) + " of " + mesh_file +
          " has no type (the mesh's boundary ids: " + id_list(on_mesh) +
          (id == 0 ? "; 0 is a boundary in no physical group" : "") + ")");
    for (const auto &[id, type] : boundary_types)
    {
      where.require(on_mesh.count(id) == 1,
                    "Boundary conditions",
                    bc_text,
                    "boundary id " + std::to_string(id) + " is not on " +
                      mesh_file + "'s boundary (its ids: " + id_list(on_mesh) +
                      ")");
    }
    pair_periodic_ids(where, bc_text);
  }


  template <int dim>
  void
  Geometry<dim>::pair_periodic_ids(const InputLocation &where,
                                   const std::string   &bc_text)
  {
    // Each periodic id must lie on one face of the bounding box, and the
    // two faces normal to an axis pair up: the grains, the neighbour
    // search and the adaptive mesh wrap positions by the box's extent.
    periodic.fill(false);
    std::array<std::array<int, 2>, dim> on_side;
    for (auto &sides : on_side)
      sides = {{-1, -1}};
    const char *const axis_names = "xyz";
    for (const auto &[id, type] : boundary_types)
    {
      if (type != BoundaryType::periodic)
        continue;
      // Per axis and side, whether every vertex of the id's faces lies on
      // that face of the bounding box.
      std::array<std::array<bool, 2>, dim> flat;
      for (auto &sides : flat)
        sides = {{true, true}};
      for (const auto &cell : coarse_mesh->active_cell_iterators())
        for (const unsigned int f : cell->face_indices())
          if (cell->at_boundary(f) && cell->face(f)->boundary_id() == id)
            for (const unsigned int v : cell->face(f)->vertex_indices())
              for (unsigned int d = 0; d < dim; ++d)
              {
                const double x   = cell->face(f)->vertex(v)[d];
                const double tol = 1e-10 * (upper_corner[d] - lower_corner[d]);
                flat[d][0] = flat[d][0] && std::abs(x - lower_corner[d]) <= tol;
                flat[d][1] = flat[d][1] && std::abs(x - upper_corner[d]) <= tol;
              }
      bool placed = false;
      for (unsigned int d = 0; d < dim && !placed; ++d)
        for (unsigned int side = 0; side < 2 && !placed; ++side)
          if (flat[d][side])
          {
            where.require(on_side[d][side] < 0,
                          "Boundary conditions",
                          bc_text,
                          "periodic boundary ids " +
                            std::to_string(on_side[d][side]) + " and " +
                            std::to_string(id) + " lie on the same face " +
                            axis_names[d] + " = " +
                            std::to_string(side == 0 ? lower_corner[d] :
                                                       upper_corner[d]) +
                            " of " + mesh_file + "; one id per face");
            on_side[d][side] = id;
            placed           = true;
          }
      where.require(placed,
                    "Boundary conditions",
                    bc_text,
                    "periodic boundary id " + std::to_string(id) + " of " +
                      mesh_file +
                      " does not lie on a face of the mesh's bounding box "
                      "(periodic pairs are the two faces normal to an axis)");
    }
    for (unsigned int d = 0; d < dim; ++d)
    {
      if (on_side[d][0] < 0 && on_side[d][1] < 0)
        continue;
      const int lone = on_side[d][0] < 0 ? on_side[d][1] : on_side[d][0];
      where.require(on_side[d][0] >= 0 && on_side[d][1] >= 0,
                    "Boundary conditions",
                    bc_text,
                    "periodic boundary id " + std::to_string(lone) + " of " +
                      mesh_file + " has no periodic partner on the opposite " +
                      axis_names[d] + " face");
      periodic[d]     = true;
      periodic_ids[d] = {static_cast<dealii::types::boundary_id>(on_side[d][0]),
                         static_cast<dealii::types::boundary_id>(
                           on_side[d][1])};
      std::vector<dealii::GridTools::PeriodicFacePair<
        typename dealii::Triangulation<dim>::cell_iterator>>
           pairs;
      bool matched = true;
      try
      {
        dealii::GridTools::collect_periodic_faces(*coarse_mesh,
                                                  periodic_ids[d].first,
                                                  periodic_ids[d].second,
                                                  d,
                                                  pairs);
      }
      catch (...)
      {
        matched = false;
      }
      where.require(matched,
                    "Boundary conditions",
                    bc_text,
                    "the faces of periodic boundary ids " +
                      std::to_string(on_side[d][0]) + " and " +
                      std::to_string(on_side[d][1]) + " of " + mesh_file +
                      " do not match by a shift along " + axis_names[d] +
                      " (Gmsh: Periodic Curve or Periodic Surface)");
    }
  }


  template <int dim>
  dealii::Point<dim>
  Geometry<dim>::CurvedBoundary::project(const dealii::Point<dim> &x) const
  {
    dealii::Tensor<1, dim> r = x - center;
    if (!sphere && dim == 3)
      r -= (r * axis) * axis;
    const double length = r.norm();
    return length > 0 ? x + (radius / length - 1) * r : x;
  }


  template <int dim>
  void
  Geometry<dim>::parse_manifolds(const InputLocation &where,
                                 const std::string   &text)
  {
    curved_boundaries.clear();
    for (const std::string &entry :
         dealii::Utilities::split_string_list(text, ';'))
    {
      const auto colon = entry.find(':');
      const auto fail  = [&](const std::string &why)
      { where.fail("Manifolds", text, "'" + entry + "': " + why); };
      if (colon == std::string::npos)
        fail("expected 'id: cylinder ...' or 'id: sphere ...'");
      const std::string id_text =
        dealii::Utilities::trim(entry.substr(0, colon));
      if (id_text.empty() ||
          id_text.find_first_not_of("0123456789") != std::string::npos ||
          id_text.size() > 5)
        fail("the id is not a boundary id");
      CurvedBoundary c;
      c.id = static_cast<dealii::types::boundary_id>(std::stoi(id_text));
      if (boundary_types.count(c.id) == 0)
        fail("boundary id " + id_text + " is not on the mesh");
      for (const auto &other : curved_boundaries)
        if (other.id == c.id)
          fail("boundary id " + id_text + " is given twice");
      std::istringstream rest(entry.substr(colon + 1));
      std::string        kind;
      rest >> kind;
      c.sphere = kind == "sphere";
      if (!c.sphere && kind != "cylinder")
        fail("unknown shape '" + kind + "' (cylinder, sphere)");
      std::string numbers_text;
      std::getline(rest, numbers_text);
      std::vector<double> numbers;
      try
      {
        for (const auto &n :
             dealii::Utilities::split_string_list(numbers_text, ','))
          numbers.push_back(std::stod(n));
      }
      catch (...)
      {
        fail("the numbers do not read");
      }
      const unsigned int needed = !c.sphere && dim == 3 ? 6 : dim;
      if (numbers.size() != needed)
        fail(kind + " needs " + std::to_string(needed) + " numbers here");
      for (unsigned int d = 0; d < dim; ++d)
        c.center[d] = numbers[d];
      if (needed == 6)
      {
        for (unsigned int d = 0; d < dim; ++d)
          c.axis[d] = numbers[dim + d];
        if (c.axis.norm() == 0)
          fail("the axis has no direction");
        c.axis /= c.axis.norm();
      }
      // The radius from the vertices of the faces: a shape that does not
      // go through them is a mistake in the file or in the entry.
      double                 sum = 0, smallest = 1e300, largest = 0;
      unsigned int           n = 0;
      std::set<unsigned int> seen;
      for (const auto &cell : coarse_mesh->active_cell_iterators())
        for (const unsigned int f : cell->face_indices())
          if (cell->at_boundary(f) && cell->face(f)->boundary_id() == c.id)
            for (const unsigned int v : cell->face(f)->vertex_indices())
              if (seen.insert(cell->face(f)->vertex_index(v)).second)
              {
                dealii::Tensor<1, dim> r = cell->face(f)->vertex(v) - c.center;
                if (!c.sphere && dim == 3)
                  r -= (r * c.axis) * c.axis;
                sum += r.norm();
                smallest = std::min(smallest, r.norm());
                largest  = std::max(largest, r.norm());
                ++n;
              }
      c.radius = sum / n;
      if (largest - smallest > 1e-3 * c.radius)
        fail("the faces of boundary id " + id_text + " lie between " +
             std::to_string(smallest) + " and " + std::to_string(largest) +
             " m from the " + (c.sphere ? "centre" : "axis") + ", not on one " +
             kind);
      curved_boundaries.push_back(c);
    }
    if (!curved_boundaries.empty())
    {
      // Refined faces follow the curve: cells are no longer boxes.
      cartesian = false;
      attach_manifolds(*coarse_mesh);
    }
  }


  template <int dim>
  void
  Geometry<dim>::attach_manifolds(dealii::Triangulation<dim> &tria) const
  {
    for (const auto &c : curved_boundaries)
    {
      for (const auto &cell : tria.active_cell_iterators())
        for (const unsigned int f : cell->face_indices())
          if (cell->at_boundary(f) && cell->face(f)->boundary_id() == c.id)
            cell->face(f)->set_all_manifold_ids(c.id);
      if constexpr (dim == 3)
        if (!c.sphere)
        {
          tria.set_manifold(c.id,
                            dealii::CylindricalManifold<dim>(c.axis, c.center));
          continue;
        }
      tria.set_manifold(c.id, dealii::SphericalManifold<dim>(c.center));
    }
  }


  template <int dim>
  void
  Geometry<dim>::read_mesh(const InputLocation &where, const std::string &text)
  {
    std::ifstream in(mesh_file);
    where.require(static_cast<bool>(in),
                  "File",
                  text,
                  "cannot be read (" + mesh_file + ")");
    auto read = std::make_shared<dealii::Triangulation<dim>>();
    try
    {
      dealii::GridIn<dim> grid_in;
      grid_in.attach_triangulation(*read);
      grid_in.read_msh(in);
    }
    catch (const std::exception &e)
    {
      std::string message = one_line(e.what());
      // deal.II's messages open with where in its sources the check
      // failed; the reason follows "Additional information:".
      const auto info = message.find("Additional information:");
      if (info != std::string::npos)
        message = message.substr(info + 23);
      // and closes with a rule of dashes.
      const auto rule = message.find("---");
      if (rule != std::string::npos)
        message = message.substr(0, rule);
      while (!message.empty() && (message.back() == ' ' || message[0] == ' '))
        message = message.back() == ' ' ?
                    message.substr(0, message.size() - 1) :
                    message.substr(1);
      if (message.size() > 200)
        message = message.substr(0, 200) + " ...";
      where.fail("File", text, "is not a mesh deal.II reads: " + message);
    }
    where.require(read->n_active_cells() > 0,
                  "File",
                  text,
                  "has no " +
                    std::string(dim == 2 ? "quadrilaterals" : "hexahedra") +
                    " (a mesh needs a Physical " +
                    (dim == 2 ? "Surface" : "Volume") +
                    " for its cells to be saved)");
    for (const auto &cell : read->active_cell_iterators())
      where.require(cell->reference_cell() ==
                      dealii::ReferenceCells::get_hypercube<dim>(),
                    "File",
                    text,
                    std::string("has ") +
                      (dim == 2 ? "triangles" :
                                  "tetrahedra, prisms or "
                                  "pyramids") +
                      "; only " + (dim == 2 ? "quadrilaterals" : "hexahedra") +
                      " are supported (Gmsh: Mesh.RecombineAll = 1" +
                      (dim == 3 ?
                         " and Mesh.SubdivisionAlgorithm = 2, or a transfinite "
                         "mesh" :
                         "") +
                      ")");

    // Axis-parallel cells are renumbered lexicographically (vertex 0 the
    // lowest corner), which MappingCartesian needs; the same numbering on
    // every cell keeps the faces consistently oriented.
    cartesian = true;
    std::vector<dealii::CellData<dim>> cells;
    for (const auto &cell : read->active_cell_iterators())
    {
      const auto box                  = cell->bounding_box();
      const auto &[lo, hi]            = box.get_boundary_points();
      const double          tolerance = 1e-10 * lo.distance(hi);
      dealii::CellData<dim> data;
      data.material_id = cell->material_id();
      std::vector<bool> found(cell->n_vertices(), false);
      for (const unsigned int v : cell->vertex_indices())
      {
        unsigned int corner    = 0;
        bool         at_corner = true;
        for (unsigned int d = 0; d < dim; ++d)
        {
          const double x = cell->vertex(v)[d];
          if (std::abs(x - hi[d]) <= tolerance)
            corner |= 1u << d;
          else if (std::abs(x - lo[d]) > tolerance)
            at_corner = false;
        }
        if (!at_corner || found[corner] || hi[0] - lo[0] <= tolerance)
        {
          cartesian = false;
          break;
        }
        found[corner]         = true;
        data.vertices[corner] = cell->vertex_index(v);
      }
      if (!cartesian)
        break;
      cells.push_back(data);
    }
    if (cartesian)
    {
      dealii::SubCellData boundary;
      for (const auto &cell : read->active_cell_iterators())
        for (const unsigned int f : cell->face_indices())
          if (cell->at_boundary(f))
          {
            dealii::CellData<dim - 1> face;
            for (const unsigned int v : cell->face(f)->vertex_indices())
              face.vertices[v] = cell->face(f)->vertex_index(v);
            face.boundary_id = cell->face(f)->boundary_id();
            if constexpr (dim == 2)
              boundary.boundary_lines.push_back(face);
            else
              boundary.boundary_quads.push_back(face);
          }
      coarse_mesh = std::make_shared<dealii::Triangulation<dim>>();
      coarse_mesh->create_triangulation(read->get_vertices(), cells, boundary);
    }
    else
      coarse_mesh = read;

    const auto bounds = dealii::GridTools::compute_bounding_box(*coarse_mesh)
                          .get_boundary_points();
    lower_corner  = bounds.first;
    upper_corner  = bounds.second;
    domain_volume = dealii::GridTools::volume(*coarse_mesh);
    coarse_edge   = std::numeric_limits<double>::max();
    for (const auto &cell : coarse_mesh->active_cell_iterators())
      coarse_edge = std::min(coarse_edge, cell->minimum_vertex_distance());
    subdivisions.clear();
  }


  template <int dim>
  bool
  Geometry<dim>::is_periodic(const unsigned int direction) const
  {
    return periodic[direction];
  }


  template <int dim>
  std::pair<dealii::types::boundary_id, dealii::types::boundary_id>
  Geometry<dim>::periodic_boundary_ids(const unsigned int direction) const
  {
    Assert(periodic[direction], dealii::ExcInternalError());
    return periodic_ids[direction];
  }


  template <int dim>
  bool
  Geometry<dim>::is_box() const
  {
    return box;
  }


  template <int dim>
  const dealii::Mapping<dim> &
  Geometry<dim>::mapping() const
  {
    if (!cell_mapping)
    {
      if (cartesian)
        cell_mapping = std::make_shared<dealii::MappingCartesian<dim>>();
      else if (has_curved_boundary())
        // Degree 2, as the velocity: the boundary's error in the fluid's
        // forces falls like h^3 instead of MappingQ1's h^2
        // (doc/validation.md, "Flow past a cylinder").
        cell_mapping = std::make_shared<dealii::MappingQ<dim>>(2);
      else
        cell_mapping = std::make_shared<dealii::MappingQ1<dim>>();
    }
    return *cell_mapping;
  }


  template <int dim>
  bool
  Geometry<dim>::has_curved_boundary() const
  {
    return !curved_boundaries.empty();
  }


  template <int dim>
  bool
  Geometry<dim>::is_curved(
    const typename dealii::Triangulation<dim>::cell_iterator &cell) const
  {
    if (curved_boundaries.empty())
      return false;
    for (const unsigned int l : cell->line_indices())
      if (cell->line(l)->manifold_id() != dealii::numbers::flat_manifold_id)
        return true;
    return false;
  }


  template <int dim>
  bool
  Geometry<dim>::is_cartesian() const
  {
    return cartesian;
  }


  template <int dim>
  BoundaryType
  Geometry<dim>::boundary_type(const dealii::types::boundary_id id) const
  {
    const auto entry = boundary_types.find(id);
    AssertThrow(entry != boundary_types.end(),
                dealii::ExcMessage("boundary id " + std::to_string(id) +
                                   " has no boundary condition"));
    return entry->second;
  }


  template <int dim>
  std::vector<dealii::types::boundary_id>
  Geometry<dim>::boundary_ids(const BoundaryType type) const
  {
    std::vector<dealii::types::boundary_id> ids;
    for (const auto &[id, t] : boundary_types)
      if (t == type)
        ids.push_back(id);
    return ids;
  }


  template <int dim>
  bool
  Geometry<dim>::has_velocity_boundary() const
  {
    return !boundary_ids(BoundaryType::velocity).empty();
  }


  template <int dim>
  double
  Geometry<dim>::volume() const
  {
    return domain_volume;
  }


  template <int dim>
  std::vector<unsigned int>
  Geometry<dim>::equivalent_subdivisions() const
  {
    if (box)
      return subdivisions;
    const double h = std::pow(domain_volume / n_coarse_cells(), 1.0 / dim);
    std::vector<unsigned int> n(dim);
    for (unsigned int d = 0; d < dim; ++d)
      n[d] = std::max(1u,
                      static_cast<unsigned int>(
                        std::round((upper_corner[d] - lower_corner[d]) / h)));
    return n;
  }


  template <int dim>
  unsigned int
  Geometry<dim>::n_coarse_cells() const
  {
    if (!box)
      return coarse_mesh->n_active_cells();
    unsigned int n = 1;
    for (const unsigned int s : subdivisions)
      n *= s;
    return n;
  }


  template <int dim>
  bool
  Geometry<dim>::contains(const dealii::Point<dim> &x) const
  {
    for (unsigned int d = 0; d < dim; ++d)
    {
      const double eps = 1e-12 * (upper_corner[d] - lower_corner[d]);
      if (x[d] < lower_corner[d] - eps || x[d] > upper_corner[d] + eps)
        return false;
    }
    if (box)
      return true;
    if (!locator)
      locator = std::make_shared<dealii::GridTools::Cache<dim>>(
        *coarse_mesh, dealii::StaticMappingQ1<dim>::mapping);
    const auto found = dealii::GridTools::find_active_cell_around_point(
      *locator,
      x,
      typename dealii::Triangulation<dim>::active_cell_iterator(),
      std::vector<bool>(),
      1e-10);
    return found.first.state() == dealii::IteratorState::valid;
  }


  template <int dim>
  std::vector<dealii::types::boundary_id>
  Geometry<dim>::add_walls(Contact::Walls<dim> &walls) const
  {
    const auto meets = [](const BoundaryType t)
    { return t != BoundaryType::open && t != BoundaryType::periodic; };
    const unsigned int                      first = walls.n_walls();
    std::vector<dealii::types::boundary_id> ids;
    if (box)
    {
      std::array<bool, 2 * dim> is_wall;
      for (unsigned int f = 0; f < 2 * dim; ++f)
        is_wall[f] = meets(boundary_types.at(f));
      const auto numbers = walls.add_box(lower_corner, upper_corner, is_wall);
      // A box's boundary ids are its face numbers.
      ids.resize(walls.n_walls() - first);
      for (unsigned int f = 0; f < 2 * dim; ++f)
        if (is_wall[f])
          ids[numbers[f] - first] = f;
      return ids;
    }
    // Points numbered by position (to a billionth of the domain), so that
    // facets of neighbouring faces share the numbers of their corners.
    const double quantum = 1e-9 * lower_corner.distance(upper_corner);
    std::map<std::array<long long, dim>, unsigned int> number;
    std::vector<dealii::Point<dim>>                    points;
    std::vector<Contact::BoundaryFacet<dim>>           facets;
    const auto vertex = [&](const dealii::Point<dim> &x)
    {
      std::array<long long, dim> key;
      for (unsigned int d = 0; d < dim; ++d)
        key[d] = std::llround(x[d] / quantum);
      const auto [entry, added] = number.emplace(key, points.size());
      if (added)
        points.push_back(x);
      return entry->second;
    };
    // A curved face as n x n pieces whose corners lie on its surface, n
    // such that a piece's chord departs from the curve by at most 1e-4 of
    // its radius (sagitta l^2/(8 R)); the same n for all the faces of a
    // curve, so that neighbours share their corners.
    std::map<dealii::types::boundary_id, unsigned int> pieces_per_edge;
    for (const auto &c : curved_boundaries)
    {
      double longest = 0;
      for (const auto &cell : coarse_mesh->active_cell_iterators())
        for (const unsigned int f : cell->face_indices())
          if (cell->at_boundary(f) && cell->face(f)->boundary_id() == c.id)
            longest = std::max(longest, cell->face(f)->diameter());
      pieces_per_edge[c.id] = static_cast<unsigned int>(
        std::ceil(longest / (c.radius * std::sqrt(8e-4))));
    }
    for (const auto &cell : coarse_mesh->active_cell_iterators())
      for (const unsigned int f : cell->face_indices())
        if (cell->at_boundary(f) &&
            meets(boundary_types.at(cell->face(f)->boundary_id())))
        {
          const auto            face  = cell->face(f);
          const CurvedBoundary *curve = nullptr;
          for (const auto &c : curved_boundaries)
            if (c.id == face->boundary_id())
              curve = &c;
          const unsigned int n = curve ? pieces_per_edge[curve->id] : 1;
          // The face's point at parameters (s, t) in [0, 1]^(dim-1).
          const auto at = [&](const double s, const double t)
          {
            dealii::Point<dim> x;
            if (dim == 2)
              x = face->vertex(0) + s * (face->vertex(1) - face->vertex(0));
            else
              x = dealii::Point<dim>((1 - s) * (1 - t) * face->vertex(0) +
                                     s * (1 - t) * face->vertex(1) +
                                     (1 - s) * t * face->vertex(dim - 1) +
                                     s * t * face->vertex(dim == 3 ? 3 : 1));
            return curve ? curve->project(x) : x;
          };
          // Pieces: segments in 2D, two triangles per quadrilateral in 3D
          // (split along the diagonal from its first corner).
          std::vector<std::array<unsigned int, dim>> pieces;
          for (unsigned int i = 0; i < n; ++i)
            for (unsigned int j = 0; j < (dim == 2 ? 1u : n); ++j)
            {
              const double s0 = double(i) / n, s1 = double(i + 1) / n;
              const double t0 = double(j) / n, t1 = double(j + 1) / n;
              std::array<unsigned int, dim> piece;
              if constexpr (dim == 2)
              {
                piece = {{vertex(at(s0, 0)), vertex(at(s1, 0))}};
                pieces.push_back(piece);
              }
              else
              {
                const unsigned int a = vertex(at(s0, t0)),
                                   b = vertex(at(s1, t0)),
                                   c = vertex(at(s0, t1)),
                                   d = vertex(at(s1, t1));
                pieces.push_back({{a, b, d}});
                pieces.push_back({{a, d, c}});
              }
            }
          for (const auto &piece : pieces)
          {
            dealii::Tensor<1, dim> normal;
            const auto             e = points[piece[1]] - points[piece[0]];
            if constexpr (dim == 2)
            {
              normal[0] = -e[1];
              normal[1] = e[0];
            }
            else
              normal = dealii::cross_product_3d(e,
                                                points[piece[dim - 1]] -
                                                  points[piece[0]]);
            if (normal * (cell->center() - points[piece[0]]) < 0)
              normal = -normal;
            facets.push_back({piece, normal});
            ids.push_back(face->boundary_id());
          }
        }
    if (!facets.empty())
      walls.add_facets(points, facets);
    return ids;
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
    return !boundary_ids(BoundaryType::open).empty();
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
    if (!box)
      return shortest_side();
    const auto no_slip = [&](const unsigned int face)
    {
      return boundary_types.at(face) == BoundaryType::wall ||
             boundary_types.at(face) == BoundaryType::velocity;
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
    return coarse_edge / std::pow(2.0, level);
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
    if (!box)
    {
      // From the coarse mesh's description, as a generated box is made
      // (copy_triangulation() left p4est coarsening flags it could not
      // carry out, and the adaptive mesh looped on them).
      auto [vertices, cells, faces] =
        dealii::GridTools::get_coarse_mesh_description(*coarse_mesh);
      tria.create_triangulation(vertices, cells, faces);
      attach_manifolds(tria);
    }
    else
      dealii::GridGenerator::subdivided_hyper_rectangle(
        tria, subdivisions, lower_corner, upper_corner, /*colorize=*/true);

    std::vector<dealii::GridTools::PeriodicFacePair<
      typename dealii::parallel::distributed::Triangulation<
        dim>::cell_iterator>>
      periodic_faces;
    for (unsigned int d = 0; d < dim; ++d)
      if (is_periodic(d))
        dealii::GridTools::collect_periodic_faces(tria,
                                                  periodic_ids[d].first,
                                                  periodic_ids[d].second,
                                                  d,
                                                  periodic_faces);
    if (!periodic_faces.empty())
      tria.add_periodicity(periodic_faces);
  }


  template <int dim>
  dealii::BoundingBox<dim>
  cell_search_box(const dealii::CellAccessor<dim> &cell)
  {
    auto   box     = cell.bounding_box();
    double longest = 0;
    for (unsigned int d = 0; d < dim; ++d)
      longest = std::max(longest, box.side_length(d));
    box.extend(0.25 * longest);
    return box;
  }


  template class Geometry<2>;
  template class Geometry<3>;
  template dealii::BoundingBox<2>
  cell_search_box(const dealii::CellAccessor<2> &);
  template dealii::BoundingBox<3>
  cell_search_box(const dealii::CellAccessor<3> &);
} // namespace ImmersedGrains
