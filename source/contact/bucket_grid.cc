#include <deal.II/base/exceptions.h>

#include <immersed_grains/contact/bucket_grid.h>

#include <algorithm>
#include <cmath>

namespace ImmersedGrains
{
  namespace Contact
  {
    namespace
    {
      // Steps @p q to the next combination of one bucket coordinate per
      // axis from @p around, axes below @p first_axis fixed: false after
      // the last.
      template <int dim>
      bool
      next_bucket(std::array<unsigned int, dim>                    &q,
                  const std::array<std::vector<unsigned int>, dim> &around,
                  const unsigned int                                first_axis)
      {
        for (unsigned int d = first_axis; d < dim; ++d)
        {
          if (++q[d] < around[d].size())
            return true;
          q[d] = 0;
        }
        return false;
      }
    } // namespace


    template <int dim>
    BucketGrid<dim>::BucketGrid(const Point<dim>            &lower,
                                const Point<dim>            &upper,
                                const std::array<bool, dim> &periodic)
        : lower(lower)
        , extent(upper - lower)
        , periodic(periodic)
        , grid_lower(lower)
        , grid_extent(upper - lower)
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
                                    const double       largest_reach,
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
          AssertThrow(extent[d] >= 2 * largest_reach,
                      dealii::ExcMessage(
                        "BucketGrid: a periodic axis must be at least two "
                        "times (largest diameter + alert distance) long, "
                        "else a grain could touch two images of the same "
                        "neighbour."));
        n[d] =
          std::max(1., std::min(std::floor(grid_extent[d] / min_size), 1e6));
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
        bucket_size[d]        = grid_extent[d] / n[d];
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
          double x = positions[i][d] - grid_lower[d];
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
      const unsigned int n_grains = positions.size();
      if (n_grains == 0)
        return;

      // Buckets sized by the largest "small" radius r_cut, not by the
      // largest grain: with a few large grains among many small ones,
      // buckets of the large grains' size would hold (R/r)^dim small ones
      // each. A small grain (r <= r_cut) finds its small partners in the
      // adjacent buckets; a large one scans the buckets within
      // r_i + r_max + alert and finds every pair it is part of.
      const auto [min_it, max_it] =
        std::minmax_element(radii.begin(), radii.end());
      const double max_radius = *max_it;
      cut_radius              = max_radius;
      if (max_radius > 2 * *min_it)
      {
        // The 90th percentile, at least twice the smallest radius: a
        // tenth of the grains scanning wider is cheaper than every grain
        // scanning buckets sized for the largest.
        sort_buffer_radius.assign(radii.begin(), radii.end());
        auto nth =
          sort_buffer_radius.begin() + static_cast<long>(0.9 * (n_grains - 1));
        std::nth_element(sort_buffer_radius.begin(),
                         nth,
                         sort_buffer_radius.end());
        cut_radius = std::min(max_radius, std::max(2 * *min_it, *nth));
      }
      const double min_size = 2 * cut_radius + alert_distance;
      // Buckets over the grains' bounding box within the domain on the
      // non-periodic axes. Over the whole domain, a cloud of 10,000
      // spheres in a box 14 cloud radii wide got buckets of 0.3 mm holding
      // 150 grains each, and this search took 40 % of a coupled run.
      for (unsigned int d = 0; d < dim; ++d)
      {
        grid_lower[d]  = lower[d];
        grid_extent[d] = extent[d];
        if (periodic[d])
          continue;
        double lo = lower[d] + extent[d], hi = lower[d];
        for (const auto &x : positions)
        {
          lo = std::min(lo, x[d]);
          hi = std::max(hi, x[d]);
        }
        lo             = std::max(lo, lower[d]);
        hi             = std::min(hi, lower[d] + extent[d]);
        grid_lower[d]  = std::min(lo, hi);
        grid_extent[d] = std::max(hi - lo, min_size);
      }
      choose_buckets(n_grains, 2 * max_radius + alert_distance, min_size);
      sort_grains_into_buckets(positions, radii);

      bool any_periodic = false;
      for (unsigned int d = 0; d < dim; ++d)
        any_periodic |= periodic[d];
      std::array<unsigned int, dim> stride;
      stride[0] = 1;
      for (unsigned int d = 1; d < dim; ++d)
        stride[d] = stride[d - 1] * n_buckets_per_axis[d - 1];

