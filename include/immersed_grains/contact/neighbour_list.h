#ifndef immersed_grains_contact_neighbour_list_h
#define immersed_grains_contact_neighbour_list_h

#include <immersed_grains/contact/bucket_grid.h>

#include <cstdint>
#include <vector>

namespace ImmersedGrains
{
  namespace Contact
  {
    /**
     * The grain-grain neighbour search kept over several calls (a Verlet
     * list): BucketGrid finds the pairs within the alert distance plus a
     * skin, and later calls only test those candidates, for as long as no
     * two grains can have closed the skin since, i.e. while the two largest
     * displacements since that search, less the grains' common
     * translation, add up to less than the skin plus the alert distance of
     * that search minus the present one. A pair is
     * evaluated by the same function as in BucketGrid (evaluate_pair()), and
     * the list comes out sorted by (first, second), so find_pairs() returns
     * exactly what BucketGrid::find_pairs() would, bit for bit.
     *
     * Grains are recognised by their ids, so the caller may reorder them
     * between calls (the ParticleHandler's cell order changes as grains
     * cross cells). A grain that has gone leaves its candidates unused; a
     * grain that was not there at the last search joins the candidates
     * with the grains near it (BucketGrid::grains_near()), while such
     * newcomers are few and all radii lie within a factor 2 (else a new
     * search, as for a changed radius). Displacements on a periodic axis are
     * taken modulo its length, so a grain wrapped to the other side keeps the
     * list.
     */
    template <int dim>
    class NeighbourList
    {
    public:
      /**
       * The box and its periodic axes as for BucketGrid; @p skin_factor
       * times the smallest diameter is the skin (0: a new search at every
       * call).
       */
      NeighbourList(const Point<dim>            &lower,
                    const Point<dim>            &upper,
                    const std::array<bool, dim> &periodic    = {},
                    const double                 skin_factor = default_skin);

      /**
       * As BucketGrid::find_pairs(): every pair (i < j) with
       * |x_j - x_i| - r_i - r_j < alert_distance, sorted by (i, j). @p ids
       * names each grain across calls (unique; empty: the index is the id,
       * and the caller keeps the order).
       */
      void
      find_pairs(const std::vector<Point<dim>>    &positions,
                 const std::vector<double>        &radii,
                 const std::vector<std::uint64_t> &ids,
                 double                            alert_distance,
                 std::vector<GrainPair<dim>>      &pairs);

      /// Calls of find_pairs() so far, and how many of them searched.
      unsigned long
      n_calls() const
      {
        return calls;
      }

      unsigned long
      n_searches() const
      {
        return searches;
      }

      /// A quarter of the smallest grain's diameter: chosen on the 3D
      /// falling cloud and the 10^5-grain suspension (doc/contacts.md,
      /// "Kept over sub-steps").
      static constexpr double default_skin = 0.25;

    private:
      BucketGrid<dim>       grid;
      Point<dim>            lower;
      Tensor<1, dim>        extent;
      std::array<bool, dim> periodic;
      bool                  any_periodic = false;
      double                skin_factor;

      unsigned long calls = 0, searches = 0;

      // The last search: its grains (by their index then), where they
      // were, their radii, the alert distance plus skin it used, and
      // whether each grain counted as large (BucketGrid::large_radius()).
      std::vector<std::uint64_t> search_ids;
      std::vector<Point<dim>>    search_position;
      std::vector<double>        search_radius;
      std::vector<char>          search_large;
      double                     search_reach = 0;
      // The grains BucketGrid searched (the first ones of the arrays above;
      // newcomers since are appended), and the extreme radii of all.
      unsigned int n_searched   = 0;
      double       search_r_min = 0, search_r_max = 0;
      // Its candidates, as indices of that search.
      struct Candidate
      {
        unsigned int first, second;
      };
      std::vector<Candidate> candidates;

      // The search's index of an id: dense where the ids allow.
      std::vector<unsigned int>                           index_of_id;
      std::vector<std::pair<std::uint64_t, unsigned int>> sorted_ids;

      // Work arrays of a call.
      std::vector<unsigned int>         now_of_search, search_of_now;
      std::vector<std::array<int, dim>> wrap_count;
      std::vector<Point<dim>>           wrapped;
      std::vector<Tensor<1, dim>>       displacement;
      std::vector<unsigned int>         newcomers, nearby;

      void
      search(const std::vector<Point<dim>>    &positions,
             const std::vector<double>        &radii,
             const std::vector<std::uint64_t> &ids,
             double                            alert_distance,
             double                            skin);

      /// Whether the candidates still hold every pair within
      /// @p alert_distance; fills search_of_now and now_of_search.
      bool
      still_valid(const std::vector<Point<dim>>    &positions,
                  const std::vector<double>        &radii,
                  const std::vector<std::uint64_t> &ids,
                  double                            alert_distance);
    };
  } // namespace Contact
} // namespace ImmersedGrains

#endif
