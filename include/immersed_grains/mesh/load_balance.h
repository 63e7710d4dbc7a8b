#ifndef immersed_grains_mesh_load_balance_h
#define immersed_grains_mesh_load_balance_h

#include <deal.II/base/parameter_handler.h>
#include <deal.II/distributed/tria.h>
#include <deal.II/particles/particle_handler.h>

#include <boost/signals2/connection.hpp>

#include <string>

namespace ImmersedGrains
{
  /**
   * Partitions the mesh by work, not by cells: each cell weighs 1000 plus
   * Grain weight times 1000 per grain it holds (the triangulation's
   * `weight` signal, used whenever it repartitions: at every adaptation,
   * and when this class finds the ranks' loads too uneven).
   */
  template <int dim>
  class LoadBalance
  {
  public:
    struct Parameters
    {
      static void
      declare_parameters(dealii::ParameterHandler &prm);
      void
      parse_parameters(dealii::ParameterHandler &prm, const std::string &file);

      double grain_weight  = dim == 2 ? 1.5 : 0.2;
      double max_imbalance = 1.2;
    };

    LoadBalance(const Parameters                                  &parameters,
                dealii::parallel::distributed::Triangulation<dim> &tria,
                const dealii::Particles::ParticleHandler<dim>     &grains);
    ~LoadBalance();

    /** The largest rank's load over the mean load (collective). */
    double
    imbalance() const;

  private:
    unsigned int
    weight(const typename dealii::Triangulation<dim>::cell_iterator &cell,
           typename dealii::Triangulation<dim>::CellStatus status) const;

    const Parameters                                  &parameters;
    dealii::parallel::distributed::Triangulation<dim> &triangulation;
    const dealii::Particles::ParticleHandler<dim>     &grains;
    boost::signals2::connection                        connection;
  };
} // namespace ImmersedGrains

#endif
