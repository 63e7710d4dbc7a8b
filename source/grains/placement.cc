#include <deal.II/base/utilities.h>

#include <immersed_grains/contact/bucket_grid.h>
#include <immersed_grains/grains/periodic_span.h>
#include <immersed_grains/grains/placement.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <random>
#include <sstream>

namespace ImmersedGrains
{
  namespace
  {
    using dealii::Point;
    using dealii::Tensor;

    // std::mt19937_64 is fully specified by the standard, the library's
    // distributions are not: draw through these so that a seed gives the
    // same grains with any compiler.
    struct Random
    {
      std::mt19937_64 engine;

      double
      uniform()
      {
        return (engine() >> 11) * 0x1.0p-53;
      }

      double
      uniform(const double a, const double b)
      {
        return a + (b - a) * uniform();
      }

      double
      normal(const double mean, const double deviation)
      {
        // Box-Muller; 1 - u keeps the logarithm finite.
        const double u = 1 - uniform(), v = uniform();
        return mean +
               deviation * std::sqrt(-2 * std::log(u)) * std::cos(2 * M_PI * v);
      }
    };

    template <int dim>
    std::string
    to_text(const Point<dim> &p)
    {
      std::ostringstream s;
      s << '(' << p << ')';
      return s.str();
    }

    // Each class's share of the grains' number: its volume fraction over
    // its grain's volume, normalised.
    template <int dim>
    std::vector<double>
    class_number_shares(const GrainParameters<dim> &prm)
    {
      std::vector<double> shares;
      double              sum = 0;
      for (unsigned int k = 0; k < prm.class_radii.size(); ++k)
      {
        shares.push_back(prm.class_fractions[k] /
                         grain_volume<dim>(prm.class_radii[k]));
        sum += shares.back();
      }
      for (double &s : shares)
        s /= sum;
      return shares;
    }

    template <int dim>
    double
    draw_radius(const GrainParameters<dim> &prm, Random &random)
    {
      switch (prm.radius_distribution)
      {
        case RadiusDistribution::uniform:
          return random.uniform(prm.min_radius, prm.max_radius);
        case RadiusDistribution::normal:
          for (;;)
          {
            const double r = random.normal(prm.radius, prm.radius_deviation);
            if (r >= prm.min_radius && r <= prm.max_radius)
              return r;
          }
        case RadiusDistribution::lognormal:
          for (;;)
          {
            const double r = prm.radius * std::exp(std::log(prm.radius_spread) *
                                                   random.normal(0, 1));
            if (r >= prm.min_radius && r <= prm.max_radius)
              return r;
          }
        case RadiusDistribution::classes:
        {
          // A class drawn with its share of the grains' number.
          const std::vector<double> shares = class_number_shares(prm);
          double                    u      = random.uniform();
          for (unsigned int k = 0; k + 1 < shares.size(); ++k)
            if ((u -= shares[k]) < 0)
              return prm.class_radii[k];
          return prm.class_radii.back();
        }
        default:
          return prm.radius;
      }
    }

    // Each class's exact number of grains: @p total split in proportion
    // to @p weights, the remainders going to the largest fractional parts
    // (the earlier class on a tie).
    std::vector<unsigned int>
    apportion(const unsigned int total, const std::vector<double> &weights)
    {
      double sum = 0;
      for (const double w : weights)
        sum += w;
      std::vector<unsigned int> n(weights.size());
      std::vector<double>       rest(weights.size());
      unsigned int              given = 0;
      for (unsigned int k = 0; k < weights.size(); ++k)
      {
        const double exact = total * weights[k] / sum;
        n[k]               = static_cast<unsigned int>(std::floor(exact));
        rest[k]            = exact - n[k];
        given += n[k];
      }
      std::vector<unsigned int> order(weights.size());
      for (unsigned int k = 0; k < order.size(); ++k)
        order[k] = k;
      std::stable_sort(order.begin(),
                       order.end(),
                       [&](unsigned int a, unsigned int b)
                       { return rest[a] > rest[b]; });
      for (unsigned int k = 0; given < total; ++k, ++given)
        ++n[order[k % order.size()]];
      return n;
    }

