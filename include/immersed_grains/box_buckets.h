#ifndef immersed_grains_box_buckets_h
#define immersed_grains_box_buckets_h

#include <deal.II/base/bounding_box.h>
#include <deal.II/base/point.h>

#include <array>
#include <vector>

namespace ImmersedGrains
{
  /**
   * A uniform grid of buckets over a box, each bucket holding the numbers
   * of the bounding boxes that reach into it: which of many fixed objects
   * (a mesh's boundary facets, its coarse cells) lie near a point, without
   * testing them all.
   */
  template <int dim>
  class BoxBuckets
  {
  public:
    /**
     * Buckets of edge @p bucket_size (larger where that would make more
     * than 8 buckets per box) over [@p lower, @p upper], filled with
     * @p boxes.
     */
    void
    reinit(const dealii::Point<dim>                    &lower,
           const dealii::Point<dim>                    &upper,
           double                                       bucket_size,
           const std::vector<dealii::BoundingBox<dim>> &boxes);

    /** The boxes in the buckets that [x - reach, x + reach] meets, each
     *  once, in increasing order. */
    void
    near(const dealii::Point<dim>  &x,
         const double               reach,
         std::vector<unsigned int> &found) const;

    /** The boxes in the bucket of @p x (none outside the grid). */
    const std::vector<unsigned int> &
    at(const dealii::Point<dim> &x) const;

  private:
    /** Calls @p f with the number of every bucket from @p from to @p to. */
    template <typename Function>
    void
    for_each_bucket(const std::array<unsigned int, dim> &from,
                    const std::array<unsigned int, dim> &to,
                    const Function                      &f) const;

    /** The bucket index along each axis of the range [a, b]. */
    bool
    range(const dealii::Point<dim>      &a,
          const dealii::Point<dim>      &b,
          std::array<unsigned int, dim> &from,
          std::array<unsigned int, dim> &to) const;

    dealii::Point<dim>                     origin;
    double                                 size = 1;
    std::array<unsigned int, dim>          n_buckets{};
    std::vector<std::vector<unsigned int>> buckets;
    std::vector<unsigned int>              none;
  };
} // namespace ImmersedGrains

#endif
