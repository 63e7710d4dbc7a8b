// The bucket grid against a brute-force O(N^2) search with the nearest
// periodic image: random polydisperse grains (some outside the box on
// non-periodic axes), in 2D and 3D, with no, some and all axes periodic,
// including periodic axes only two or three buckets long, and grains of
// size ratio 10 (a few large among many small, the large scanning the
// buckets of the small). Every pair, gap,
// normal and shift must agree (to 1e-12 of the radius), and the list must be
// sorted by (i, j). Also the walls of a box against their definition.

#include <immersed_grains/contact/bucket_grid.h>
#include <immersed_grains/contact/walls.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

using namespace ImmersedGrains::Contact;
using dealii::Point;
using dealii::Tensor;

namespace
{
  // std::mt19937 is specified exactly; the distributions are not, so the
  // uniform numbers are made here to keep the output the same everywhere.
  std::mt19937 random_engine(7);

  double
  uniform(const double a, const double b)
  {
    return a + (b - a) * (random_engine() / 4294967296.);
  }

  bool all_ok = true;

  template <int dim>
  void
  compare(const std::array<bool, dim> &periodic,
          const unsigned int           n,
          const double                 box_length,
          const double                 large_share = 0)
  {
    Point<dim> lower, upper;
    for (unsigned int d = 0; d < dim; ++d)
      upper[d] = box_length;
    std::vector<Point<dim>> x(n);
    std::vector<double>     r(n);
    for (unsigned int i = 0; i < n; ++i)
    {
      // Without large_share: radii within a factor 2. With it: that share
      // of grains ten times larger than the rest, which scan the small
      // grains' buckets within their reach.
      r[i] = large_share == 0            ? uniform(0.5, 1.0) :
             uniform(0, 1) < large_share ? uniform(1.0, 1.5) :
                                           uniform(0.1, 0.15);
      for (unsigned int d = 0; d < dim; ++d)
        // Periodic axes: anywhere, even several periods away. Others: some
        // grains a little outside the box.
        x[i][d] = (periodic[d] ? uniform(-2 * box_length, 3 * box_length) :
                                 uniform(-0.5, box_length + 0.5));
    }
    const double alert = 0.3;

    BucketGrid<dim>             grid(lower, upper, periodic);
    std::vector<GrainPair<dim>> pairs;
    grid.find_pairs(x, r, alert, pairs);

    std::vector<GrainPair<dim>> expected;
    for (unsigned int i = 0; i < n; ++i)
      for (unsigned int j = i + 1; j < n; ++j)
      {
        Tensor<1, dim> d = x[j] - x[i], shift;
        for (unsigned int a = 0; a < dim; ++a)
          if (periodic[a])
          {
            shift[a] = -box_length * std::round(d[a] / box_length);
            d[a] += shift[a];
          }
        const double gap = d.norm() - r[i] - r[j];
        if (gap < alert)
          expected.push_back({i, j, d / d.norm(), gap, shift});
      }

    bool same = (pairs.size() == expected.size());
    for (unsigned int p = 0; same && p < pairs.size(); ++p)
      same = pairs[p].first == expected[p].first &&
             pairs[p].second == expected[p].second &&
             std::abs(pairs[p].gap - expected[p].gap) < 1e-12 &&
             (pairs[p].normal - expected[p].normal).norm() < 1e-12 &&
             (pairs[p].shift - expected[p].shift).norm() < 1e-12;

    std::printf("%dD periodic (", dim);
    for (unsigned int d = 0; d < dim; ++d)
      std::printf("%s%d", d > 0 ? "," : "", int(periodic[d]));
    std::printf(") buckets (");
    for (unsigned int d = 0; d < dim; ++d)
      std::printf("%s%u", d > 0 ? "," : "", grid.n_buckets()[d]);
    std::printf("): %zu pairs, brute force %zu, identical: %s\n",
                pairs.size(),
                expected.size(),
                same ? "yes" : "no");
    all_ok = all_ok && same;
  }

  template <int dim>
  void
  box_walls()
  {
    Point<dim> lower, upper;
    for (unsigned int d = 0; d < dim; ++d)
    {
      lower[d] = -1;
      upper[d] = 2 + d;
    }
    std::array<bool, 2 * dim> faces;
    faces.fill(true);
    faces[1] = false; // no wall on the upper x face
    Walls<dim> walls;
    const auto numbers = walls.add_box(lower, upper, faces);

    std::vector<Point<dim>> x(200);
    std::vector<double>     r(200);
    for (unsigned int i = 0; i < x.size(); ++i)
    {
      r[i] = uniform(0.1, 0.3);
      for (unsigned int d = 0; d < dim; ++d)
        x[i][d] = uniform(lower[d] - 0.2, upper[d] + 0.2);
    }
    std::vector<WallContact<dim>> contacts;
    walls.find_contacts(x, r, 0.05, contacts);

    // Expected: distance to each face that is a wall, in (grain, wall)
    // order.
    unsigned int n_expected = 0;
    bool         same = (numbers[1] == dealii::numbers::invalid_unsigned_int);
    for (unsigned int i = 0; i < x.size(); ++i)
      for (unsigned int w = 0; w < walls.n_walls(); ++w)
      {
        unsigned int face = 0;
        while (numbers[face] != w)
          ++face;
        const unsigned int axis = face / 2;
        const double       gap  = (face % 2 == 0 ? x[i][axis] - lower[axis] :
                                                   upper[axis] - x[i][axis]) -
                           r[i];
        if (gap >= 0.05)
          continue;
        Tensor<1, dim> normal;
        normal[axis] = (face % 2 == 0 ? -1 : 1);
        same         = same && n_expected < contacts.size() &&
               contacts[n_expected].grain == i &&
               contacts[n_expected].wall == w &&
               std::abs(contacts[n_expected].gap - gap) < 1e-14 &&
               (contacts[n_expected].normal - normal).norm() < 1e-14;
        ++n_expected;
      }
    same = same && (n_expected == contacts.size());
    std::printf("%dD box walls: %zu contacts, expected %u, identical: %s\n",
                dim,
                contacts.size(),
                n_expected,
                same ? "yes" : "no");
    all_ok = all_ok && same;
  }
} // namespace

int
main()
{
  compare<2>({{false, false}}, 400, 20);
  compare<2>({{true, false}}, 400, 20);
  compare<2>({{true, true}}, 400, 20);
  compare<2>({{true, true}}, 10, 5.2); // periodic axes of two buckets
  compare<3>({{false, false, false}}, 600, 12);
  compare<3>({{true, false, true}}, 600, 12);
  compare<3>({{true, true, true}}, 600, 12);
  compare<3>({{true, true, true}}, 20, 7.5); // three buckets per axis
  box_walls<2>();
  box_walls<3>();
  // Size ratio 10: 2 % of the grains large among small ones.
  compare<2>({{false, false}}, 4000, 20, 0.02);
  compare<2>({{true, true}}, 4000, 20, 0.02);
  compare<3>({{false, false, false}}, 6000, 12, 0.02);
  compare<3>({{true, false, true}}, 6000, 12, 0.02);
  std::printf("%s\n", all_ok ? "OK" : "FAILED");
  return all_ok ? 0 : 1;
}