      // Grain by grain in index order, each against the grains of higher
      // index in its own and the adjacent buckets: the pairs come out
      // sorted by first, and only a grain's few partners need sorting (by
      // second). Sorting all pairs after a bucket-by-bucket search instead
      // gathered 64-byte records at random and made the time per grain grow
      // with N (241 to 455 ns from 1e3 to 1e5 grains in 3D, doc/contacts.md),
      // even for grains given in spatial order. Callers pass grains in
      // the ParticleHandler's cell order, so the buckets one grain reads
      // are mostly those its predecessor read. A large grain's pairs with
      // small grains of lower index go to a second list, merged at the end.
      const auto &xs = wrapped_position;
      const auto &rs = sorted_radius;
      late_pairs.clear();
      std::array<std::vector<unsigned int>, dim> around;
      for (unsigned int i = 0; i < n_grains; ++i)
      {
        const double ri    = radii[i];
        const bool   large = ri > cut_radius;
        // The distinct bucket coordinates around grain i on each axis
        // (fewer at a wall, or on a short periodic axis).
        for (unsigned int d = 0; d < dim; ++d)
        {
          const int n = n_buckets_per_axis[d];
          const int c = (bucket_of_grain[i] / stride[d]) % n;
          const int k =
            large ?
              static_cast<int>(
                std::min<double>(n,
                                 std::ceil((ri + max_radius + alert_distance) /
                                           bucket_size[d]))) :
              1;
          around[d].clear();
          for (int o = -k; o <= k; ++o)
          {
            int b = c + o;
            if (b < 0 || b >= n)
            {
              if (!periodic[d])
                continue;
              b = ((b % n) + n) % n;
            }
            if (std::find(around[d].begin(),
                          around[d].end(),
                          static_cast<unsigned int>(b)) == around[d].end())
              around[d].push_back(b);
          }
        }

        Point<dim> xi;
        for (unsigned int d = 0; d < dim; ++d)
          xi[d] = positions[i][d] - wrap_count[i][d] * extent[d];
        const unsigned int first = pairs.size();
        // Grains in slots [begin, end) of the bucket order.
        const auto scan = [&](const unsigned int begin, const unsigned int end)
        {
          for (unsigned int l = begin; l < end; ++l)
          {
            const unsigned int j = grain_in_order[l];
            // A small grain pairs here with small grains of higher index;
            // a large one with every grain of higher index and with the
            // small ones of lower index (which skip it).
            const bool j_large = rs[l] > cut_radius;
            if (j == i || (!large && (j < i || j_large)) ||
                (large && j < i && j_large))
              continue;
            GrainPair<dim> pair;
            if (!evaluate_pair<dim>(i,
                                    j,
                                    xi,
                                    xs[l],
                                    ri,
                                    rs[l],
                                    wrap_count[i],
                                    wrap_count[j],
                                    alert_distance,
                                    periodic,
                                    any_periodic,
                                    extent,
                                    pair))
              continue;
            const bool flip = j < i;
            (flip ? late_pairs : pairs).push_back(pair);
          }
        };

        // Rows along axis 0: without wrapping, its buckets are adjacent in
        // the bucket order, so one row is one contiguous range.
        std::array<unsigned int, dim> q{};
        while (true)
        {
          unsigned int row = 0;
          for (unsigned int d = 1; d < dim; ++d)
            row += stride[d] * around[d][q[d]];
          if (!periodic[0])
            scan(bucket_start[row + around[0].front()],
                 bucket_start[row + around[0].back() + 1]);
          else
            for (const unsigned int b : around[0])
              scan(bucket_start[row + b], bucket_start[row + b + 1]);
          if (!next_bucket<dim>(q, around, 1))
            break;
        }
        std::sort(pairs.begin() + first,
                  pairs.end(),
                  [](const GrainPair<dim> &a, const GrainPair<dim> &b)
                  { return a.second < b.second; });
      }
      if (!late_pairs.empty())
      {
        const auto order = [](const GrainPair<dim> &a, const GrainPair<dim> &b)
        {
          return a.first < b.first ||
                 (a.first == b.first && a.second < b.second);
        };
        std::sort(late_pairs.begin(), late_pairs.end(), order);
        const auto middle = pairs.size();
        pairs.insert(pairs.end(), late_pairs.begin(), late_pairs.end());
        std::inplace_merge(pairs.begin(),
                           pairs.begin() + middle,
                           pairs.end(),
                           order);
      }
    }



    template <int dim>
    void
    BucketGrid<dim>::grains_near(const Point<dim>          &x,
                                 const double               distance,
                                 std::vector<unsigned int> &grains) const
    {
      grains.clear();
      if (bucket_start.empty())
        return;
      // The bucket coordinates on each axis, one more on either side than
      // the distance needs: a centre on a bucket's edge may have been
      // rounded into its neighbour.
      std::array<std::vector<unsigned int>, dim> around;
      for (unsigned int d = 0; d < dim; ++d)
      {
        const int n = n_buckets_per_axis[d];
        double    y = x[d] - grid_lower[d];
        if (periodic[d])
          y -= extent[d] * std::floor(y / extent[d]);
        const double first = std::floor((y - distance) / bucket_size[d]) - 1,
                     last  = std::floor((y + distance) / bucket_size[d]) + 1;
        if (periodic[d] && last - first + 1 >= n)
          for (int b = 0; b < n; ++b)
            around[d].push_back(b);
        else if (periodic[d])
          for (double b = first; b <= last; ++b)
            around[d].push_back(((static_cast<int>(b) % n) + n) % n);
        else
          // Grains beyond the box on this axis lie in its outer buckets.
          for (double b = std::min(std::max(first, 0.), n - 1.);
               b <= std::min(std::max(last, 0.), n - 1.);
               ++b)
            around[d].push_back(static_cast<unsigned int>(b));
        if (around[d].empty())
          return;
      }
      std::array<unsigned int, dim> stride;
      stride[0] = 1;
      for (unsigned int d = 1; d < dim; ++d)
        stride[d] = stride[d - 1] * n_buckets_per_axis[d - 1];
      std::array<unsigned int, dim> q{};
      while (true)
      {
        unsigned int bucket = 0;
        for (unsigned int d = 0; d < dim; ++d)
          bucket += stride[d] * around[d][q[d]];
        for (unsigned int l = bucket_start[bucket];
             l < bucket_start[bucket + 1];
             ++l)
          grains.push_back(grain_in_order[l]);
        if (!next_bucket<dim>(q, around, 0))
          break;
      }
    }



    template class BucketGrid<2>;
    template class BucketGrid<3>;
  } // namespace Contact
} // namespace ImmersedGrains
