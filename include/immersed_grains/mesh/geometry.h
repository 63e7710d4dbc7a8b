#ifndef immersed_grains_mesh_geometry_h
#define immersed_grains_mesh_geometry_h

#include <deal.II/base/bounding_box.h>
#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/point.h>
#include <deal.II/distributed/tria.h>
#include <deal.II/fe/mapping.h>
#include <deal.II/grid/tria_accessor.h>

#include <immersed_grains/contact/walls.h>
#include <immersed_grains/parameters.h>

#include <array>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace dealii
{
  namespace GridTools
  {
    template <int dim, int spacedim>
    class Cache;
  }
} // namespace dealii

namespace ImmersedGrains
{
  /** What happens to fluid and grains at one part of the boundary. */
  enum class BoundaryType
  {
    wall,     // no-slip for the fluid, a wall for grains
    slip,     // no normal flow, free tangential flow; a wall for grains
    open,     // traction (prescribed pressure) for the fluid; grains leave
    velocity, // prescribed fluid velocity (Fluid/Inflow velocity); a wall
              // for grains, as a distributor plate is ('inflow' in a file)
    periodic  // paired with the opposite face
  };

  std::string
  to_string(BoundaryType type);

  /**
   * The box in which to look for points of @p cell before inverting its
   * mapping: its vertices' bounding box widened by a quarter of its
   * longest side, room for an edge that bulges out of its vertices' box
   * (a curved boundary), across the box's shortest side as well.
   */
  template <int dim>
  dealii::BoundingBox<dim>
  cell_search_box(const dealii::CellAccessor<dim> &cell);

  /**
   * The domain: a box (`Geometry = box`: `Lower corner`, `Upper corner`,
   * `Subdivisions`; boundary id i is face i in deal.II's numbering,
   * 0 = x-min, 1 = x-max, 2 = y-min, 3 = y-max, 4 = z-min, 5 = z-max) or a
   * mesh read from a Gmsh file (`Geometry = gmsh`: quadrilaterals in 2D,
   * hexahedra in 3D, physical group ids as boundary ids). Either way it
   * gives the boundary condition of each boundary id, the coarse mesh, the
   * walls grains meet, and the sizes the solvers are tuned by.
   */
  template <int dim>
  class Geometry
  {
  public:
    static void
    declare_parameters(dealii::ParameterHandler &prm);

    void
    parse_parameters(dealii::ParameterHandler &prm, const std::string &file);

    /** Builds the coarse mesh and sets periodicity (what a saved mesh is
     *  loaded onto). */
    void
    create_coarse_mesh(
      dealii::parallel::distributed::Triangulation<dim> &tria) const;

    /** Builds the coarse mesh, sets periodicity, refines globally. */
    void
    create_mesh(dealii::parallel::distributed::Triangulation<dim> &tria) const;

    /** Whether the domain is a box (`Geometry = box`). */
    bool
    is_box() const;

    /** Whether every coarse cell is an axis-parallel box (always for a
     *  box domain), so that MappingCartesian is exact on every cell. */
    bool
    is_cartesian() const;

    /** Whether @p direction is periodic: on a box both its faces are
     *  `periodic`, on a Gmsh mesh two `periodic` boundary ids lie on the
     *  two faces of the mesh's bounding box normal to it. */
    bool
    is_periodic(unsigned int direction) const;

    /** The boundary ids on the lower and the upper side of the periodic
     *  @p direction. */
    std::pair<dealii::types::boundary_id, dealii::types::boundary_id>
    periodic_boundary_ids(unsigned int direction) const;

    /** @p x moved by whole periods into [lower, upper) along the
     *  periodic @p direction. */
    double
    wrap(unsigned int direction, double x) const;

    bool
    has_open_boundary() const;

    /** Whether some boundary carries a prescribed velocity. */
    bool
    has_velocity_boundary() const;

    /** The boundary ids of a type. */
    std::vector<dealii::types::boundary_id>
    boundary_ids(BoundaryType type) const;

    /** The type of boundary id @p id. */
    BoundaryType
    boundary_type(dealii::types::boundary_id id) const;

    /** The shortest and the longest side of the domain's bounding box. */
    double
    shortest_side() const;
    double
    longest_side() const;

    /** The domain's volume (area in 2D). */
    double
    volume() const;

    /** The width of the gap between the no-slip faces (wall, velocity)
     *  that confine the flow: per direction the side where both faces are
     *  no-slip, twice it where one is (the other slip or open: a film,
     *  half of a channel), nothing where neither is (periodic, slip,
     *  open); the narrowest of these, or the shortest side where no face
     *  is no-slip. A Gmsh domain: the shortest side of its bounding box.
     *  The fluid preconditioner's Darcy floor is of the order of mu over
     *  its square (fluid_assembly.cc). */
    double
    wall_gap() const;

