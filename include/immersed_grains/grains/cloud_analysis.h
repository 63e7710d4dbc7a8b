#ifndef immersed_grains_grains_cloud_analysis_h
#define immersed_grains_grains_cloud_analysis_h

#include <deal.II/base/mpi.h>
#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/point.h>
#include <deal.II/base/tensor.h>
#include <deal.II/particles/particle_handler.h>

#include <immersed_grains/grains/grain_parameters.h>

#include <string>
#include <vector>

namespace ImmersedGrains
{
  struct GrainPropertyLayout;

  /** What CloudAnalysis::analyse() measures on one state of the grains. */
  template <int dim>
  struct CloudMeasures
  {
    /** Grains in the dense parts of the cloud (clusters grown from core
     *  grains), not the loose grains of its tail. */
    unsigned int n_cloud_grains = 0;
    /** Grains outside the largest cluster: leaked into the tail or away,
     *  or in the other parts of a cloud that has broken up. */
    unsigned int n_leaked = 0;
    /** Clusters holding at least the minimum fraction of all grains. */
    unsigned int n_clusters = 0;
    /** Mean position, mean velocity and radius of gyration per axis
     *  (square root of the variance of the positions) of those grains. */
    dealii::Point<dim>     centroid;
    dealii::Tensor<1, dim> velocity;
    dealii::Tensor<1, dim> extent;
  };

  /**
   * The shape of a cloud of grains as a researcher measures it (Metzger,
   * Nicolas & Guazzelli 2007): grains are joined into clusters when their
   * centres are closer than a link distance and they lie in the dense part
   * of the cloud (label_clusters()). The cloud is every grain of a dense
   * cluster, its loose tail is not; grains outside the largest cluster
   * count as leaked. The cloud has broken up when two clusters or more hold
   * at least a minimum share of all grains each (the caller keeps the first
   * time: it is a statistics column, and checkpoints keep it with the others).
   */
  template <int dim>
  class CloudAnalysis
  {
  public:
    struct Parameters
    {
      static void
      declare_parameters(dealii::ParameterHandler &prm);
      void
      parse_parameters(dealii::ParameterHandler   &prm,
                       const std::string          &file,
                       const GrainParameters<dim> &grains);

      bool enabled = false;
      /** Clouds placed at the start: one per Grains/Placement/Center of a
       *  ball, else 1. The break-up is a count above it. */
      unsigned int placed_clouds            = 1;
      double       link_distance            = 3;   // grain diameters
      double       minimum_cluster_fraction = 0.2; // of all grains
      unsigned int core_neighbours          = 4;
    };

    CloudAnalysis(const Parameters &parameters, MPI_Comm comm);

    /**
     * Measures the grains of @p particles (collective: every rank's grains
     * are gathered). The link distance is in diameters of the grain of
     * mean volume, 2 (sum r^dim / n)^{1/dim}: a cloud at solid fraction
     * phi then has about phi (2 L/d)^dim grains within L whatever its
     * sizes, as the core condition assumes (with the largest grain's
     * diameter, a lognormal cloud of geometric deviation 1.25 linked over
     * twice the length and broke up 2.5 times later).
     */
    CloudMeasures<dim>
    analyse(const dealii::Particles::ParticleHandler<dim> &particles,
            const GrainPropertyLayout                     &layout) const;

    /** The statistics.csv columns this class fills, for @p dim. */
    static std::vector<std::string>
    column_names();

  private:
    const Parameters &parameters;
    MPI_Comm          comm;
  };

  /**
   * Density-based clusters (DBSCAN, Ester et al. 1996) of @p points: a
   * point with at least @p core_neighbours others closer than
   * @p link_distance is a core point; linked core points share a cluster,
   * another point joins the cluster of a core point it is linked to, or
   * stays alone. One label per point, numbered 0, 1, ... in order of
   * first appearance. Exposed for the tests.
   */
  template <int dim>
  std::vector<unsigned int>
  label_clusters(const std::vector<dealii::Point<dim>> &points,
                 double                                 link_distance,
                 unsigned int                           core_neighbours);
} // namespace ImmersedGrains

#endif