    // The classes' radii for a fill: with Solid fraction, each class
    // fills its share of the solid volume (the nearest whole number of
    // grains); with Count, the count is split by the classes' shares of
    // the number.
    template <int dim>
    std::vector<double>
    class_radii_of_fill(const GrainParameters<dim> &prm,
                        const double                region_volume)
    {
      const InputLocation       where{prm.file, "Grains/Placement"};
      std::vector<unsigned int> n;
      where.require(prm.count <= 50'000'000,
                    "Count",
                    prm.count_text,
                    "more than 5e7 grains");
      if (prm.count > 0)
        n = apportion(prm.count, class_number_shares(prm));
      else
        for (unsigned int k = 0; k < prm.class_radii.size(); ++k)
          n.push_back(static_cast<unsigned int>(
            std::min(5e7,
                     std::round(prm.class_fractions[k] * prm.solid_fraction *
                                region_volume /
                                grain_volume<dim>(prm.class_radii[k])))));
      std::vector<double> radii;
      for (unsigned int k = 0; k < n.size(); ++k)
        radii.insert(radii.end(), n[k], prm.class_radii[k]);
      return radii;
    }

    // The radii of a ball or box fill: Radii, Count draws, or draws until
    // the solid fraction of the region is reached.
    template <int dim>
    std::vector<double>
    fill_radii(const GrainParameters<dim> &prm,
               const double                region_volume,
               Random                     &random)
    {
      if (!prm.radii.empty())
        return prm.radii;
      if (prm.radius_distribution == RadiusDistribution::classes)
        return class_radii_of_fill(prm, region_volume);
      std::vector<double> radii;
      if (prm.count > 0)
      {
        // Checked before anything is drawn: the size estimate comes after
        // the placement.
        InputLocation{prm.file, "Grains/Placement"}.require(
          prm.count <= 50'000'000,
          "Count",
          prm.count_text,
          "more than 5e7 grains");
        for (unsigned int k = 0; k < prm.count; ++k)
          radii.push_back(draw_radius(prm, random));
        return radii;
      }
      const InputLocation where{prm.file, "Grains/Placement"};
      double              volume = 0;
      while (volume < prm.solid_fraction * region_volume)
      {
        radii.push_back(draw_radius(prm, random));
        volume += grain_volume<dim>(radii.back());
        where.require(radii.size() < 50'000'000,
                      "Solid fraction",
                      prm.solid_fraction_text,
                      "more than 5e7 grains: check Size and Radius");
      }
      return radii;
    }

    // Pushes overlapping pairs apart, each grain by half the overlap along
    // the line of centres (Gauss-Seidel: moved at once), and grains back
    // inside the region, until no pair overlaps. Returns the rounds it
    // took, or invalid_unsigned_int if 20000 rounds did not suffice.
    template <int dim>
    unsigned int
    remove_overlaps(std::vector<GrainSeed<dim>> &grains,
                    const Point<dim>            &lower,
                    const Point<dim>            &upper,
                    const bool                   ball,
                    const Point<dim>            &center,
                    const double                 ball_radius,
                    const std::array<bool, dim> &wrap)
    {
      const unsigned int n           = grains.size();
      const auto         keep_inside = [&](GrainSeed<dim> &g)
      {
        for (unsigned int d = 0; d < dim; ++d)
          if (wrap[d])
          {
            const double L = upper[d] - lower[d];
            g.position[d] -= L * std::floor((g.position[d] - lower[d]) / L);
            if (g.position[d] >= upper[d])
              g.position[d] = lower[d];
          }
          else
            g.position[d] = std::clamp(g.position[d],
                                       lower[d] + g.radius,
                                       upper[d] - g.radius);
        if (ball)
        {
          const Tensor<1, dim> a     = g.position - center;
          const double         reach = ball_radius - g.radius;
          if (a.norm() > reach)
            g.position = center + a * (reach / a.norm());
        }
      };
      std::vector<Point<dim>>              x(n);
      std::vector<double>                  r(n);
      std::vector<Contact::GrainPair<dim>> pairs;
      Contact::BucketGrid<dim>             grid(lower, upper, wrap);
      for (unsigned int round = 0; round < 20000; ++round)
      {
        for (unsigned int i = 0; i < n; ++i)
        {
          x[i] = grains[i].position;
          r[i] = grains[i].radius;
        }
        grid.find_pairs(x, r, 0, pairs);
        bool moved = false;
        for (const auto &pair : pairs)
        {
          auto          &a       = grains[pair.first];
          auto          &b       = grains[pair.second];
          Tensor<1, dim> ab      = b.position + pair.shift - a.position;
          double         d       = ab.norm();
          const double   overlap = a.radius + b.radius - d;
          if (overlap <= 0)
            continue;
          if (d == 0)
          {
            // Coincident centres: any direction will do.
            ab    = Tensor<1, dim>();
            ab[0] = 1;
            d     = 1;
          }
          // A little more than the overlap (far above round-off in the
          // positions), so that a pair pushed apart stays apart.
          const Tensor<1, dim> push =
            ((overlap + 1e-9 * (a.radius + b.radius)) / (2 * d)) * ab;
          a.position -= push;
          b.position += push;
          keep_inside(a);
          keep_inside(b);
          moved = true;
        }
        if (!moved)
          return round;
      }
      return dealii::numbers::invalid_unsigned_int;
    }

