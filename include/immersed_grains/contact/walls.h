#ifndef immersed_grains_contact_walls_h
#define immersed_grains_contact_walls_h

#include <deal.II/base/point.h>
#include <deal.II/base/tensor.h>

#include <immersed_grains/box_buckets.h>

#include <array>
#include <map>
#include <utility>
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
     * A flat piece of a mesh's boundary: a segment in 2D, a triangle in 3D
     * (vertex numbers into Walls' vertex list), with its unit normal
     * pointing into the domain.
     */
    template <int dim>
    struct BoundaryFacet
    {
      std::array<unsigned int, dim> vertices;
      Tensor<1, dim>                inward_normal;
    };

    /**
     * The fixed or rigidly moving obstacles grains collide with. Walls are
     * numbered in the order they are added; WallContact::wall and
     * velocities() use that numbering, which is all the contact solver
     * needs, so the kind of obstacle stays private to this class.
     *
     * Two kinds: infinite planes (the faces of a box) and the facets of a
     * mesh's boundary, each facet a wall of its own. A grain meets a facet
     * at the facet's closest point to its centre, on the facet's inside,
     * on an edge or at a vertex; the normal points from the centre to that
     * point. A point on an edge or at a vertex is a contact only where it
     * is the closest point of every wall facet sharing that edge or vertex
     * (a local minimum of the distance over the boundary), and it is
     * reported once: a grain sliding across the joint of two coplanar
     * facets, or past a concave corner, meets no phantom edge, while a
     * grain rounding a convex edge or corner meets the edge itself.
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

      /**
       * Adds the facets of a boundary (segments in 2D, triangles in 3D)
       * over the points @p vertices; facets sharing an edge or a vertex
       * must use the same vertex number for it. Returns the wall number of
       * the first facet; the others follow in order.
       */
      unsigned int
      add_facets(const std::vector<Point<dim>>         &vertices,
                 const std::vector<BoundaryFacet<dim>> &facets);

      void
      set_velocity(const unsigned int wall, const Tensor<1, dim> &velocity);

      unsigned int
      n_walls() const;

      /** The plane of wall @p wall, which must be a plane. */
      const PlaneWall<dim> &
      plane(const unsigned int wall) const;

      unsigned int
      n_facets() const;

      /**
       * The smallest distance from @p x to a wall minus @p radius (negative
       * where a grain of that radius there overlaps one), over the walls
       * within @p reach of it; @p reach where none is.
       */
      double
      clearance(const Point<dim> &x, double radius, double reach) const;

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
      /** Where the closest point of a facet lies. */
      enum class Feature
      {
        inside,
        edge,
        vertex
      };

      struct ClosestPoint
      {
        Point<dim>   point;
        Feature      feature;
        unsigned int a, b; // the vertex (a), or the edge's vertices (a < b)
      };

      ClosestPoint
      closest_point(const unsigned int facet, const Point<dim> &x) const;

      /** The facets sharing the edge or the vertex of @p where. */
      const std::vector<unsigned int> &
      facets_at(const ClosestPoint &where) const;

      /** Appends the facet contacts of the grain at @p x to @p contacts. */
      void
      find_facet_contacts(const unsigned int             grain,
                          const Point<dim>              &x,
                          const double                   radius,
                          const double                   alert_distance,
                          std::vector<unsigned int>     &candidates,
                          std::vector<WallContact<dim>> &contacts) const;

      std::vector<PlaneWall<dim>> planes;
      std::vector<unsigned int>   plane_walls; // wall number of each plane
      std::vector<Tensor<1, dim>> wall_velocities;

      std::vector<Point<dim>>         vertices;
      std::vector<BoundaryFacet<dim>> facets;
      std::vector<unsigned int>       facet_walls;   // wall number of each
      std::vector<int>                plane_of_wall; // -1 for a facet
      std::map<unsigned int, std::vector<unsigned int>> vertex_facets;
      std::map<std::pair<unsigned int, unsigned int>, std::vector<unsigned int>>
        edge_facets;

      BoxBuckets<dim> facet_buckets;
    };
  } // namespace Contact
} // namespace ImmersedGrains

#endif
