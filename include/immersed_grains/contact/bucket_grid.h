#ifndef immersed_grains_contact_bucket_grid_h
#define immersed_grains_contact_bucket_grid_h

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
