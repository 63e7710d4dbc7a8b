#ifndef immersed_grains_contact_bucket_grid_h
#define immersed_grains_contact_bucket_grid_h

#include <deal.II/base/point.h>
#include <deal.II/base/tensor.h>

#include <array>
#include <cmath>
#include <vector>

namespace ImmersedGrains
{
  namespace Contact
  {
    using dealii::Point;
    using dealii::Tensor;

    /**
     * A candidate grain-grain contact: two grains whose gap is below the
     * alert distance at the start of the step.
     */
    template <int dim>
    struct GrainPair
    {
      /// Grain indices, first < second.
      unsigned int first;
      unsigned int second;

      /// Unit normal from the centre of @p first to the centre of the image
      /// of @p second that is nearest to it.
      Tensor<1, dim> normal;

      /// Centre distance minus both radii (negative: overlap), in metres.
      double gap;

      /// Periodic image used: x[second] + shift is the centre seen by
      /// @p first. Zero unless the pair touches across a periodic face.
      Tensor<1, dim> shift;
    };

    /**
     * The pair of grain @p i (the one that searches) with grain @p j, from
     * their centres wrapped into the box on the periodic axes (@p xi,
     * @p xj: the positions minus @p wrap_i, @p wrap_j periods): true, with
     * @p pair filled, where |x_j - x_i| - r_i - r_j < @p alert_distance for
     * the nearest periodic image. BucketGrid and NeighbourList both build
     * their pairs here, so that a pair comes out bit for bit the same from
     * either, whichever of its grains searches.
     */
    template <int dim>
#if defined(__GNUC__)
    // Runs in the search's innermost loop, where it rejects most grains:
    // inlined there rather than called.
    __attribute__((always_inline))
#endif
    inline bool
    evaluate_pair(const unsigned int           i,
                  const unsigned int           j,
                  const Point<dim>            &xi,
                  const Point<dim>            &xj,
                  const double                 ri,
                  const double                 rj,
                  const std::array<int, dim>  &wrap_i,
                  const std::array<int, dim>  &wrap_j,
                  const double                 alert_distance,
                  const std::array<bool, dim> &periodic,
                  const bool                   any_periodic,
                  const Tensor<1, dim>        &extent,
                  GrainPair<dim>              &pair)
    {
      Tensor<1, dim>       d = xj - xi;
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
      const double reach = ri + rj + alert_distance;
      const double dist2 = d.norm_square();
      if (dist2 >= reach * reach)
        return false;

      // Stored with first < second: seen from j when j < i.
      const bool flip   = j < i;
      pair.first        = flip ? j : i;
      pair.second       = flip ? i : j;
      const double dist = std::sqrt(dist2);
      if (dist > 0)
        pair.normal = (flip ? -d : d) / dist;
      else
      {
        pair.normal    = Tensor<1, dim>();
        pair.normal[0] = 1; // coincident centres: any unit vector
      }
      pair.gap = dist - ri - rj;
      // d = (x_j + shift) - x_i with shift a whole number of periods.
      pair.shift = Tensor<1, dim>();
      for (unsigned int a = 0; a < dim; ++a)
        if (periodic[a])
        {
          pair.shift[a] =
            (wrap_j[a] - wrap_i[a]) * -extent[a] + image[a] * extent[a];
          if (flip)
            pair.shift[a] = -pair.shift[a];
        }
      return true;
    }

    /**
     * Uniform bucket grid ("cell list") for the grain-grain neighbour search,
     * independent of any finite element mesh: O(N) for a bounded number of
     * grains per bucket.
     *
     * The bucket edge is at least the diameter of the largest "small"
     * grain (the 90th percentile of the radii, at least twice the smallest
     * radius, or the largest grain when all are within a factor 2) plus the
     * alert distance, so every pair of small grains closer than the alert
     * distance lies in the same or in adjacent buckets; a larger grain
     * scans the buckets within its reach. A few large grains among many
     * small ones thus keep the search O(N). Grains outside the box on a
     * non-periodic axis are clamped into the outermost bucket layer, which
     * keeps the search correct (only slower) for grains that escaped through a
     * wall. On a periodic axis positions are wrapped and pairs use the nearest
     * image; that axis must be at least two bucket edges long, so that no grain
     * can see two images of the same neighbour.
     *
     * The object keeps its work arrays between calls, so that a time loop
     * does not allocate once the grain count is steady.
     */
    template <int dim>
    class BucketGrid
    {
    public:
      /**
       * The box [lower, upper] in which the grains live (positions outside
       * it are allowed on non-periodic axes) and which axes are periodic.
       */
      BucketGrid(const Point<dim>            &lower,
                 const Point<dim>            &upper,
                 const std::array<bool, dim> &periodic = {});

      /**
       * Fills @p pairs with every pair (i < j) with
       * |x_j - x_i| - r_i - r_j < alert_distance, sorted by (i, j).
       */
      void
      find_pairs(const std::vector<Point<dim>> &positions,
                 const std::vector<double>     &radii,
                 const double                   alert_distance,
                 std::vector<GrainPair<dim>>   &pairs);

      /// The radius above which a grain counts as large in the last
      /// find_pairs() call: a large grain searches for its pairs with the
      /// small grains of lower index, which skip it.
      double
      large_radius() const
      {
        return cut_radius;
      }

      /**
       * Fills @p grains with the grains of the last find_pairs() call (their
       * indices there) whose buckets lie within @p distance of @p x (on a
       * periodic axis, of any of its images): every grain of that call
       * whose centre was within @p distance of @p x is among them.
       */
      void
      grains_near(const Point<dim>          &x,
                  double                     distance,
                  std::vector<unsigned int> &grains) const;

      /// Number of buckets per axis chosen by the last find_pairs() call.
      const std::array<unsigned int, dim> &
      n_buckets() const;

    private:
      Point<dim>            lower;
      Tensor<1, dim>        extent;
      std::array<bool, dim> periodic;

      // The box the buckets cover in the last call: on non-periodic axes
      // the part of [lower, upper] that the grains occupy, so that a cloud
      // in a large domain gets buckets of its own scale.
      Point<dim>     grid_lower;
      Tensor<1, dim> grid_extent;

      double cut_radius = 0;

      std::array<unsigned int, dim> n_buckets_per_axis;
      Tensor<1, dim>                bucket_size;

      // Work arrays, grains sorted by bucket (counting sort).
      std::vector<unsigned int>         bucket_of_grain;
      std::vector<unsigned int>         bucket_start;
      std::vector<unsigned int>         grain_in_order;
      std::vector<Point<dim>>           wrapped_position;
      std::vector<double>               sorted_radius;
      std::vector<std::array<int, dim>> wrap_count;
      std::vector<unsigned int>         sort_buffer;
      std::vector<double>               sort_buffer_radius;
      // Pairs of a large grain with small grains of lower index.
      std::vector<GrainPair<dim>> late_pairs;

      /** Buckets of edge at least @p min_size; a periodic axis must be at
       *  least twice @p largest_reach (the largest diameter plus the alert
       *  distance) long. */
      void
      choose_buckets(const unsigned int n_grains,
                     const double       largest_reach,
                     const double       min_size);

      void
      sort_grains_into_buckets(const std::vector<Point<dim>> &positions,
                               const std::vector<double>     &radii);
    };
  } // namespace Contact
} // namespace ImmersedGrains

#endif