    // Random sequential addition into a ball or box, largest grains first.
    // On the axes where @p wrap is set (a box spanning a periodic axis of
    // the domain) the centres are drawn over the whole period and grains
    // meet their neighbours' periodic images. Drawn a radius clear of the
    // faces, as at a wall, they would leave a layer one radius deep on each
    // side of the periodic face empty: a lighter sheet that drives a
    // box-wide convection through a suspension.
    template <int dim>
    std::vector<GrainSeed<dim>>
    random_fill(const GrainParameters<dim> &prm,
                Random                     &random,
                std::array<bool, dim>       wrap)
    {
      const InputLocation where{prm.file, "Grains/Placement"};
      const bool          ball = (prm.shape == PlacementShape::ball);
      Point<dim>          lower, upper;
      double              region_volume = 1;
      for (unsigned int d = 0; d < dim; ++d)
      {
        const double half = ball ? prm.size[0] : prm.size[d] / 2;
        lower[d]          = prm.center[d] - half;
        upper[d]          = prm.center[d] + half;
        region_volume *= 2 * half;
      }
      if (ball)
        region_volume = grain_volume<dim>(prm.size[0]);

      std::vector<double> radii = fill_radii(prm, region_volume, random);
      std::sort(radii.begin(), radii.end(), std::greater<double>());
      const double r_max = radii.empty() ? 0 : radii.front();
      // A grain then meets at most one image of another (the periodic
      // overlap check after placement asks the same).
      for (unsigned int d = 0; d < dim; ++d)
        wrap[d] = wrap[d] && !ball && upper[d] - lower[d] >= 4 * r_max;
      // A centre's coordinate on axis d for a grain of radius r: within
      // the period [lower, upper) where wrapped, clear of the faces else.
      const auto draw = [&](const unsigned int d, const double r)
      {
        if (!wrap[d])
          return random.uniform(lower[d] + r, upper[d] - r);
        const double y = random.uniform(lower[d], upper[d]);
        return y < upper[d] ? y : lower[d];
      };
      // What the entry that set the number of grains is called.
      const std::string what  = !prm.radii.empty() ? "Radii" :
                                prm.count > 0      ? "Count" :
                                                     "Solid fraction";
      const std::string value = !prm.radii.empty() ? prm.radii_text :
                                prm.count > 0      ? prm.count_text :
                                                     prm.solid_fraction_text;
      for (unsigned int d = 0; d < dim; ++d)
        where.require(upper[d] - lower[d] > 2 * r_max,
                      "Size",
                      prm.size_text,
                      "the region is narrower than the largest grain");
      double total = 0;
      for (const double r : radii)
        total += grain_volume<dim>(r);
      where.require(total < region_volume,
                    what,
                    value,
                    "the grains' volume exceeds the region's");
      // No arrangement of equal grains is denser than the hexagonal
      // (discs) or face-centred cubic (spheres) packing.
      const double densest =
        dim == 2 ? M_PI / (2 * std::sqrt(3.)) : M_PI / (3 * std::sqrt(2.));
      where.require(total < densest * region_volume,
                    what,
                    value,
                    "a solid fraction of " +
                      std::to_string(total / region_volume) +
                      " exceeds the densest packing of equal grains (" +
                      std::to_string(densest) + ")");

      // Hash grid of placed grains, cell edge 2 r_max: overlaps can only be
      // with grains in the 3^dim cells around.
      // At most a few cells per grain: small grains in a large box asked
      // for 10^9 cells (24 GB of empty lists) when only the edge was
      // bounded. Larger cells are only slower.
      const double max_cells = std::max(64., 4. * radii.size());
      std::array<unsigned int, dim> n_cells;
      std::array<double, dim>       wanted;
      double                        wanted_total = 1;
      for (unsigned int d = 0; d < dim; ++d)
      {
        wanted[d] = std::max(
          1., std::min(1e3, std::floor((upper[d] - lower[d]) / (2 * r_max))));
        wanted_total *= wanted[d];
      }
      const double shrink  = wanted_total > max_cells ?
                               std::pow(wanted_total / max_cells, 1. / dim) :
                               1.;
      unsigned int n_total = 1;
      for (unsigned int d = 0; d < dim; ++d)
      {
        n_cells[d] =
          static_cast<unsigned int>(std::max(1., wanted[d] / shrink));
        n_total *= n_cells[d];
      }
      std::vector<std::vector<unsigned int>> cells(n_total);
      const auto cell_of = [&](const Point<dim> &x, std::array<int, dim> &c)
      {
        for (unsigned int d = 0; d < dim; ++d)
          c[d] = std::min<int>(n_cells[d] - 1,
                               std::max(0.,
                                        (x[d] - lower[d]) /
                                          (upper[d] - lower[d]) * n_cells[d]));
      };
      const auto index = [&](const std::array<int, dim> &c)
      {
        unsigned int k = 0;
        for (int d = dim - 1; d >= 0; --d)
          k = k * n_cells[d] + c[d];
        return k;
      };

      std::vector<GrainSeed<dim>> grains;
      grains.reserve(radii.size());
      std::vector<double> unplaced;
      const unsigned int  max_tries = 5000;
      for (const double r : radii)
      {
        bool placed = false;
        for (unsigned int t = 0; t < max_tries && !placed; ++t)
        {
          Point<dim> x;
          for (unsigned int d = 0; d < dim; ++d)
            x[d] = draw(d, r);
          if (ball && (x - prm.center).norm() > prm.size[0] - r)
            continue;
          std::array<int, dim> c;
          cell_of(x, c);
          bool free = true;
          // Visit the 3^dim neighbour cells.
          for (unsigned int k = 0; k < std::pow(3, dim) && free; ++k)
          {
            std::array<int, dim> n      = c;
            unsigned int         q      = k;
            bool                 inside = true;
            for (unsigned int d = 0; d < dim; ++d, q /= 3)
            {
              n[d] += int(q % 3) - 1;
              if (wrap[d])
                n[d] = (n[d] + int(n_cells[d])) % int(n_cells[d]);
              inside = inside && n[d] >= 0 && n[d] < int(n_cells[d]);
            }
            if (!inside)
              continue;
            for (const unsigned int j : cells[index(n)])
            {
              Tensor<1, dim> ab = grains[j].position - x;
              for (unsigned int d = 0; d < dim; ++d)
                if (wrap[d])
                {
                  const double L = upper[d] - lower[d];
                  ab[d] -= L * std::round(ab[d] / L);
                }
              if (ab.norm() < grains[j].radius + r)
              {
                free = false;
                break;
              }
            }
          }
          if (!free)
            continue;
          cells[index(c)].push_back(grains.size());
          grains.push_back({x, Tensor<1, dim>(), r});
          placed = true;
        }
        if (!placed)
          unplaced.push_back(r);
      }
      if (unplaced.empty())
        return grains;

      // Random sequential addition jams well below random close packing:
      // put the rest at random (overlapping) positions and push
      // overlapping pairs apart until none overlaps. The result is still
      // a homogeneous random arrangement (no lattice, no ordering by
      // insertion) up to about 0.5 (spheres) and 0.75 (discs).
      for (const double r : unplaced)
      {
        Point<dim> x;
        do
          for (unsigned int d = 0; d < dim; ++d)
            x[d] = draw(d, r);
        while (ball && (x - prm.center).norm() > prm.size[0] - r);
        grains.push_back({x, Tensor<1, dim>(), r});
      }
      const unsigned int rounds = remove_overlaps<dim>(
        grains, lower, upper, ball, prm.center, prm.size[0], wrap);
      if (rounds == dealii::numbers::invalid_unsigned_int)
        where.fail(what,
                   value,
                   "no arrangement without overlaps found for " +
                     std::to_string(grains.size()) +
                     " grains (solid fraction " +
                     std::to_string(total / region_volume) +
                     "; random close packing is near " +
                     (dim == 2 ? "0.82" : "0.64") +
                     " for equal grains): lower it, enlarge the region or "
                     "use Shape = lattice");
      return grains;
    }

