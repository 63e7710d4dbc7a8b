#include <deal.II/base/mpi.h>

#include <immersed_grains/contact/bucket_grid.h>
#include <immersed_grains/grains/cloud_analysis.h>
#include <immersed_grains/grains/grains.h>
#include <immersed_grains/parameters.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <unordered_map>

namespace ImmersedGrains
{
  template <int dim>
  void
  CloudAnalysis<dim>::Parameters::declare_parameters(
    dealii::ParameterHandler &prm)
  {
    using namespace dealii::Patterns;
    prm.enter_subsection("Cloud analysis");
    {
      prm.declare_entry(
        "Enabled",
        "auto",
        Selection("auto|true|false"),
        "Measure the grains as a cloud at every statistics row: clusters, "
        "leaked grains, the cloud's centroid, velocity and extent "
        "(statistics.csv columns cloud_*, leaked, clusters, "
        "breakup_time; doc/theory.md). auto: on when the grains are placed "
        "as a ball (Grains/Placement/Shape = ball).");
      prm.declare_entry(
        "Link distance",
        "3",
        Double(0),
        "Two grains whose centres are closer than this many "
        "diameters of the grain of mean volume belong to the same "
        "cluster (the mean spacing of a cloud at solid "
        "fraction 0.2 is about 2 diameters in 2D, 1.4 in 3D).");
      prm.declare_entry(
        "Core neighbours",
        "4",
        Integer(0),
        "A grain with at least this many others within the link distance "
        "is a core grain (density-based clustering, Ester et al. 1996): "
        "clusters are grown from core grains only, and other grains join the "
        "cluster of a core grain they are linked to, so that a thin filament "
        "does not hold two blobs together. A cloud at solid fraction phi has "
        "about phi (2 L/d)^dim neighbours within L (7.2 at phi = 0.2, L = 3 "
        "diameters in 2D; 43 in 3D): the default marks where the density "
        "falls to about half of that of a 2D cloud at phi = 0.2. 0 joins "
        "every linked pair.");
      prm.declare_entry(
        "Minimum cluster fraction",
        "0.2",
        Double(0, 1),
        "A cluster holding at least this share of all grains "
        "is counted in the column clusters (the cloud has broken up when "
        "there are two); grains outside the largest cluster "
        "are counted in the column leaked.");
    }
    prm.leave_subsection();
  }


  template <int dim>
  void
  CloudAnalysis<dim>::Parameters::parse_parameters(
    dealii::ParameterHandler   &prm,
    const std::string          &file,
    const GrainParameters<dim> &grains)
  {
    prm.enter_subsection("Cloud analysis");
    {
      const InputLocation where{file, "Cloud analysis"};
      const std::string   choice = prm.get("Enabled");
      where.require(!(choice == "true" && !grains.enabled),
                    "Enabled",
                    choice,
                    "needs grains (Grains/Enabled = true)");
      enabled = grains.enabled &&
                (choice == "true" ||
                 (choice == "auto" && grains.shape == PlacementShape::ball));
      placed_clouds            = grains.shape == PlacementShape::ball ?
                                   std::max<std::size_t>(1, grains.centers.size()) :
                                   1;
      link_distance            = prm.get_double("Link distance");
      minimum_cluster_fraction = prm.get_double("Minimum cluster fraction");
      core_neighbours          = prm.get_integer("Core neighbours");
      where.require(!enabled || link_distance > 0,
                    "Link distance",
                    prm.get("Link distance"),
                    "must be positive");
    }
    prm.leave_subsection();
  }


  template <int dim>
  CloudAnalysis<dim>::CloudAnalysis(const Parameters &parameters, MPI_Comm comm)
      : parameters(parameters)
      , comm(comm)
  {
  }


  template <int dim>
  std::vector<std::string>
  CloudAnalysis<dim>::column_names()
  {
    const char              *axes[] = {"x", "y", "z"};
    std::vector<std::string> c      = {"cloud_grains"};
    for (const char *name :
         {"cloud_centroid_", "cloud_velocity_", "cloud_extent_"})
      for (int d = 0; d < dim; ++d)
        c.push_back(std::string(name) + axes[d]);
    for (const char *name : {"leaked", "clusters", "breakup_time"})
      c.emplace_back(name);
    return c;
  }


