#include <deal.II/base/exceptions.h>

#include <immersed_grains/contact/neighbour_list.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace ImmersedGrains
{
  namespace Contact
  {
    namespace
    {
      constexpr unsigned int none = std::numeric_limits<unsigned int>::max();
    }


    template <int dim>
    NeighbourList<dim>::NeighbourList(const Point<dim>            &lower,
                                      const Point<dim>            &upper,
                                      const std::array<bool, dim> &periodic,
                                      const double                 skin_factor)
        : grid(lower, upper, periodic)
        , lower(lower)
        , extent(upper - lower)
        , periodic(periodic)
        , skin_factor(skin_factor)
    {
      AssertThrow(skin_factor >= 0,
                  dealii::ExcMessage(
                    "NeighbourList: the skin must not be negative."));
      for (unsigned int d = 0; d < dim; ++d)
        any_periodic |= periodic[d];
    }


    template <int dim>
    void
    NeighbourList<dim>::search(const std::vector<Point<dim>>    &positions,
                               const std::vector<double>        &radii,
                               const std::vector<std::uint64_t> &ids,
                               const double                      alert_distance,
                               double                            skin)
    {
      const unsigned int n = positions.size();
      ++searches;
      // Only the indices are kept: the full records of the wider search,
      // 64 bytes each in 3D, would stay allocated between searches.
      std::vector<GrainPair<dim>> search_pairs;
      grid.find_pairs(positions, radii, alert_distance + skin, search_pairs);
      candidates.resize(search_pairs.size());
      for (std::size_t k = 0; k < search_pairs.size(); ++k)
        candidates[k] = {search_pairs[k].first, search_pairs[k].second};
      search_position = positions;
      search_radius   = radii;
      search_large.resize(n);
      for (unsigned int i = 0; i < n; ++i)
        search_large[i] = radii[i] > grid.large_radius();
      search_reach = alert_distance + skin;
      n_searched   = n;
      search_r_min = *std::min_element(radii.begin(), radii.end());
      search_r_max = *std::max_element(radii.begin(), radii.end());

      search_ids.assign(ids.begin(), ids.end());
      index_of_id.clear();
      sorted_ids.clear();
      if (!ids.empty())
      {
        const std::uint64_t max_id = *std::max_element(ids.begin(), ids.end());
        if (max_id < 16 * std::uint64_t(n) + 1024)
        {
          index_of_id.assign(max_id + 1, none);
          for (unsigned int i = 0; i < n; ++i)
            index_of_id[ids[i]] = i;
        }
        else
        {
          sorted_ids.resize(n);
          for (unsigned int i = 0; i < n; ++i)
            sorted_ids[i] = {ids[i], i};
          std::sort(sorted_ids.begin(), sorted_ids.end());
        }
      }
      search_of_now.resize(n);
      now_of_search.resize(n);
      for (unsigned int i = 0; i < n; ++i)
        search_of_now[i] = now_of_search[i] = i;
    }


    template <int dim>
    bool
    NeighbourList<dim>::still_valid(const std::vector<Point<dim>>    &positions,
                                    const std::vector<double>        &radii,
                                    const std::vector<std::uint64_t> &ids,
                                    const double alert_distance)
    {
      const unsigned int n        = positions.size();
      const unsigned int n_search = search_position.size();
      if (searches == 0 || alert_distance > search_reach)
        return false;

      // Each grain's index in the search, none for a newcomer.
      search_of_now.resize(n);
      newcomers.clear();
      if (ids.empty() ||
          (ids.size() == search_ids.size() &&
           std::equal(ids.begin(), ids.end(), search_ids.begin())))
      {
        if (n != n_search)
          return false;
        for (unsigned int i = 0; i < n; ++i)
          search_of_now[i] = i;
      }
      else
        for (unsigned int i = 0; i < n; ++i)
        {
          unsigned int k = none;
          if (!index_of_id.empty())
          {
            if (ids[i] < index_of_id.size())
              k = index_of_id[ids[i]];
          }
          else
          {
            const auto it = std::lower_bound(sorted_ids.begin(),
                                             sorted_ids.end(),
                                             std::make_pair(ids[i], 0u));
            if (it != sorted_ids.end() && it->first == ids[i])
              k = it->second;
          }
          search_of_now[i] = k;
          if (k == none)
            newcomers.push_back(i);
        }
      // With grains gone or come BucketGrid would choose its large grains
      // from another population, and a pair's search side (the order in
      // which the radii are subtracted) could change: only where no grain
      // can be large, i.e. all radii lie within a factor 2. Newcomers (on
      // several ranks, copies of grains that came near the rank's
      // boundary) join the list while they are few.
      if (n != n_search || !newcomers.empty())
      {
        double r_min = search_r_min, r_max = search_r_max;
        for (const unsigned int i : newcomers)
        {
          r_min = std::min(r_min, radii[i]);
          r_max = std::max(r_max, radii[i]);
        }
        if (r_max > 2 * r_min)
          return false;
        if (!newcomers.empty() &&
            (index_of_id.empty() ||
             n_search + newcomers.size() >
               n_searched + std::max(64u, n_searched / 8)))
          return false;
      }

      now_of_search.assign(n_search, none);
      displacement.resize(n);
      Tensor<1, dim> low, high;
      bool           first = true;
      for (unsigned int i = 0; i < n; ++i)
      {
        const unsigned int k = search_of_now[i];
        if (k == none)
          continue;
        if (radii[i] != search_radius[k] || now_of_search[k] != none)
          return false;
        now_of_search[k]  = i;
        Tensor<1, dim> dx = positions[i] - search_position[k];
        for (unsigned int a = 0; a < dim; ++a)
        {
          if (periodic[a])
            dx[a] -= extent[a] * std::round(dx[a] / extent[a]);
          if (!(std::abs(dx[a]) <= std::numeric_limits<double>::max()))
            return false; // NaN or infinite
          low[a]  = first ? dx[a] : std::min(low[a], dx[a]);
          high[a] = first ? dx[a] : std::max(high[a], dx[a]);
        }
        first           = false;
        displacement[i] = dx;
      }
      // A pair's distance changes by the difference of its grains'
      // displacements, which a common translation u leaves alone: the two
      // largest |dx - u| bound it. u halfway between the extremes on each
      // axis: a cloud or a suspension that settles as a whole keeps its
      // list for as long as its grains keep their relative places.
      const Tensor<1, dim> common  = 0.5 * (low + high);
      double               largest = 0, second = 0;
      for (unsigned int i = 0; i < n; ++i)
      {
        if (search_of_now[i] == none)
          continue;
        const double s = (displacement[i] - common).norm();
        if (s > largest)
        {
          second  = largest;
          largest = s;
        }
        else if (s > second)
          second = s;
      }
      // A pair left out of the candidates was at least search_reach apart
      // (surface to surface) and has closed by at most the two largest
      // displacements. The margin covers the rounding of the distances.
      const double margin = 1e-9 * search_reach;
      if (largest + second > (search_reach - alert_distance) - margin)
        return false;

      // A newcomer takes the place it would have at the search had it moved
      // with the common translation since, and its candidates are the
      // grains now closer than search_reach plus the largest displacement:
      // a pair left out then closes by at most the newcomer's displacement
      // from now on, the partner's from now on and the partner's up to now,
      // which the test above bounds as for any other pair.
      const double reach = search_reach + largest + margin;
      for (const unsigned int i : newcomers)
      {
        const unsigned int k = search_position.size();
        if (ids[i] >= index_of_id.size())
        {
          if (ids[i] >= 16 * std::uint64_t(n) + 1024)
            return false;
          index_of_id.resize(ids[i] + 1, none);
        }
        if (index_of_id[ids[i]] != none && index_of_id[ids[i]] >= n_searched)
          return false; // the same id twice among the newcomers
        index_of_id[ids[i]] = k;
        search_ids.push_back(ids[i]);
        search_position.push_back(positions[i] - common);
        search_radius.push_back(radii[i]);
        search_large.push_back(0);
        search_r_min     = std::min(search_r_min, radii[i]);
        search_r_max     = std::max(search_r_max, radii[i]);
        search_of_now[i] = k;
        now_of_search.push_back(i);
        displacement[i] = common;

        // Partners among the searched grains, from where they were then:
        // each is now within the largest displacement of that place moved
        // by the common translation.
        grid.grains_near(positions[i] - common,
                         reach + radii[i] + search_r_max + largest,
                         nearby);
        // And among the newcomers so far, this call's included.
        for (unsigned int m = n_searched; m < k; ++m)
          nearby.push_back(m);
        for (const unsigned int m : nearby)
        {
          const unsigned int j = now_of_search[m];
          if (j == none || j == i)
            continue;
          Tensor<1, dim> d = positions[j] - positions[i];
          for (unsigned int a = 0; a < dim; ++a)
            if (periodic[a])
              d[a] -= extent[a] * std::round(d[a] / extent[a]);
          if (d.norm() - radii[i] - radii[j] < reach)
            candidates.push_back({std::min(k, m), std::max(k, m)});
        }
      }
      return true;
    }


    template <int dim>
    void
    NeighbourList<dim>::find_pairs(const std::vector<Point<dim>>    &positions,
                                   const std::vector<double>        &radii,
                                   const std::vector<std::uint64_t> &ids,
                                   const double                 alert_distance,
                                   std::vector<GrainPair<dim>> &pairs)
    {
      AssertThrow(radii.size() == positions.size() &&
                    (ids.empty() || ids.size() == positions.size()),
                  dealii::ExcMessage(
                    "NeighbourList: one radius and one id per position are "
                    "needed."));
      AssertThrow(alert_distance >= 0,
                  dealii::ExcMessage(
                    "NeighbourList: the alert distance must not be "
                    "negative."));
      ++calls;
      pairs.clear();
      const unsigned int n = positions.size();
      if (n == 0)
        return;

      if (!still_valid(positions, radii, ids, alert_distance))
      {
        const auto [r_min, r_max] =
          std::minmax_element(radii.begin(), radii.end());
        double skin = skin_factor * 2 * *r_min;
        // BucketGrid needs a periodic axis twice the reach of its search.
        for (unsigned int a = 0; a < dim; ++a)
          if (periodic[a])
            skin = std::min(skin,
                            0.999 * (0.5 * extent[a] -
                                     (2 * *r_max + alert_distance)));
        search(positions, radii, ids, alert_distance, std::max(skin, 0.));
      }

      // Centres wrapped into the box as BucketGrid wraps them.
      wrap_count.resize(n);
      wrapped.resize(n);
      for (unsigned int i = 0; i < n; ++i)
        for (unsigned int d = 0; d < dim; ++d)
        {
          int c = 0;
          if (periodic[d])
            c = static_cast<int>(
              std::floor((positions[i][d] - lower[d]) / extent[d]));
          wrap_count[i][d] = c;
          wrapped[i][d]    = positions[i][d] - c * extent[d];
        }

      bool in_order = true;
      for (const Candidate &c : candidates)
      {
        const unsigned int a = now_of_search[c.first],
                           b = now_of_search[c.second];
        if (a == none || b == none)
          continue;
        // The grain that searches in BucketGrid: the one of lower index,
        // unless the other is large and it is not.
        const unsigned int lo = std::min(a, b), hi = std::max(a, b);
        const bool         large_lo = search_large[search_of_now[lo]],
                   large_hi         = search_large[search_of_now[hi]];
        const unsigned int i        = (large_hi && !large_lo) ? hi : lo;
        const unsigned int j        = i == lo ? hi : lo;
        GrainPair<dim>     pair;
        if (!evaluate_pair<dim>(i,
                                j,
                                wrapped[i],
                                wrapped[j],
                                radii[i],
                                radii[j],
                                wrap_count[i],
                                wrap_count[j],
                                alert_distance,
                                periodic,
                                any_periodic,
                                extent,
                                pair))
          continue;
        if (!pairs.empty())
        {
          const auto &last = pairs.back();
          in_order &= last.first < pair.first ||
                      (last.first == pair.first && last.second < pair.second);
        }
        pairs.push_back(pair);
      }
      if (!in_order)
        std::sort(pairs.begin(),
                  pairs.end(),
                  [](const GrainPair<dim> &p, const GrainPair<dim> &q) {
                    return p.first < q.first ||
                           (p.first == q.first && p.second < q.second);
                  });
    }


    template class NeighbourList<2>;
    template class NeighbourList<3>;
  } // namespace Contact
} // namespace ImmersedGrains
