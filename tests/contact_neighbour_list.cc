// The neighbour list kept over calls against a new bucket-grid search at
// every call: random grains (radii within a factor 2, and a share ten
// times larger) in 2D and 3D boxes with no, some and all axes periodic move
// for 300 calls by random steps of up to a fiftieth of the smallest radius,
// wrap on the periodic axes, change order (grains swapped, as the
// ParticleHandler reorders them when they cross cells), leave, come
// back, appear with new ids and go for good (as copies of other ranks'
// grains near a rank's boundary do), and jump by a diameter now and then;
// the alert distance varies.
// Every call's pairs must equal the search's bit for bit (indices, normal,
// gap, shift, order), and the list must be reused: fewer searches than a
// tenth of the calls (a third among ten times larger grains, where a grain
// that comes or goes brings a search).

#include <immersed_grains/contact/bucket_grid.h>
#include <immersed_grains/contact/neighbour_list.h>

#include <cstdio>
#include <cstring>
#include <random>
#include <vector>

using namespace ImmersedGrains::Contact;
using dealii::Point;
using dealii::Tensor;

namespace
{
  // std::mt19937 is specified exactly; the distributions are not.
  std::mt19937 random_engine(11);

  double
  uniform(const double a, const double b)
  {
    return a + (b - a) * (random_engine() / 4294967296.);
  }

  unsigned int
  below(const unsigned int n)
  {
    return random_engine() % n;
  }

  template <int dim>
  bool
  same(const GrainPair<dim> &p, const GrainPair<dim> &q)
  {
    if (p.first != q.first || p.second != q.second)
      return false;
    return std::memcmp(&p.gap, &q.gap, sizeof(double)) == 0 &&
           std::memcmp(&p.normal, &q.normal, sizeof(p.normal)) == 0 &&
           std::memcmp(&p.shift, &q.shift, sizeof(p.shift)) == 0;
  }

  bool all_ok = true;

  template <int dim>
  void
  follow(const std::array<bool, dim> &periodic,
         const unsigned int           n,
         const double                 box_length,
         const double                 large_share = 0)
  {
    Point<dim> lower, upper;
    for (unsigned int d = 0; d < dim; ++d)
      upper[d] = box_length;
    std::vector<Point<dim>>    x(n);
    std::vector<double>        r(n);
    std::vector<std::uint64_t> id(n);
    for (unsigned int i = 0; i < n; ++i)
    {
      r[i]  = large_share == 0            ? uniform(0.5, 1.0) :
              uniform(0, 1) < large_share ? uniform(1.0, 1.5) :
                                            uniform(0.1, 0.15);
      id[i] = 3 * i + 5; // ids are names, not indices
      for (unsigned int d = 0; d < dim; ++d)
        x[i][d] = uniform(0, box_length);
    }
    std::uint64_t next_id = 3 * n + 5;
    const double  step    = 0.01 * (large_share == 0 ? 0.5 : 0.1);

    NeighbourList<dim>          list(lower, upper, periodic);
    BucketGrid<dim>             grid(lower, upper, periodic);
    std::vector<GrainPair<dim>> pairs, expected;
    // A grain taken out, with its id, radius and place.
    std::vector<std::uint64_t> out_id;
    std::vector<double>        out_r;
    std::vector<Point<dim>>    out_x;
    bool                       identical = true;
    std::size_t                n_pairs   = 0;
    const unsigned int         n_calls   = 300;
    for (unsigned int call = 0; call < n_calls; ++call)
    {
      for (unsigned int i = 0; i < x.size(); ++i)
        for (unsigned int d = 0; d < dim; ++d)
        {
          x[i][d] += uniform(-step, step);
          if (periodic[d] && (x[i][d] < 0 || x[i][d] >= box_length))
            x[i][d] -= box_length * std::floor(x[i][d] / box_length);
        }
      // A few neighbours in the order swap places.
      for (unsigned int k = 0; k < 3; ++k)
      {
        const unsigned int i = below(x.size() - 1);
        std::swap(x[i], x[i + 1]);
        std::swap(r[i], r[i + 1]);
        std::swap(id[i], id[i + 1]);
      }
      if (call % 40 == 17) // a grain leaves
      {
        const unsigned int i = below(x.size());
        out_id.push_back(id[i]);
        out_r.push_back(r[i]);
        out_x.push_back(x[i]);
        x.erase(x.begin() + i);
        r.erase(r.begin() + i);
        id.erase(id.begin() + i);
      }
      if (call % 40 == 37 && !out_id.empty()) // and comes back
      {
        const unsigned int i = below(x.size());
        x.insert(x.begin() + i, out_x.back());
        r.insert(r.begin() + i, out_r.back());
        id.insert(id.begin() + i, out_id.back());
        out_x.pop_back();
        out_r.pop_back();
        out_id.pop_back();
      }
      if (large_share == 0 && call % 7 == 3) // a grain never seen, as a
      // copy from another rank
      {
        const unsigned int i = below(x.size());
        Point<dim>         y;
        for (unsigned int d = 0; d < dim; ++d) // some outside the box
          y[d] =
            periodic[d] ? uniform(0, box_length) : uniform(-1, box_length + 1);
        x.insert(x.begin() + i, y);
        r.insert(r.begin() + i, r[(i + 1) % r.size()]);
        id.insert(id.begin() + i, next_id++);
      }
      if (large_share == 0 && call % 7 == 5) // and one goes for good
      {
        const unsigned int i = below(x.size());
        x.erase(x.begin() + i);
        r.erase(r.begin() + i);
        id.erase(id.begin() + i);
      }
      if (call % 97 == 50) // one grain jumps by a diameter
        x[below(x.size())][0] += 2 * r[0];
      const double alert = uniform(0.04, 0.05) * (large_share == 0 ? 1 : 0.2);

      list.find_pairs(x, r, id, alert, pairs);
      grid.find_pairs(x, r, alert, expected);
      bool ok = pairs.size() == expected.size();
      for (std::size_t p = 0; ok && p < pairs.size(); ++p)
        ok = same(pairs[p], expected[p]);
      identical = identical && ok;
      n_pairs += expected.size();
    }
    // Newcomers join the list; a grain that leaves or comes back among ten
    // times larger ones, or jumps, brings a search.
    const unsigned int share  = large_share == 0 ? 10 : 3;
    const bool         reused = list.n_searches() * share < list.n_calls();

    std::printf("%dD periodic (", dim);
    for (unsigned int d = 0; d < dim; ++d)
      std::printf("%s%d", d > 0 ? "," : "", int(periodic[d]));
    std::printf("), %u grains%s: %u calls, %s pairs, identical: %s, "
                "searches fewer than 1/%u of the calls: %s\n",
                n,
                large_share > 0 ? " (2 % ten times larger)" : "",
                n_calls,
                n_pairs > 100 * n_calls ? "over 100 per call" : "FEW",
                identical ? "yes" : "no",
                share,
                reused ? "yes" : "no");
    all_ok = all_ok && identical && reused;
  }
} // namespace

int
main()
{
  follow<2>({{false, false}}, 400, 20);
  follow<2>({{true, false}}, 400, 20);
  follow<2>({{true, true}}, 400, 20);
  follow<3>({{false, false, false}}, 600, 12);
  follow<3>({{true, false, true}}, 600, 12);
  follow<3>({{true, true, true}}, 600, 12);
  follow<2>({{true, true}}, 4000, 20, 0.02);
  follow<3>({{false, false, false}}, 6000, 12, 0.02);
  std::printf("%s\n", all_ok ? "OK" : "FAILED");
  return all_ok ? 0 : 1;
}
