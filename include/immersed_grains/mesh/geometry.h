#ifndef immersed_grains_mesh_geometry_h
#define immersed_grains_mesh_geometry_h

#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/point.h>
#include <deal.II/distributed/tria.h>

#include <immersed_grains/parameters.h>

#include <string>
#include <vector>

namespace ImmersedGrains
{
  /** What happens to fluid and grains at one face of the box. */
  enum class BoundaryType
  {
    wall,     // no-slip for the fluid, a wall for grains
    slip,     // no normal flow, free tangential flow; a wall for grains
    open,     // traction (prescribed pressure) for the fluid; grains leave
    velocity, // prescribed fluid velocity (Fluid/Boundary velocity); a wall
    periodic  // paired with the opposite face
  };

  std::string
  to_string(BoundaryType type);

  /**
   * The box domain, its subdivisions and the boundary condition of each
   * face. Boundary id i is face i in deal.II's numbering: 0 = x-min,
   * 1 = x-max, 2 = y-min, 3 = y-max, 4 = z-min, 5 = z-max.
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

    bool
    is_periodic(unsigned int direction) const;

    /** @p x moved by whole periods into [lower, upper) along the
     *  periodic @p direction. */
    double
    wrap(unsigned int direction, double x) const;

    bool
    has_open_boundary() const;

    /** The shortest and the longest side of the box. */
    double
    shortest_side() const;
    double
    longest_side() const;

    /** The width of the gap between the no-slip faces (wall, velocity)
     *  that confine the flow: per direction the side where both faces are
     *  no-slip, twice it where one is (the other slip or open: a film,
     *  half of a channel), nothing where neither is (periodic, slip,
     *  open); the narrowest of these, or the shortest side where no face
     *  is no-slip. The fluid preconditioner's Darcy floor is of the order
     *  of mu over its square (fluid_assembly.cc). */
    double
    wall_gap() const;

    /** The shortest edge of the cells of refinement level @p level (the
     *  coarse mesh of `Subdivisions` is level 0). */
    double
    shortest_cell_edge(unsigned int level) const;

    dealii::Point<dim>        lower_corner;
    dealii::Point<dim>        upper_corner;
    std::vector<unsigned int> subdivisions;
    unsigned int              initial_refinement = 0;
    std::vector<BoundaryType> boundary_types; // one per face
  };
} // namespace ImmersedGrains

#endif
