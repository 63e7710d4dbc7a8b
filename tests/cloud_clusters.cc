// The clusters of the cloud analysis (label_clusters) on point sets whose
// answer is known by construction, in 2D and 3D:
// - two dense blobs (random points at a mean spacing of about half the link
//   distance) joined by a filament of points in single file: one cluster
//   when every linked pair joins (no core condition), two with the
//   default core condition (4 neighbours), the filament's points attached
//   to a blob or alone;
// - one blob with loose points far away: the loose points are alone;
// - the same partition after a shuffle of the points (only a point linked
//   to the core points of two clusters could go either way, DBSCAN's one
//   order dependence; the cloud analysis orders grains by index);
// - one point, and points all farther apart than the link distance.

#include <immersed_grains/grains/cloud_analysis.h>

#include <algorithm>
#include <cstdio>
#include <map>
#include <random>
#include <set>
#include <vector>

using dealii::Point;
using ImmersedGrains::label_clusters;

namespace
{
  std::mt19937 random_engine(3);

  double
  uniform(const double a, const double b)
  {
    return a + (b - a) * (random_engine() / 4294967296.);
  }

  // n points uniformly in the ball of radius R around c (rejection).
  template <int dim>
  void
  add_blob(std::vector<Point<dim>> &points,
           const Point<dim>        &c,
           const double             R,
           const unsigned int       n)
  {
    for (unsigned int k = 0; k < n;)
    {
      Point<dim> p;
      for (unsigned int d = 0; d < dim; ++d)
        p[d] = uniform(-R, R);
      if (p.norm() <= R)
      {
        points.push_back(c + p);
        ++k;
      }
    }
  }

  // Sizes of the clusters, largest first.
  std::vector<unsigned int>
  sizes(const std::vector<unsigned int> &label)
  {
    std::map<unsigned int, unsigned int> count;
    for (const unsigned int l : label)
      ++count[l];
    std::vector<unsigned int> s;
    for (const auto &[l, n] : count)
      s.push_back(n);
    std::sort(s.rbegin(), s.rend());
    return s;
  }

  // Whether two labellings make the same partition.
  bool
  same_partition(const std::vector<unsigned int> &a,
                 const std::vector<unsigned int> &b)
  {
    std::map<unsigned int, unsigned int> ab, ba;
    for (unsigned int i = 0; i < a.size(); ++i)
      if (ab.emplace(a[i], b[i]).first->second != b[i] ||
          ba.emplace(b[i], a[i]).first->second != a[i])
        return false;
    return true;
  }


  template <int dim>
  void
  check()
  {
    const double link = 1; // the link distance
    // A blob of radius 4 whose mean spacing is about link/2.
    const double       R = 4;
    const unsigned int n =
      dim == 2 ? 4 * 16 * 4 : 8 * 64 * 4 / 2; // points per blob
    std::vector<Point<dim>> points;
    Point<dim>              left, right;
    left[0]  = -6;
    right[0] = 6;
    add_blob(points, left, R, n);
    add_blob(points, right, R, n);
    // The filament: single file along x from one blob to the other, 0.8
    // apart (each point has two neighbours within the link distance).
    for (double x = -2; x <= 2; x += 0.8)
    {
      Point<dim> p;
      p[0] = x;
      points.push_back(p);
    }
    const unsigned int n_filament = points.size() - 2 * n;

    const auto joined = sizes(label_clusters(points, link, 0));
    std::printf("%dD: two blobs of %u and a filament of %u, no core "
                "condition: %zu cluster(s), the largest %u\n",
                dim,
                n,
                n_filament,
                joined.size(),
                joined[0]);
    const auto   split    = sizes(label_clusters(points, link, 4));
    unsigned int in_blobs = split.size() > 1 ? split[0] + split[1] : 0;
    std::printf("%dD: with 4 core neighbours: the two largest hold %u of "
                "the %u points (at least %u: %s), the third largest %u\n",
                dim,
                in_blobs,
                static_cast<unsigned int>(points.size()),
                2 * n,
                in_blobs >= 2 * n && split[0] <= n + n_filament ? "yes" : "no",
                split.size() > 2 ? split[2] : 0u);

    // Order independence.
    const auto                label = label_clusters(points, link, 4);
    std::vector<unsigned int> order(points.size());
    for (unsigned int i = 0; i < order.size(); ++i)
      order[i] = i;
    std::shuffle(order.begin(), order.end(), random_engine);
    std::vector<Point<dim>> shuffled;
    for (const unsigned int i : order)
      shuffled.push_back(points[i]);
    const auto                relabel = label_clusters(shuffled, link, 4);
    std::vector<unsigned int> back(points.size());
    for (unsigned int k = 0; k < order.size(); ++k)
      back[order[k]] = relabel[k];
    std::printf("%dD: the same partition after a shuffle: %s\n",
                dim,
                same_partition(label, back) ? "yes" : "no");

    // One blob and five loose points far from it and from each other.
    std::vector<Point<dim>> cloud;
    add_blob(cloud, Point<dim>(), R, n);
    for (unsigned int k = 0; k < 5; ++k)
    {
      Point<dim> p;
      p[dim - 1] = 10 + 3. * k;
      cloud.push_back(p);
    }
    const auto loose = sizes(label_clusters(cloud, link, 4));
    std::printf("%dD: a blob and 5 loose points: %zu clusters, the largest "
                "%u, the others of one point: %s\n",
                dim,
                loose.size(),
                loose[0],
                loose.size() == 6 && loose[1] == 1 ? "yes" : "no");

    // Degenerate sets.
    std::vector<Point<dim>> one(1);
    std::vector<Point<dim>> apart;
    for (unsigned int k = 0; k < 4; ++k)
    {
      Point<dim> p;
      p[0] = 1.5 * k;
      apart.push_back(p);
    }
    std::printf("%dD: one point: %zu cluster; four points 1.5 apart: %zu "
                "clusters (0 core neighbours), %zu (4)\n",
                dim,
                sizes(label_clusters(one, link, 4)).size(),
                sizes(label_clusters(apart, link, 0)).size(),
                sizes(label_clusters(apart, link, 4)).size());
  }
} // namespace

int
main()
{
  check<2>();
  check<3>();
}