    /** The shortest edge of the cells of refinement level @p level (the
     *  coarse mesh is level 0). */
    double
    shortest_cell_edge(unsigned int level) const;

    /** Subdivisions of the bounding box into cells of the coarse mesh's
     *  mean size: the box's own Subdivisions, for a Gmsh mesh an estimate
     *  (sizes of meshes not yet made, the memory estimate of --check). */
    std::vector<unsigned int>
    equivalent_subdivisions() const;

    /** The number of coarse cells. */
    unsigned int
    n_coarse_cells() const;

    /** Whether @p x lies in the domain (on its boundary counts). */
    bool
    contains(const dealii::Point<dim> &x) const;

    /** The mapping of the mesh's cells: MappingCartesian where every cell
     *  is an axis-parallel box (exact there, with constant Jacobians and a
     *  closed-form inverse, a fraction of MappingQ1's cost), a quadratic
     *  map (MappingQ of degree 2, the velocity's degree) where the mesh has
     *  curved boundaries (`Mesh/Manifolds`), MappingQ1 elsewhere. */
    const dealii::Mapping<dim> &
    mapping() const;

    /** Whether the mesh has curved boundaries (`Mesh/Manifolds`), so that
     *  mapping() is quadratic. */
    bool
    has_curved_boundary() const;

    /** Whether an edge of @p cell lies on a curved boundary: the cells
     *  whose quadratic map differs from their bilinear (trilinear) one;
     *  every other cell's map is MappingQ1's. */
    bool
    is_curved(
      const typename dealii::Triangulation<dim>::cell_iterator &cell) const;

    /** Adds the boundaries grains meet (wall, slip and velocity ids) to
     *  @p walls: the box's planes, or the boundary faces of a Gmsh mesh as
     *  facets (a quadrilateral face as two triangles in 3D). Returns the
     *  boundary id of each wall added, in the order of their numbers. */
    std::vector<dealii::types::boundary_id>
    add_walls(Contact::Walls<dim> &walls) const;

    /** The bounding box of the domain. */
    dealii::Point<dim>                                 lower_corner;
    dealii::Point<dim>                                 upper_corner;
    std::vector<unsigned int>                          subdivisions; // box only
    unsigned int                                       initial_refinement = 0;
    std::map<dealii::types::boundary_id, BoundaryType> boundary_types;
    std::string mesh_file; // Gmsh only, as a path from the working folder

    /** The exact shape of a curved boundary (Mesh/Manifolds): a cylinder
     *  (a circle in 2D) or a sphere, by boundary id. */
    struct CurvedBoundary
    {
      dealii::types::boundary_id id;
      bool                       sphere;
      dealii::Point<dim>         center;
      dealii::Tensor<1, dim>     axis;       // a cylinder's in 3D, unit length
      double                     radius = 0; // the mean over its vertices

      /** The point of the surface closest to @p x. */
      dealii::Point<dim>
      project(const dealii::Point<dim> &x) const;
    };
    std::vector<CurvedBoundary> curved_boundaries;

  private:
    void
    parse_box(dealii::ParameterHandler &prm, const InputLocation &where);

    void
    parse_box_conditions(const InputLocation &where,
                         const std::string   &bc_text);

    void
    parse_id_conditions(const InputLocation &where, const std::string &bc_text);

    void
    parse_mesh_conditions(const InputLocation &where,
                          const std::string   &bc_text);

    void
    pair_periodic_ids(const InputLocation &where, const std::string &bc_text);

    void
    read_mesh(const InputLocation &where, const std::string &text);

    void
    parse_manifolds(const InputLocation &where, const std::string &text);

    /** Gives the faces of the curved boundaries their manifolds. */
    void
    attach_manifolds(dealii::Triangulation<dim> &tria) const;

    std::array<bool, dim> periodic{};
    std::array<
      std::pair<dealii::types::boundary_id, dealii::types::boundary_id>,
      dim>
                                                periodic_ids;
    bool                                        box           = true;
    bool                                        cartesian     = true;
    double                                      domain_volume = 0;
    double                                      coarse_edge   = 0;
    std::shared_ptr<dealii::Triangulation<dim>> coarse_mesh; // Gmsh only
    // Finds the coarse cell around a point (contains()); built on first use.
    mutable std::shared_ptr<dealii::GridTools::Cache<dim, dim>> locator;
    mutable std::shared_ptr<const dealii::Mapping<dim>>         cell_mapping;
  };
} // namespace ImmersedGrains

#endif
