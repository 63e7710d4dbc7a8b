#include <deal.II/base/mpi.h>

#include <immersed_grains/mesh/load_balance.h>
#include <immersed_grains/parameters.h>

#include <cmath>
#include <string>

namespace ImmersedGrains
{
  template <int dim>
  void
  LoadBalance<dim>::Parameters::declare_parameters(
    dealii::ParameterHandler &prm)
  {
    using namespace dealii::Patterns;
    prm.enter_subsection("Load balancing");
    {
      prm.declare_entry(
        "Grain weight",
        "auto",
        Anything(),
        "On several MPI ranks: the work of one grain relative to one cell's "
        "fluid work, for partitioning the mesh; a number from 0 (balance "
        "cells only) to 1000, or auto: 1.5 in 2D, 0.2 in 3D, the measured "
        "ratios. A 2D cloud step on one rank: about 25 us per cell for the "
        "fluid and 37 us per grain for the drag, contacts and sorting "
        "(doc/adaptivity.md); Lethe's 3D sedimentation scene: 216 us per "
        "Q2-Q1 cell, 44 us per grain (doc/performance.md).");
      prm.declare_entry("Max imbalance",
                        "1.2",
                        Double(1),
                        "Repartition before a step when the most loaded "
                        "rank carries more than this many times the mean "
                        "load (cells and grains weighted as above).");
    }
    prm.leave_subsection();
  }


  template <int dim>
  void
  LoadBalance<dim>::Parameters::parse_parameters(dealii::ParameterHandler &prm,
                                                 const std::string        &file)
  {
    prm.enter_subsection("Load balancing");
    {
      const InputLocation where{file, "Load balancing"};
      const std::string   weight = prm.get("Grain weight");
      if (weight == "auto")
        grain_weight = dim == 2 ? 1.5 : 0.2;
      else
        where.require(parse_number(weight, grain_weight) && grain_weight >= 0 &&
                        grain_weight <= 1000,
                      "Grain weight",
                      weight,
                      "must be auto or a number from 0 to 1000");
      max_imbalance = prm.get_double("Max imbalance");
    }
    prm.leave_subsection();
  }


  template <int dim>
  LoadBalance<dim>::LoadBalance(
    const Parameters                                  &parameters,
    dealii::parallel::distributed::Triangulation<dim> &tria,
    const dealii::Particles::ParticleHandler<dim>     &grains)
      : parameters(parameters)
      , triangulation(tria)
      , grains(grains)
  {
    connection = triangulation.signals.weight.connect(
      [this](const typename dealii::Triangulation<dim>::cell_iterator &cell,
             const typename dealii::Triangulation<dim>::CellStatus     status)
        -> unsigned int { return weight(cell, status); });
  }


  template <int dim>
  LoadBalance<dim>::~LoadBalance()
  {
    connection.disconnect();
  }


  template <int dim>
  unsigned int
  LoadBalance<dim>::weight(
    const typename dealii::Triangulation<dim>::cell_iterator &cell,
    const typename dealii::Triangulation<dim>::CellStatus     status) const
  {
    using Tria = dealii::Triangulation<dim>;
    const unsigned int per_grain =
      static_cast<unsigned int>(std::lround(1000 * parameters.grain_weight));
    std::size_t n = 0;
    switch (status)
    {
      case Tria::CELL_PERSIST:
        n = grains.n_particles_in_cell(cell);
        break;
      case Tria::CELL_REFINE:
        // Called for each future child with the parent: share its grains.
        // (It has no children yet.)
        n = grains.n_particles_in_cell(cell) /
            cell->reference_cell().n_isotropic_children();
        break;
      case Tria::CELL_COARSEN:
        for (const auto &child : cell->child_iterators())
          n += grains.n_particles_in_cell(child);
        break;
      default:
        break;
    }
    return 1000 + per_grain * static_cast<unsigned int>(n);
  }


  template <int dim>
  double
  LoadBalance<dim>::imbalance() const
  {
    double load = 0;
    for (const auto &cell : triangulation.active_cell_iterators())
      if (cell->is_locally_owned())
        load += weight(cell, dealii::Triangulation<dim>::CELL_PERSIST);
    const MPI_Comm comm  = triangulation.get_communicator();
    const double   total = dealii::Utilities::MPI::sum(load, comm);
    const double   most  = dealii::Utilities::MPI::max(load, comm);
    const double   ranks = dealii::Utilities::MPI::n_mpi_processes(comm);
    return total > 0 ? most / (total / ranks) : 1.0;
  }


  template class LoadBalance<2>;
  template class LoadBalance<3>;
} // namespace ImmersedGrains
