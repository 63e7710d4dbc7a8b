#include <deal.II/base/exceptions.h>

#include <immersed_grains/contact/bucket_grid.h>

#include <algorithm>
#include <cmath>

namespace ImmersedGrains
{
  namespace Contact
  {
    template <int dim>
    BucketGrid<dim>::BucketGrid(const Point<dim>            &lower,
                                const Point<dim>            &upper,
                                const std::array<bool, dim> &periodic)
        : lower(lower)
        , extent(upper - lower)
        , periodic(periodic)
    {
      for (unsigned int d = 0; d < dim; ++d)
      {
        AssertThrow(extent[d] > 0,
                    dealii::ExcMessage(
                      "BucketGrid: the upper corner must lie above the "
                      "lower corner on every axis."));
        n_buckets_per_axis[d] = 1;
        bucket_size[d]        = extent[d];
      }
    }



    template <int dim>
    const std::array<unsigned int, dim> &
    BucketGrid<dim>::n_buckets() const
    {
      return n_buckets_per_axis;
    }



    template <int dim>
    void
    BucketGrid<dim>::choose_buckets(const unsigned int n_grains,
                                    const double       min_size)
    {
      // A very sparse population in a large box would otherwise ask for more
      // buckets than memory holds; a few buckets per grain keep the search
      // O(N) with larger buckets instead.
      const double max_buckets = std::max(64., 4. * n_grains);

      std::array<double, dim> n;
      double                  total = 1;
      for (unsigned int d = 0; d < dim; ++d)
      {
        if (periodic[d])
          AssertThrow(extent[d] >= 2 * min_size,
                      dealii::ExcMessage(
                        "BucketGrid: a periodic axis must be at least two "
                        "times (largest diameter + alert distance) long, "
                        "else a grain could touch two images of the same "
                        "neighbour."));
        n[d] = std::max(1., std::min(std::floor(extent[d] / min_size), 1e6));
        total *= n[d];
      }
      while (total > max_buckets)
      {
        const double shrink = std::pow(total / max_buckets, 1. / dim);
        total               = 1;
        for (unsigned int d = 0; d < dim; ++d)
        {
          n[d] = std::max(1., std::floor(n[d] / shrink));
          total *= n[d];
        }
      }
      for (unsigned int d = 0; d < dim; ++d)
      {
        n_buckets_per_axis[d] = static_cast<unsigned int>(n[d]);
        bucket_size[d]        = extent[d] / n[d];
      }
    }



    template <int dim>
    void
    BucketGrid<dim>::sort_grains_into_buckets(
      const std::vector<Point<dim>> &positions,
      const std::vector<double>     &radii)
    {
      const unsigned int n_grains = positions.size();
      unsigned int       n_total  = 1;
      for (unsigned int d = 0; d < dim; ++d)
        n_total *= n_buckets_per_axis[d];

      bucket_of_grain.resize(n_grains);
      wrap_count.resize(n_grains);
      for (unsigned int i = 0; i < n_grains; ++i)
      {
        unsigned int bucket = 0;
        unsigned int stride = 1;
        for (unsigned int d = 0; d < dim; ++d)
        {
          double x = positions[i][d] - lower[d];
          int    c = 0;
          if (periodic[d])
          {
            c = static_cast<int>(std::floor(x / extent[d]));
            x -= c * extent[d];
          }
          wrap_count[i][d] = c;
          // Clamped in floating point first: a grain far outside the box
          // (or at infinity) must not overflow the integer conversion.
          const double s =
            std::min(std::max(std::floor(x / bucket_size[d]), 0.),
                     n_buckets_per_axis[d] - 1.);
          bucket += stride * static_cast<unsigned int>(s);
          stride *= n_buckets_per_axis[d];
        }
        bucket_of_grain[i] = bucket;
      }

      bucket_start.assign(n_total + 1, 0);
      for (unsigned int i = 0; i < n_grains; ++i)
        ++bucket_start[bucket_of_grain[i] + 1];
      for (unsigned int b = 0; b < n_total; ++b)
        bucket_start[b + 1] += bucket_start[b];

      grain_in_order.resize(n_grains);
      sort_buffer.assign(bucket_start.begin(), bucket_start.end() - 1);
      for (unsigned int i = 0; i < n_grains; ++i)
        grain_in_order[sort_buffer[bucket_of_grain[i]]++] = i;

      // Positions (wrapped into the box on periodic axes) and radii in
      // bucket order, so that the pair loop reads memory contiguously.
      wrapped_position.resize(n_grains);
      sorted_radius.resize(n_grains);
      for (unsigned int k = 0; k < n_grains; ++k)
      {
        const unsigned int i = grain_in_order[k];
        for (unsigned int d = 0; d < dim; ++d)
          wrapped_position[k][d] =
            positions[i][d] - wrap_count[i][d] * extent[d];
        sorted_radius[k] = radii[i];
      }
    }