    template <int dim>
    std::vector<GrainSeed<dim>>
    lattice_fill(const GrainParameters<dim> &prm, Random &random)
    {
      const InputLocation where{prm.file, "Grains/Placement"};
      std::vector<double> radii = prm.radii;
      double              r_max = prm.largest_drawn_radius();
      if (!radii.empty())
        r_max = *std::max_element(radii.begin(), radii.end());
      std::array<unsigned int, dim> n;
      unsigned int                  sites = 1;
      for (unsigned int d = 0; d < dim; ++d)
      {
        n[d] = std::floor(prm.size[d] / (2 * r_max) * (1 + 1e-12));
        sites *= n[d];
      }
      where.require(sites > 0,
                    "Size",
                    prm.size_text,
                    "the box is narrower than a grain diameter");
      unsigned int count = !radii.empty() ? radii.size() :
                           prm.count > 0  ? prm.count :
                                            sites;
      where.require(count <= sites,
                    radii.empty() ? "Count" : "Radii",
                    radii.empty() ? prm.count_text : prm.radii_text,
                    "the lattice in the box has only " + std::to_string(sites) +
                      " sites");
      std::vector<GrainSeed<dim>> grains;
      for (unsigned int k = 0; k < count; ++k)
      {
        Point<dim>   x;
        unsigned int q = k;
        for (unsigned int d = 0; d < dim; ++d)
        {
          x[d] =
            prm.center[d] - prm.size[d] / 2 + r_max + 2 * r_max * (q % n[d]);
          q /= n[d];
        }
        const double r = radii.empty() ? draw_radius(prm, random) : radii[k];
        grains.push_back({x, Tensor<1, dim>(), r});
      }
      return grains;
    }

