#ifndef immersed_grains_contact_walls_h
#define immersed_grains_contact_walls_h

#include <deal.II/base/point.h>
#include <deal.II/base/tensor.h>

#include <array>
#include <vector>

namespace ImmersedGrains
{
  namespace Contact
  {
    using dealii::Point;
    using dealii::Tensor;

    /**
     * A candidate grain-wall contact: a grain closer to a wall than the
     * alert distance at the start of the step.
     */
    template <int dim>
    struct WallContact
    {
      unsigned int grain;
      unsigned int wall;

      /// Unit normal from the grain centre towards the wall's closest point,
      /// the same convention as GrainPair (from the grain to its partner).
      Tensor<1, dim> normal;

      /// Distance from the centre to the wall minus the radius (negative:
      /// overlap), in metres.
      double gap;
    };

    /**
     * An infinite plane through @p point with unit normal @p inward_normal
     * pointing into the domain, moving rigidly with @p velocity.
     */
    template <int dim>
    struct PlaneWall
    {
      Point<dim>     point;
      Tensor<1, dim> inward_normal;
      Tensor<1, dim> velocity;
    };

    /**
     * The fixed or rigidly moving obstacles grains collide with. Walls are
     * numbered in the order they are added; WallContact::wall and
     * velocities() use that numbering, which is all the contact solver
     * needs, so the kind of obstacle stays private to this class.
     *
     * Today the obstacles are planes (the faces of a box). Boundary faces of
     * a general mesh fit the same interface as further primitives (segments
     * in 2D, triangles or quadrilaterals in 3D): each gives the closest point
     * to a grain centre, and the contact normal points from the centre to
     * that point, which also handles edges and corners. With many faces the
     * grain loop in find_contacts() would then go through a bucket grid of
     * the faces instead of over all walls.
     */
    template <int dim>
    class Walls
    {
    public:
      /**
       * Adds a plane; returns its wall number. @p inward_normal need not be
       * of unit length.
       */
      unsigned int
      add_plane(const Point<dim>     &point,
                const Tensor<1, dim> &inward_normal,
                const Tensor<1, dim> &velocity = Tensor<1, dim>());

      /**
       * Adds the faces of the box [lower, upper] for which @p is_wall is
       * true, in deal.II's face order (2d: the lower face on axis d, 2d+1:
       * the upper one). Returns the wall number of each face, or
       * numbers::invalid_unsigned_int where no wall was added.
       */
      std::array<unsigned int, 2 * dim>
      add_box(const Point<dim>                &lower,
              const Point<dim>                &upper,
              const std::array<bool, 2 * dim> &is_wall);

      void
      set_velocity(const unsigned int wall, const Tensor<1, dim> &velocity);

      unsigned int
      n_walls() const;

      const PlaneWall<dim> &
      plane(const unsigned int wall) const;

      /// Velocity of each wall, indexed by wall number.
      const std::vector<Tensor<1, dim>> &
      velocities() const;

      /**
       * Fills @p contacts with every (grain, wall) whose gap is below
       * @p alert_distance, sorted by grain, then wall. A grain that has gone
       * through a wall gets a negative gap, so the solver pushes it back.
       */
      void
      find_contacts(const std::vector<Point<dim>> &positions,
                    const std::vector<double>     &radii,
                    const double                   alert_distance,
                    std::vector<WallContact<dim>> &contacts) const;

    private:
      std::vector<PlaneWall<dim>> planes;
      std::vector<Tensor<1, dim>> wall_velocities;
    };
  } // namespace Contact
} // namespace ImmersedGrains

#endif