    template <int dim>
    void
    BucketGrid<dim>::sort_pairs_by_index(const unsigned int           n_grains,
                                         std::vector<GrainPair<dim>> &pairs)
    {
      // Two stable counting sorts (by second, then by first): O(N + pairs),
      // and an order that does not depend on the bucket layout.
      const unsigned int         n_pairs   = unsorted_pairs.size();
      std::vector<unsigned int> &by_second = sort_buffer;
      by_second.resize(n_pairs);
      by_first.resize(n_pairs);
      sort_count.assign(n_grains + 1, 0);
      for (const auto &pair : unsorted_pairs)
        ++sort_count[pair.second + 1];
      for (unsigned int i = 0; i < n_grains; ++i)
        sort_count[i + 1] += sort_count[i];
      for (unsigned int p = 0; p < n_pairs; ++p)
        by_second[sort_count[unsorted_pairs[p].second]++] = p;

      sort_count.assign(n_grains + 1, 0);
      for (const auto &pair : unsorted_pairs)
        ++sort_count[pair.first + 1];
      for (unsigned int i = 0; i < n_grains; ++i)
        sort_count[i + 1] += sort_count[i];
      for (const unsigned int p : by_second)
        by_first[sort_count[unsorted_pairs[p].first]++] = p;

      pairs.resize(n_pairs);
      for (unsigned int p = 0; p < n_pairs; ++p)
        pairs[p] = unsorted_pairs[by_first[p]];
    }



