// The neighbour search (BucketGrid) with grains of several sizes: the time
// per grain of find_pairs() for random grains at solid fraction 0.3 in a
// cube (3D) or square (2D), against the same count of equal grains.
//
// Distributions: equal radii r; two sizes r and 10 r in equal volume
// shares (one large grain per 1000 small ones, which the grid must not
// size its buckets for); a lognormal of geometric deviation 1.5 truncated
// at three deviations (radii over a factor 11). Grains may overlap (the
// search does not care), which keeps the set-up O(N).
//
// Usage: neighbour_search_sizes [dim] [N ...]   (default 3, N = 1e4 1e5)
// Reports per distribution: the buckets per axis, the pairs found, and the
// nanoseconds per grain of find_pairs (the best of 5 calls).

#include <immersed_grains/contact/bucket_grid.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

using namespace ImmersedGrains::Contact;
using dealii::Point;

namespace
{
  template <int dim>
  void
  measure(const std::string &name, std::vector<double> radii)
  {
    std::mt19937_64                        engine(5);
    std::uniform_real_distribution<double> unit(0., 1.);
    std::shuffle(radii.begin(), radii.end(), engine);
    double volume = 0;
    for (const double r : radii)
      volume += dim == 2 ? M_PI * r * r : 4. / 3. * M_PI * r * r * r;
    const double side = std::pow(volume / 0.3, 1. / dim);
    Point<dim>   lower, upper;
    for (unsigned int d = 0; d < dim; ++d)
      upper[d] = side;
    std::vector<Point<dim>> x(radii.size());
    for (auto &p : x)
      for (unsigned int d = 0; d < dim; ++d)
        p[d] = side * unit(engine);
    // Grains in spatial order, as the ParticleHandler gives them.
    std::sort(x.begin(),
              x.end(),
              [&](const Point<dim> &a, const Point<dim> &b)
              { return a[dim - 1] < b[dim - 1]; });
    const double    alert = 0.1 * *std::min_element(radii.begin(), radii.end());
    BucketGrid<dim> grid(lower, upper);
    std::vector<GrainPair<dim>> pairs;
    double                      best = 1e300;
    for (unsigned int k = 0; k < 5; ++k)
    {
      const auto start = std::chrono::steady_clock::now();
      grid.find_pairs(x, radii, alert, pairs);
      best = std::min(best,
                      std::chrono::duration<double>(
                        std::chrono::steady_clock::now() - start)
                        .count());
    }
    std::printf("%-28s N = %8zu  buckets %4u per axis  pairs %9zu  %7.1f ns "
                "per grain\n",
                name.c_str(),
                radii.size(),
                grid.n_buckets()[0],
                pairs.size(),
                best / radii.size() * 1e9);
  }

  template <int dim>
  void
  run(const unsigned int n)
  {
    const double r = 1e-3;
    measure<dim>("equal", std::vector<double>(n, r));
    // Equal volume shares of r and 10 r: (10)^dim small grains per large.
    const unsigned int  per_large = std::pow(10, dim);
    std::vector<double> two;
    for (unsigned int i = 0; i < n; ++i)
      two.push_back(i % (per_large + 1) == 0 ? 10 * r : r);
    measure<dim>("two sizes, ratio 10", two);
    std::mt19937_64                  engine(3);
    std::normal_distribution<double> normal(0., 1.);
    std::vector<double>              lognormal;
    while (lognormal.size() < n)
    {
      const double z = normal(engine);
      if (std::abs(z) <= 3)
        lognormal.push_back(r * std::exp(std::log(1.5) * z));
    }
    measure<dim>("lognormal, deviation 1.5", lognormal);
  }
} // namespace

int
main(int argc, char **argv)
{
  int                       dim = 3;
  std::vector<unsigned int> sizes;
  for (int a = 1; a < argc; ++a)
  {
    const int value = std::atoi(argv[a]);
    if (a == 1 && (value == 2 || value == 3))
      dim = value;
    else if (value > 0)
      sizes.push_back(value);
  }
  if (sizes.empty())
    sizes = {10000, 100000};
  for (const unsigned int n : sizes)
    dim == 2 ? run<2>(n) : run<3>(n);
}
