#include <deal.II/base/exceptions.h>

#include <immersed_grains/contact/walls.h>

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
      wall_velocities.push_back(velocity);
      return planes.size() - 1;
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
      AssertIndexRange(wall, planes.size());
      planes[wall].velocity = velocity;
      wall_velocities[wall] = velocity;
    }



    template <int dim>
    unsigned int
    Walls<dim>::n_walls() const
    {
      return planes.size();
    }



    template <int dim>
    const PlaneWall<dim> &
    Walls<dim>::plane(const unsigned int wall) const
    {
      AssertIndexRange(wall, planes.size());
      return planes[wall];
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
      for (unsigned int i = 0; i < positions.size(); ++i)
        for (unsigned int w = 0; w < planes.size(); ++w)
        {
          const double gap =
            (positions[i] - planes[w].point) * planes[w].inward_normal -
            radii[i];
          if (gap < alert_distance)
            contacts.push_back({i, w, -planes[w].inward_normal, gap});
        }
    }



    template class Walls<2>;
    template class Walls<3>;
  } // namespace Contact
} // namespace ImmersedGrains