    template <int dim>
    std::vector<GrainSeed<dim>>
    read_file(const GrainParameters<dim> &prm)
    {
      const InputLocation where{prm.file, "Grains/Placement"};
      std::ifstream       in(prm.placement_path);
      where.require(bool(in), "File", prm.placement_file, "cannot open it");
      std::vector<GrainSeed<dim>> grains;
      unsigned int                line_number = 0;
      for (std::string line; std::getline(in, line);)
      {
        ++line_number;
        line = line.substr(0, line.find('#'));
        std::replace(line.begin(), line.end(), ',', ' ');
        std::istringstream  words(line);
        std::vector<double> v;
        std::string         word;
        while (words >> word)
        {
          std::istringstream number(word);
          double             x;
          std::string        rest;
          if (!(number >> x) || (number >> rest))
            where.fail("File",
                       prm.placement_file,
                       "line " + std::to_string(line_number) + ": '" + word +
                         "' is not a number");
          v.push_back(x);
        }
        if (v.empty())
          continue;
        if (v.size() != dim && v.size() != dim + 1 && v.size() != 2 * dim + 1)
          where.fail("File",
                     prm.placement_file,
                     "line " + std::to_string(line_number) + ": expected " +
                       std::to_string(dim) + ", " + std::to_string(dim + 1) +
                       " or " + std::to_string(2 * dim + 1) +
                       " numbers (x[, r[, v]]), got " +
                       std::to_string(v.size()));
        GrainSeed<dim> g{Point<dim>(), Tensor<1, dim>(), prm.radius};
        for (unsigned int d = 0; d < dim; ++d)
          g.position[d] = v[d];
        if (v.size() > dim)
          g.radius = v[dim];
        if (v.size() > dim + 1)
          for (unsigned int d = 0; d < dim; ++d)
            g.velocity[d] = v[dim + 1 + d];
        if (!(g.radius > 0))
          where.fail("File",
                     prm.placement_file,
                     "line " + std::to_string(line_number) +
                       ": the radius must be positive");
        grains.push_back(g);
      }
      where.require(!grains.empty(),
                    "File",
                    prm.placement_file,
                    "holds no grains");
      return grains;
    }

