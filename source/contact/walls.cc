#include <deal.II/base/exceptions.h>
#include <deal.II/base/utilities.h>

#include <immersed_grains/contact/walls.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace ImmersedGrains
{
  namespace Contact
  {
    template <int dim>
    unsigned int
    Walls<dim>::add_plane(const Point<dim>     &point,
                          const Tensor<1, dim> &inward_normal,
                          const Tensor<1, dim> &velocity)
    {
      const double length = inward_normal.norm();
      AssertThrow(length > 0,
                  dealii::ExcMessage(
                    "Walls: a plane needs a non-zero normal."));
      planes.push_back({point, inward_normal / length, velocity});
      plane_walls.push_back(wall_velocities.size());
      plane_of_wall.push_back(planes.size() - 1);
      wall_velocities.push_back(velocity);
      return wall_velocities.size() - 1;
    }



    template <int dim>
    std::array<unsigned int, 2 * dim>
    Walls<dim>::add_box(const Point<dim>                &lower,
                        const Point<dim>                &upper,
                        const std::array<bool, 2 * dim> &is_wall)
    {
      std::array<unsigned int, 2 * dim> numbers;
      numbers.fill(dealii::numbers::invalid_unsigned_int);
      for (unsigned int d = 0; d < dim; ++d)
      {
        Tensor<1, dim> e;
        e[d] = 1;
        if (is_wall[2 * d])
          numbers[2 * d] = add_plane(lower, e);
        if (is_wall[2 * d + 1])
          numbers[2 * d + 1] = add_plane(upper, -e);
      }
      return numbers;
    }



    template <int dim>
    void
    Walls<dim>::set_velocity(const unsigned int    wall,
                             const Tensor<1, dim> &velocity)
    {
      AssertIndexRange(wall, wall_velocities.size());
      if (plane_of_wall[wall] >= 0)
        planes[plane_of_wall[wall]].velocity = velocity;
      wall_velocities[wall] = velocity;
    }



    template <int dim>
    unsigned int
    Walls<dim>::n_walls() const
    {
      return wall_velocities.size();
    }



    template <int dim>
    unsigned int
    Walls<dim>::n_facets() const
    {
      return facets.size();
    }



    template <int dim>
    const PlaneWall<dim> &
    Walls<dim>::plane(const unsigned int wall) const
    {
      AssertIndexRange(wall, wall_velocities.size());
      Assert(plane_of_wall[wall] >= 0, dealii::ExcMessage("not a plane"));
      return planes[plane_of_wall[wall]];
    }



    template <int dim>
    const std::vector<Tensor<1, dim>> &
    Walls<dim>::velocities() const
    {
      return wall_velocities;
    }



    template <int dim>
    void
    Walls<dim>::find_contacts(const std::vector<Point<dim>> &positions,
                              const std::vector<double>     &radii,
                              const double                   alert_distance,
                              std::vector<WallContact<dim>> &contacts) const
    {
      AssertThrow(radii.size() == positions.size(),
                  dealii::ExcMessage(
                    "Walls: one radius per position is needed."));
      contacts.clear();
      std::vector<unsigned int> candidates;
      for (unsigned int i = 0; i < positions.size(); ++i)
      {
        const std::size_t first = contacts.size();
        for (unsigned int k = 0; k < planes.size(); ++k)
        {
          const double gap =
            (positions[i] - planes[k].point) * planes[k].inward_normal -
            radii[i];
          if (gap < alert_distance)
            contacts.push_back(
              {i, plane_walls[k], -planes[k].inward_normal, gap});
        }
        if (!facets.empty())
        {
          find_facet_contacts(
            i, positions[i], radii[i], alert_distance, candidates, contacts);
          std::sort(contacts.begin() + first,
                    contacts.end(),
                    [](const WallContact<dim> &a, const WallContact<dim> &b)
                    { return a.wall < b.wall; });
        }
      }
    }



    template <int dim>
    double
    Walls<dim>::clearance(const Point<dim> &x,
                          const double      radius,
                          const double      reach) const
    {
      double best = reach;
      for (const auto &plane : planes)
        best = std::min(best, (x - plane.point) * plane.inward_normal - radius);
      std::vector<unsigned int>     candidates;
      std::vector<WallContact<dim>> contacts;
      find_facet_contacts(0, x, radius, reach, candidates, contacts);
      for (const auto &c : contacts)
        best = std::min(best, c.gap);
      return best;
    }



    template <int dim>
    unsigned int
    Walls<dim>::add_facets(const std::vector<Point<dim>>         &new_vertices,
                           const std::vector<BoundaryFacet<dim>> &new_facets)
    {
      const unsigned int first_wall   = wall_velocities.size();
      const unsigned int vertex_shift = vertices.size();
      vertices.insert(vertices.end(), new_vertices.begin(), new_vertices.end());
      for (auto facet : new_facets)
      {
        for (auto &v : facet.vertices)
        {
          AssertThrow(v < new_vertices.size(),
                      dealii::ExcMessage("Walls: a facet's vertex number is "
                                         "out of range."));
          v += vertex_shift;
        }
        const double length = facet.inward_normal.norm();
        AssertThrow(length > 0,
                    dealii::ExcMessage("Walls: a facet needs a normal."));
        facet.inward_normal /= length;
        const unsigned int f = facets.size();
        facets.push_back(facet);
        facet_walls.push_back(wall_velocities.size());
        plane_of_wall.push_back(-1);
        wall_velocities.emplace_back();
        for (unsigned int a = 0; a < dim; ++a)
        {
          vertex_facets[facet.vertices[a]].push_back(f);
          if (dim == 3)
          {
            const unsigned int u = facet.vertices[a],
                               w = facet.vertices[(a + 1) % dim];
            edge_facets[{std::min(u, w), std::max(u, w)}].push_back(f);
          }
        }
      }

      // Buckets about the size of a facet.
      std::vector<dealii::BoundingBox<dim>> boxes;
      double                                mean_extent = 0;
      for (const auto &facet : facets)
      {
        std::vector<Point<dim>> corners;
        double                  extent = 0;
        for (const unsigned int v : facet.vertices)
        {
          for (const auto &c : corners)
            extent = std::max(extent, c.distance(vertices[v]));
          corners.push_back(vertices[v]);
        }
        boxes.emplace_back(corners);
        mean_extent += extent / facets.size();
      }
      Point<dim> lo = vertices[0], hi = vertices[0];
      for (const auto &v : vertices)
        for (unsigned int d = 0; d < dim; ++d)
        {
          lo[d] = std::min(lo[d], v[d]);
          hi[d] = std::max(hi[d], v[d]);
        }
      facet_buckets.reinit(lo, hi, mean_extent, boxes);
      return first_wall;
    }



    template <int dim>
    typename Walls<dim>::ClosestPoint
    Walls<dim>::closest_point(const unsigned int facet,
                              const Point<dim>  &x) const
    {
      const auto  &v = facets[facet].vertices;
      ClosestPoint c;
      const auto   at_vertex = [&](const unsigned int k)
      {
        c.point   = vertices[v[k]];
        c.feature = Feature::vertex;
        c.a = c.b = v[k];
        return c;
      };
      const auto on_edge =
        [&](const unsigned int i, const unsigned int j, const double t)
      {
        c.point   = vertices[v[i]] + t * (vertices[v[j]] - vertices[v[i]]);
        c.feature = Feature::edge;
        c.a       = std::min(v[i], v[j]);
        c.b       = std::max(v[i], v[j]);
        return c;
      };
      const Point<dim> &a  = vertices[v[0]];
      const Point<dim> &b  = vertices[v[1]];
      const auto        ab = b - a;
      if (dim == 2)
      {
        const double t = (x - a) * ab / ab.norm_square();
        if (t <= 0)
          return at_vertex(0);
        if (t >= 1)
          return at_vertex(1);
        c.point   = a + t * ab;
        c.feature = Feature::inside;
        c.a = c.b = 0;
        return c;
      }
      // The closest point of a triangle by its Voronoi regions (Ericson,
      // Real-Time Collision Detection, 2005, section 5.1.5).
      const Point<dim> &p  = vertices[v[dim - 1]];
      const auto        ac = p - a;
      const auto        ap = x - a;
      const double      d1 = ab * ap, d2 = ac * ap;
      if (d1 <= 0 && d2 <= 0)
        return at_vertex(0);
      const auto   bp = x - b;
      const double d3 = ab * bp, d4 = ac * bp;
      if (d3 >= 0 && d4 <= d3)
        return at_vertex(1);
      const double vc = d1 * d4 - d3 * d2;
      if (vc <= 0 && d1 >= 0 && d3 <= 0)
        return on_edge(0, 1, d1 / (d1 - d3));
      const auto   cp = x - p;
      const double d5 = ab * cp, d6 = ac * cp;
      if (d6 >= 0 && d5 <= d6)
        return at_vertex(dim - 1);
      const double vb = d5 * d2 - d1 * d6;
      if (vb <= 0 && d2 >= 0 && d6 <= 0)
        return on_edge(0, dim - 1, d2 / (d2 - d6));
      const double va = d3 * d6 - d5 * d4;
      if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0)
        return on_edge(1, dim - 1, (d4 - d3) / ((d4 - d3) + (d5 - d6)));
      const double denominator = 1 / (va + vb + vc);
      c.point   = a + (vb * denominator) * ab + (vc * denominator) * ac;
      c.feature = Feature::inside;
      c.a = c.b = 0;
      return c;
    }



    template <int dim>
    const std::vector<unsigned int> &
    Walls<dim>::facets_at(const ClosestPoint &where) const
    {
      if (where.feature == Feature::vertex)
        return vertex_facets.at(where.a);
      return edge_facets.at({where.a, where.b});
    }



    template <int dim>
    void
    Walls<dim>::find_facet_contacts(
      const unsigned int             grain,
      const Point<dim>              &x,
      const double                   radius,
      const double                   alert,
      std::vector<unsigned int>     &candidates,
      std::vector<WallContact<dim>> &contacts) const
    {
      if (facets.empty())
        return;
      const double reach = radius + std::max(alert, 0.);
      facet_buckets.near(x, reach, candidates);
      // Distances that differ by less than this are the same point.
      const double same = 1e-12 * std::max(radius, reach);
      for (const unsigned int f : candidates)
      {
        const ClosestPoint closest = closest_point(f, x);
        const double       d       = x.distance(closest.point);
        if (d - radius >= alert)
          continue;
        const auto &n = facets[f].inward_normal;
        if (closest.feature == Feature::inside)
        {
          // Signed: a centre that went through the facet (by less than a
          // radius) overlaps it by more than its radius. Further behind,
          // the facet is the far side of a thin solid, not this grain's.
          const double s = (x - closest.point) * n;
          if (s > -radius && s - radius < alert)
            contacts.push_back({grain, facet_walls[f], -n, s - radius});
          continue;
        }
        // An edge or a vertex: a contact where it is the closest point of
        // every facet sharing it, reported by the first of them.
        bool keep = d > 0;
        for (const unsigned int g : facets_at(closest))
          if (g != f && keep)
          {
            const double e = x.distance(closest_point(g, x).point);
            keep           = e >= d - same && !(g < f && e <= d + same);
          }
        if (keep)
          contacts.push_back(
            {grain, facet_walls[f], (closest.point - x) / d, d - radius});
      }
    }



    template class Walls<2>;
    template class Walls<3>;
  } // namespace Contact
} // namespace ImmersedGrains
