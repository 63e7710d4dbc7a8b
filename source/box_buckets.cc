#include <immersed_grains/box_buckets.h>

#include <algorithm>
#include <cmath>

namespace ImmersedGrains
{
  template <int dim>
  void
  BoxBuckets<dim>::reinit(const dealii::Point<dim> &lower,
                          const dealii::Point<dim> &upper,
                          const double              bucket_size,
                          const std::vector<dealii::BoundingBox<dim>> &boxes)
  {
    origin      = lower;
    double span = 0;
    for (unsigned int d = 0; d < dim; ++d)
      span = std::max(span, upper[d] - lower[d]);
    size = bucket_size > 0 ? std::max(bucket_size, 1e-6 * span) : 1;
    for (;;)
    {
      std::size_t total = 1;
      for (unsigned int d = 0; d < dim; ++d)
      {
        n_buckets[d] =
          static_cast<unsigned int>((upper[d] - lower[d]) / size) + 1;
        total *= n_buckets[d];
      }
      if (total <= 8 * boxes.size() + 64)
        break;
      size *= 1.5;
    }
    std::size_t total = 1;
    for (unsigned int d = 0; d < dim; ++d)
      total *= n_buckets[d];
    buckets.assign(total, {});
    for (unsigned int k = 0; k < boxes.size(); ++k)
    {
      std::array<unsigned int, dim> from, to;
      const auto &[a, b] = boxes[k].get_boundary_points();
      if (range(a, b, from, to))
        for_each_bucket(from,
                        to,
                        [&](const std::size_t bucket)
                        { buckets[bucket].push_back(k); });
    }
  }


  template <int dim>
  bool
  BoxBuckets<dim>::range(const dealii::Point<dim>      &a,
                         const dealii::Point<dim>      &b,
                         std::array<unsigned int, dim> &from,
                         std::array<unsigned int, dim> &to) const
  {
    for (unsigned int d = 0; d < dim; ++d)
    {
      const double lo = (a[d] - origin[d]) / size,
                   hi = (b[d] - origin[d]) / size;
      if (hi < 0 || lo >= n_buckets[d])
        return false;
      from[d] = lo < 0 ? 0 : static_cast<unsigned int>(lo);
      to[d] =
        std::min<unsigned int>(n_buckets[d] - 1, static_cast<unsigned int>(hi));
    }
    return true;
  }


  template <int dim>
  template <typename Function>
  void
  BoxBuckets<dim>::for_each_bucket(const std::array<unsigned int, dim> &from,
                                   const std::array<unsigned int, dim> &to,
                                   const Function                      &f) const
  {
    std::array<unsigned int, dim> k = from;
    for (;;)
    {
      std::size_t index = 0, stride = 1;
      for (unsigned int d = 0; d < dim; ++d)
      {
        index += k[d] * stride;
        stride *= n_buckets[d];
      }
      f(index);
      unsigned int d = 0;
      for (; d < dim; ++d)
        if (++k[d] <= to[d])
          break;
        else
          k[d] = from[d];
      if (d == dim)
        return;
    }
  }


  template <int dim>
  void
  BoxBuckets<dim>::near(const dealii::Point<dim>  &x,
                        const double               reach,
                        std::vector<unsigned int> &found) const
  {
    found.clear();
    dealii::Point<dim> a = x, b = x;
    for (unsigned int d = 0; d < dim; ++d)
    {
      a[d] -= reach;
      b[d] += reach;
    }
    std::array<unsigned int, dim> from, to;
    if (!range(a, b, from, to))
      return;
    for_each_bucket(from,
                    to,
                    [&](const std::size_t bucket) {
                      found.insert(found.end(),
                                   buckets[bucket].begin(),
                                   buckets[bucket].end());
                    });
    std::sort(found.begin(), found.end());
    found.erase(std::unique(found.begin(), found.end()), found.end());
  }


  template <int dim>
  const std::vector<unsigned int> &
  BoxBuckets<dim>::at(const dealii::Point<dim> &x) const
  {
    std::array<unsigned int, dim> from, to;
    if (buckets.empty() || !range(x, x, from, to))
      return none;
    std::size_t index = 0, stride = 1;
    for (unsigned int d = 0; d < dim; ++d)
    {
      index += from[d] * stride;
      stride *= n_buckets[d];
    }
    return buckets[index];
  }


  template class BoxBuckets<2>;
  template class BoxBuckets<3>;
} // namespace ImmersedGrains