    // Input grains must not overlap (touching is fine): names the first
    // offending pair.
    template <int dim>
    void
    check_overlaps(const std::vector<GrainSeed<dim>> &grains,
                   const Geometry<dim>               &geometry,
                   const double                       allowed_overlap,
                   const InputLocation               &where,
                   const std::string                 &parameter,
                   const std::string                 &value)
    {
      std::vector<Point<dim>> x;
      std::vector<double>     r;
      double                  r_min = 1e300;
      for (const auto &g : grains)
      {
        Point<dim> p = g.position;
        for (unsigned int d = 0; d < dim; ++d)
          p[d] = std::clamp(p[d],
                            geometry.lower_corner[d],
                            geometry.upper_corner[d]);
        x.push_back(p);
        r.push_back(g.radius);
        r_min = std::min(r_min, g.radius);
      }
      // Periodic overlaps are only checked where the axis is long enough
      // for the bucket grid; shorter periodic boxes are rejected later.
      std::array<bool, dim> periodic;
      double                r_max = *std::max_element(r.begin(), r.end());
      for (unsigned int d = 0; d < dim; ++d)
        periodic[d] =
          geometry.is_periodic(d) &&
          geometry.upper_corner[d] - geometry.lower_corner[d] >= 4 * r_max;
      Contact::BucketGrid<dim>             grid(geometry.lower_corner,
                                    geometry.upper_corner,
                                    periodic);
      std::vector<Contact::GrainPair<dim>> pairs;
      grid.find_pairs(x, r, 0, pairs);
      for (const auto &p : pairs)
        if (p.gap < -allowed_overlap * r_min)
          where.fail(parameter,
                     value,
                     "grains " + std::to_string(p.first + 1) + " at " +
                       to_text(grains[p.first].position) + " and " +
                       std::to_string(p.second + 1) + " at " +
                       to_text(grains[p.second].position) + " overlap by " +
                       std::to_string(-p.gap) + " m");
    }

    template <int dim>
    void
    check_inside(const std::vector<GrainSeed<dim>> &grains,
                 const Geometry<dim>               &geometry,
                 const double                       allowed_overlap,
                 const InputLocation               &where,
                 const std::string                 &parameter,
                 const std::string                 &value)
    {
      const auto &lo = geometry.lower_corner;
      const auto &hi = geometry.upper_corner;
      if (!geometry.is_box())
      {
        // Inside the mesh, and clear of the walls it meets.
        Contact::Walls<dim> walls;
        geometry.add_walls(walls);
        for (unsigned int k = 0; k < grains.size(); ++k)
        {
          const auto &g    = grains[k];
          const auto  name = "grain " + std::to_string(k + 1) + " at " +
                            to_text(g.position) + " with radius " +
                            std::to_string(g.radius);
          if (!geometry.contains(g.position))
            where.fail(parameter,
                       value,
                       name + " is outside the mesh " + geometry.mesh_file);
          const double clearance = walls.clearance(g.position, g.radius, 0);
          if (clearance < -allowed_overlap * g.radius)
            where.fail(parameter,
                       value,
                       name + " overlaps a wall of the mesh by " +
                         std::to_string(-clearance) + " m");
        }
        return;
      }
      for (unsigned int k = 0; k < grains.size(); ++k)
        for (unsigned int d = 0; d < dim; ++d)
        {
          const double x   = grains[k].position[d];
          const double r   = geometry.is_periodic(d) ?
                               0 :
                               grains[k].radius * (1 - allowed_overlap);
          const double eps = 1e-12 * (hi[d] - lo[d]);
          if (x - r < lo[d] - eps || x + r > hi[d] + eps ||
              (geometry.is_periodic(d) && x >= hi[d]))
            where.fail(parameter,
                       value,
                       "grain " + std::to_string(k + 1) + " at " +
                         to_text(grains[k].position) + " with radius " +
                         std::to_string(grains[k].radius) +
                         " is not inside the domain " + to_text(lo) + " - " +
                         to_text(hi));
        }
    }
  } // namespace