    template <int dim>
    void
    BucketGrid<dim>::find_pairs(const std::vector<Point<dim>> &positions,
                                const std::vector<double>     &radii,
                                const double                   alert_distance,
                                std::vector<GrainPair<dim>>   &pairs)
    {
      AssertThrow(radii.size() == positions.size(),
                  dealii::ExcMessage(
                    "BucketGrid: one radius per position is needed."));
      AssertThrow(alert_distance >= 0,
                  dealii::ExcMessage(
                    "BucketGrid: the alert distance must not be negative."));

      pairs.clear();
      unsorted_pairs.clear();
      const unsigned int n_grains = positions.size();
      if (n_grains == 0)
        return;

      const double max_radius = *std::max_element(radii.begin(), radii.end());
      choose_buckets(n_grains, 2 * max_radius + alert_distance);
      sort_grains_into_buckets(positions, radii);

      // With fewer than three buckets on a periodic axis the offsets -1 and
      // +1 name the same bucket; only then is a duplicate check needed.
      bool may_repeat = false;
      for (unsigned int d = 0; d < dim; ++d)
        may_repeat |= (periodic[d] && n_buckets_per_axis[d] < 3);

      bool any_periodic = false;
      for (unsigned int d = 0; d < dim; ++d)
        any_periodic |= periodic[d];

      const auto &xs        = wrapped_position;
      const auto &rs        = sorted_radius;
      const auto  test_pair = [&](const unsigned int k, const unsigned int l)
      {
        Tensor<1, dim>       d = xs[l] - xs[k];
        std::array<int, dim> image{};
        if (any_periodic)
          for (unsigned int a = 0; a < dim; ++a)
            if (periodic[a])
            {
              if (d[a] > 0.5 * extent[a])
                image[a] = -1;
              else if (d[a] < -0.5 * extent[a])
                image[a] = 1;
              d[a] += image[a] * extent[a];
            }
        const double reach = rs[k] + rs[l] + alert_distance;
        const double dist2 = d.norm_square();
        if (dist2 >= reach * reach)
          return;

        const unsigned int i = grain_in_order[k];
        const unsigned int j = grain_in_order[l];

        const double   dist = std::sqrt(dist2);
        Tensor<1, dim> normal;
        if (dist > 0)
          normal = d / dist;
        else
          normal[0] = 1; // coincident centres: any unit vector will do

        // d = (x_j + shift) - x_i with shift a whole number of periods.
        Tensor<1, dim> shift;
        for (unsigned int a = 0; a < dim; ++a)
          if (periodic[a])
            shift[a] = (wrap_count[j][a] - wrap_count[i][a]) * -extent[a] +
                       image[a] * extent[a];

        GrainPair<dim> pair;
        pair.gap = dist - rs[k] - rs[l];
        if (i < j)
        {
          pair.first  = i;
          pair.second = j;
          pair.normal = normal;
          pair.shift  = shift;
        }
        else
        {
          pair.first  = j;
          pair.second = i;
          pair.normal = -normal;
          pair.shift  = -shift;
        }
        unsorted_pairs.push_back(pair);
      };

      std::array<unsigned int, dim> index{};
      unsigned int                  n_total = 1;
      for (unsigned int d = 0; d < dim; ++d)
        n_total *= n_buckets_per_axis[d];

      constexpr unsigned int              n_offsets = (dim == 2 ? 9 : 27);
      std::array<unsigned int, n_offsets> neighbours;
      for (unsigned int b = 0; b < n_total; ++b)
      {
        // index is the multi-index of bucket b (axis 0 runs fastest).
        unsigned int n_neighbours = 0;
        for (unsigned int o = 0; o < n_offsets; ++o)
        {
          unsigned int offset_code = o;
          unsigned int neighbour   = 0;
          unsigned int stride      = 1;
          bool         inside      = true;
          for (unsigned int d = 0; d < dim; ++d)
          {
            int c = static_cast<int>(index[d]) +
                    static_cast<int>(offset_code % 3) - 1;
            offset_code /= 3;
            const int n = n_buckets_per_axis[d];
            if (c < 0 || c >= n)
            {
              if (!periodic[d])
              {
                inside = false;
                break;
              }
              c = (c + n) % n;
            }
            neighbour += stride * c;
            stride *= n;
          }
          // Each unordered bucket pair is visited from its lower bucket.
          if (!inside || neighbour < b)
            continue;
          if (may_repeat &&
              std::find(neighbours.begin(),
                        neighbours.begin() + n_neighbours,
                        neighbour) != neighbours.begin() + n_neighbours)
            continue;
          neighbours[n_neighbours++] = neighbour;
        }

        for (unsigned int q = 0; q < n_neighbours; ++q)
        {
          const unsigned int nb = neighbours[q];
          for (unsigned int k = bucket_start[b]; k < bucket_start[b + 1]; ++k)
            for (unsigned int l = (nb == b ? k + 1 : bucket_start[nb]);
                 l < bucket_start[nb + 1];
                 ++l)
              test_pair(k, l);
        }

        for (unsigned int d = 0; d < dim; ++d)
        {
          if (++index[d] < n_buckets_per_axis[d])
            break;
          index[d] = 0;
        }
      }

      sort_pairs_by_index(n_grains, pairs);
    }



    template class BucketGrid<2>;
    template class BucketGrid<3>;
  } // namespace Contact
} // namespace ImmersedGrains