  namespace
  {
    // Union-find with path halving; the smaller root joins the larger
    // index's tree so labels do not depend on the order of the unions.
    unsigned int
    find_root(std::vector<unsigned int> &parent, unsigned int i)
    {
      while (parent[i] != i)
      {
        parent[i] = parent[parent[i]];
        i         = parent[i];
      }
      return i;
    }
  } // namespace


  namespace
  {
    // The ranks' values one after the other, in the order of the ranks, on
    // every rank. As raw doubles: deal.II's all_gather() serialises and
    // zlib-compresses each rank's part, which took 4 % of the 2D cloud's
    // run on one rank, for a few hundred grains' records at every step.
    std::vector<double>
    gather_on_every_rank(const std::vector<double> &local, MPI_Comm comm)
    {
      const unsigned int n_ranks =
        dealii::Utilities::MPI::n_mpi_processes(comm);
      if (n_ranks == 1)
        return local;
      const int        count = local.size();
      std::vector<int> counts(n_ranks), offsets(n_ranks, 0);
      int              error =
        MPI_Allgather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, comm);
      AssertThrowMPI(error);
      for (unsigned int r = 1; r < n_ranks; ++r)
        offsets[r] = offsets[r - 1] + counts[r - 1];
      std::vector<double> all(offsets.back() + counts.back());
      error = MPI_Allgatherv(local.data(),
                             count,
                             MPI_DOUBLE,
                             all.data(),
                             counts.data(),
                             offsets.data(),
                             MPI_DOUBLE,
                             comm);
      AssertThrowMPI(error);
      return all;
    }
  } // namespace


  template <int dim>
  std::vector<unsigned int>
  label_clusters(const std::vector<dealii::Point<dim>> &points,
                 const double                           link_distance,
                 const unsigned int                     core_neighbours)
  {
    const unsigned int n = points.size();
    if (n == 0)
      return {};

    // Linked pairs (i < j) from the contacts' bucket grid: spheres of
    // diameter link_distance that overlap. The box around the points is
    // widened by a link so that it has a volume with one point, or with
    // points on a line.
    dealii::Point<dim> lower = points[0], upper = points[0];
    for (const auto &p : points)
      for (unsigned int d = 0; d < dim; ++d)
      {
        lower[d] = std::min(lower[d], p[d] - link_distance);
        upper[d] = std::max(upper[d], p[d] + link_distance);
      }
    std::vector<Contact::GrainPair<dim>> links;
    Contact::BucketGrid<dim>(lower, upper)
      .find_pairs(points, std::vector<double>(n, link_distance / 2), 0, links);
    std::vector<unsigned int> n_links(n, 0);
    for (const auto &link : links)
    {
      ++n_links[link.first];
      ++n_links[link.second];
    }

    // Core grains (enough neighbours) joined through their links; a thin
    // filament of grains does not hold two blobs together.
    std::vector<unsigned int> parent(n);
    std::iota(parent.begin(), parent.end(), 0u);
    auto is_core = [&](unsigned int i)
    { return n_links[i] >= core_neighbours; };
    for (const auto &link : links)
      if (is_core(link.first) && is_core(link.second))
      {
        const unsigned int a = find_root(parent, link.first);
        const unsigned int b = find_root(parent, link.second);
        if (a != b)
          parent[std::min(a, b)] = std::max(a, b);
      }
    // Other grains join the cluster of their first linked core grain (in
    // the order of the links: deterministic); grains with none stay alone.
    std::vector<unsigned int> attached(n,
                                       dealii::numbers::invalid_unsigned_int);
    for (const auto &link : links)
      for (const auto &[border, core] :
           {std::make_pair(link.first, link.second),
            std::make_pair(link.second, link.first)})
        if (!is_core(border) && is_core(core) &&
            attached[border] == dealii::numbers::invalid_unsigned_int)
          attached[border] = core;

    std::vector<unsigned int>                      label(n);
    std::unordered_map<unsigned int, unsigned int> number;
    for (unsigned int i = 0; i < n; ++i)
    {
      const unsigned int root =
        find_root(parent,
                  attached[i] == dealii::numbers::invalid_unsigned_int ?
                    i :
                    attached[i]);
      label[i] = number.emplace(root, number.size()).first->second;
    }
    return label;
  }


  template <int dim>
  CloudMeasures<dim>
  CloudAnalysis<dim>::analyse(
    const dealii::Particles::ParticleHandler<dim> &particles,
    const GrainPropertyLayout                     &layout) const
  {
    // Every rank gets all grains, ordered by id: the clusters and the sums
    // are then the same on any number of ranks.
    const unsigned int  record = 2 + 2 * dim;
    std::vector<double> local;
    local.reserve(particles.n_locally_owned_particles() * record);
    for (const auto &p : particles)
    {
      local.push_back(p.get_id());
      for (unsigned int d = 0; d < dim; ++d)
        local.push_back(p.get_location()[d]);
      const auto props = p.get_properties();
      for (unsigned int d = 0; d < dim; ++d)
        local.push_back(props[layout.velocity + d]);
      local.push_back(props[layout.radius]);
    }
    const std::vector<double> all = gather_on_every_rank(local, comm);
    const unsigned int        n   = all.size() / record;
    std::vector<unsigned int> order(n);
    std::iota(order.begin(), order.end(), 0u);
    std::sort(order.begin(),
              order.end(),
              [&](unsigned int a, unsigned int b)
              { return all[a * record] < all[b * record]; });
    std::vector<dealii::Point<dim>>     x(n);
    std::vector<dealii::Tensor<1, dim>> v(n);
    double smallest = std::numeric_limits<double>::max(), largest = 0,
           sum_of_powers = 0;
    for (unsigned int i = 0; i < n; ++i)
    {
      for (unsigned int d = 0; d < dim; ++d)
      {
        x[i][d] = all[order[i] * record + 1 + d];
        v[i][d] = all[order[i] * record + 1 + dim + d];
      }
      const double r = all[order[i] * record + 1 + 2 * dim];
      smallest       = std::min(smallest, r);
      largest        = std::max(largest, r);
      sum_of_powers += dealii::Utilities::fixed_power<dim>(r);
    }

    CloudMeasures<dim> m;
    if (n == 0)
      return m;
    // One size: that diameter exactly.
    const double                    diameter = largest == smallest ?
                                                 2 * largest :
                                                 2 * std::pow(sum_of_powers / n, 1.0 / dim);
    const std::vector<unsigned int> label =
      label_clusters(x,
                     parameters.link_distance * diameter,
                     parameters.core_neighbours);
    const unsigned int n_labels =
      *std::max_element(label.begin(), label.end()) + 1;
    std::vector<unsigned int> size(n_labels, 0);
    for (const unsigned int l : label)
      ++size[l];
    // Clusters: the large ones. The cloud: every grain of a dense part
    // (a cluster grown from a core grain has more members than a core
    // grain has neighbours), not the loose grains of the tail.
    const double       minimum = parameters.minimum_cluster_fraction * n;
    const unsigned int dense   = std::max(2u, parameters.core_neighbours + 1);
    std::vector<bool>  blob(n_labels);
    for (unsigned int l = 0; l < n_labels; ++l)
    {
      m.n_clusters += size[l] >= minimum && size[l] > 0;
      blob[l] = size[l] >= dense;
    }

    for (unsigned int i = 0; i < n; ++i)
      if (blob[label[i]])
      {
        ++m.n_cloud_grains;
        for (unsigned int d = 0; d < dim; ++d)
          m.centroid[d] += x[i][d];
        m.velocity += v[i];
      }
    m.n_leaked = n - *std::max_element(size.begin(), size.end());
    if (m.n_cloud_grains > 0)
    {
      m.centroid /= m.n_cloud_grains;
      m.velocity /= m.n_cloud_grains;
      for (unsigned int i = 0; i < n; ++i)
        if (blob[label[i]])
          for (unsigned int d = 0; d < dim; ++d)
            m.extent[d] +=
              dealii::Utilities::fixed_power<2>(x[i][d] - m.centroid[d]);
      for (unsigned int d = 0; d < dim; ++d)
        m.extent[d] = std::sqrt(m.extent[d] / m.n_cloud_grains);
    }
    return m;
  }


  template class CloudAnalysis<2>;
  template class CloudAnalysis<3>;
  template std::vector<unsigned int>
  label_clusters<2>(const std::vector<dealii::Point<2>> &,
                    double,
                    unsigned int);
  template std::vector<unsigned int>
  label_clusters<3>(const std::vector<dealii::Point<3>> &,
                    double,
                    unsigned int);
} // namespace ImmersedGrains