  template <int dim>
  std::vector<GrainSeed<dim>>
  place_grains(const GrainParameters<dim> &prm, const Geometry<dim> &geometry)
  {
    const InputLocation place{prm.file, "Grains/Placement"};
    Random              random{std::mt19937_64(prm.random_seed)};

    std::vector<GrainSeed<dim>> grains;
    std::string                 parameter, value;
    switch (prm.shape)
    {
      case PlacementShape::ball:
      case PlacementShape::box:
        // One region per centre, filled in turn from the same random
        // stream.
        for (const Point<dim> &c : prm.centers)
        {
          GrainParameters<dim> region = prm;
          region.center               = c;
          // A box that spans a periodic axis of a box domain fills it
          // across the periodic faces, over the domain's period exactly.
          std::array<bool, dim> wrap;
          for (unsigned int d = 0; d < dim; ++d)
          {
            wrap[d] = prm.fill_across_periodic_faces &&
                      prm.shape == PlacementShape::box &&
                      spans_periodic_axis(geometry, c, prm.size, d);
            if (wrap[d])
            {
              region.center[d] =
                0.5 * (geometry.lower_corner[d] + geometry.upper_corner[d]);
              region.size[d] =
                geometry.upper_corner[d] - geometry.lower_corner[d];
            }
          }
          for (const auto &g : random_fill<dim>(region, random, wrap))
            grains.push_back(g);
        }
        parameter = prm.centers.size() > 1 ? "Center" : "Size";
        value     = prm.centers.size() > 1 ? prm.center_text : prm.size_text;
        break;
      case PlacementShape::lattice:
        grains    = lattice_fill(prm, random);
        parameter = "Size";
        value     = prm.size_text;
        break;
      case PlacementShape::list:
        for (const auto &x : prm.positions)
          grains.push_back({x, Tensor<1, dim>(), prm.radius});
        parameter = "Positions";
        value     = prm.positions_text;
        if (!prm.radii.empty())
        {
          const InputLocation g{prm.file, "Grains"};
          g.require(prm.radii.size() == grains.size(),
                    "Radii",
                    prm.radii_text,
                    "expected one radius per position (" +
                      std::to_string(grains.size()) + ")");
          for (unsigned int k = 0; k < grains.size(); ++k)
            grains[k].radius = prm.radii[k];
        }
        break;
      case PlacementShape::file:
        grains    = read_file(prm);
        parameter = "File";
        value     = prm.placement_file;
        break;
    }

    if (!prm.velocities.empty())
    {
      place.require(prm.velocities.size() == 1 ||
                      prm.velocities.size() == grains.size(),
                    "Velocities",
                    prm.velocities_text,
                    "give one velocity for all grains or one per grain (" +
                      std::to_string(grains.size()) + ")");
      for (unsigned int k = 0; k < grains.size(); ++k)
      {
        const Point<dim> &v =
          prm.velocities[prm.velocities.size() == 1 ? 0 : k];
        for (unsigned int d = 0; d < dim; ++d)
          grains[k].velocity[d] = v[d];
      }
    }

    if (grains.empty())
      return grains;
    // A packing the contact solver made (a file another run wrote) holds
    // overlaps up to its Overlap tolerance: it must read back.
    const double allowed_overlap =
      prm.contacts_enabled ? std::max(1e-9, prm.contact.overlap_tolerance) :
                             1e-9;
    check_inside(grains, geometry, allowed_overlap, place, parameter, value);
    if ((prm.shape != PlacementShape::ball &&
         prm.shape != PlacementShape::box) ||
        prm.centers.size() > 1)
      check_overlaps(
        grains, geometry, allowed_overlap, place, parameter, value);
    return grains;
  }


  template std::vector<GrainSeed<2>>
  place_grains(const GrainParameters<2> &, const Geometry<2> &);
  template std::vector<GrainSeed<3>>
  place_grains(const GrainParameters<3> &, const Geometry<3> &);
} // namespace ImmersedGrains
