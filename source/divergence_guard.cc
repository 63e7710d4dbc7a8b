#include <deal.II/base/mpi.h>

#include <immersed_grains/divergence_guard.h>
#include <immersed_grains/fluid/fluid_solver.h>
#include <immersed_grains/grains/grains.h>

#include <cmath>
#include <functional>
#include <iomanip>
#include <sstream>

namespace ImmersedGrains
{
  namespace
  {
    // Calls @p visit(cell centre, whether a velocity, value) for the fluid
    // DoFs of each owned cell, in turn, until it returns true (the
    // searches behind the messages; failure paths only).
    template <int dim>
    void
    visit_fluid_values(
      const FluidSolver<dim> &fluid,
      const std::function<bool(const dealii::Point<dim> &, bool, double)>
        &visit)
    {
      const auto &dof_handler = fluid.get_dof_handler();
      const auto &solution    = fluid.get_solution();
      const auto &fe          = dof_handler.get_fe();
      std::vector<dealii::types::global_dof_index> indices(
        fe.n_dofs_per_cell());
      for (const auto &cell : dof_handler.active_cell_iterators())
        if (cell->is_locally_owned())
        {
          cell->get_dof_indices(indices);
          const dealii::Point<dim> centre = cell->center();
          for (unsigned int i = 0; i < indices.size(); ++i)
            if (visit(centre,
                      fe.system_to_component_index(i).first < dim,
                      solution[indices[i]]))
              return;
        }
    }

    template <int dim>
    std::string
    coordinates(const dealii::Point<dim> &where)
    {
      std::ostringstream text;
      text << "(";
      for (unsigned int d = 0; d < dim; ++d)
        text << (d > 0 ? ", " : "") << where[d];
      text << ")";
      return text.str();
    }
  } // namespace


  template <int dim>
  void
  DivergenceGuard<dim>::declare_parameters(dealii::ParameterHandler &prm)
  {
    prm.declare_entry(
      "Divergence speed factor",
      "100",
      dealii::Patterns::Double(0),
      "A run stops with a message, after a last output, when a fluid or "
      "grain speed exceeds this many times the fastest motion the scene "
      "drives: free fall across the box along gravity, the boundary and "
      "initial velocities, a prescribed grain velocity, and the speeds a "
      "body force or an open-face pressure reaches across the box "
      "(doc/stability.md). Such a run is exploding without being NaN yet, "
      "and its adaptive steps shrink towards zero. 0 switches the check "
      "off.");
  }


  template <int dim>
  void
  DivergenceGuard<dim>::parse_parameters(dealii::ParameterHandler &prm)
  {
    speed_factor = prm.get_double("Divergence speed factor");
  }


  template <int dim>
  void
  DivergenceGuard<dim>::start(const dealii::Tensor<1, dim> &gravity_,
                              const double                  fall_height_,
                              const double initial_grain_speed_,
                              MPI_Comm     comm_)
  {
    gravity             = gravity_;
    fall_height         = fall_height_;
    initial_grain_speed = initial_grain_speed_;
    comm                = comm_;
  }


  template <int dim>
  std::string
  DivergenceGuard<dim>::find_not_finite(const FluidSolver<dim>     *fluid,
                                        const Grains<dim>          *grains,
                                        const GrainStatistics<dim> *statistics,
                                        const unsigned int          step) const
  {
    // One pass over the owned values (a ghosted vector has no norm) and
    // two statistics, on every step: the search below runs only on failure.
    bool fluid_finite = true;
    if (fluid)
    {
      const auto &solution = fluid->get_solution();
      for (const auto i : solution.locally_owned_elements())
        if (!std::isfinite(solution[i]))
        {
          fluid_finite = false;
          break;
        }
      fluid_finite =
        dealii::Utilities::MPI::min(fluid_finite ? 1 : 0, comm) == 1;
    }
    const bool grains_finite =
      !statistics ||
      (std::isfinite(statistics->kinetic_energy) &&
       (statistics->n_grains == 0 || std::isfinite(statistics->centroid[0])));
    if (fluid_finite && grains_finite)
      return "";

    std::string        field;
    dealii::Point<dim> where;
    bool               found = false;
    if (!fluid_finite)
      visit_fluid_values<dim>(
        *fluid,
        [&](const dealii::Point<dim> &centre, const bool velocity, double value)
        {
          if (std::isfinite(value))
            return false;
          found = true;
          where = centre;
          field = velocity ? "fluid velocity" : "fluid pressure";
          return true;
        });
    if (!found && grains)
    {
      const unsigned int velocity = grains->layout().velocity;
      for (const auto &p : grains->particle_handler())
      {
        const auto props           = p.get_properties();
        bool       finite_velocity = true, finite_position = true;
        for (unsigned int d = 0; d < dim; ++d)
        {
          finite_velocity &= std::isfinite(props[velocity + d]);
          finite_position &= std::isfinite(p.get_location()[d]);
        }
        if (!finite_velocity || !finite_position)
        {
          found = true;
          where = finite_position ? p.get_location() :
                                    p.get_surrounding_cell()->center();
          field = "velocity of grain " + std::to_string(p.get_id());
          break;
        }
      }
    }
    // The lowest rank that found one tells.
    const unsigned int n_ranks = dealii::Utilities::MPI::n_mpi_processes(comm);
    const unsigned int rank    = dealii::Utilities::MPI::this_mpi_process(comm);
    const unsigned int teller =
      dealii::Utilities::MPI::min(found ? rank : n_ranks, comm);
    const std::string text =
      teller == n_ranks ? std::string("a global sum of the fluid or of the "
                                      "grains") :
                          "the " + field + " near " + coordinates(where);
    const std::string place =
      dealii::Utilities::MPI::broadcast(comm,
                                        text,
                                        teller == n_ranks ? 0 : teller);
    return place +
           " is not finite (NaN or Inf); the run diverged there. The last "
           "output (step " +
           std::to_string(step) +
           ") holds it; a shorter Time step, or Adaptive time step = "
           "true, usually keeps it finite.";
  }


  template <int dim>
  double
  DivergenceGuard<dim>::driven_speed(const FluidSolver<dim> *fluid) const
  {
    return std::max({std::sqrt(2 * gravity.norm() * fall_height),
                     initial_grain_speed,
                     fluid ? fluid->driven_speed() : 0.0});
  }


  template <int dim>
  std::string
  DivergenceGuard<dim>::find_speeding(const FluidSolver<dim>     *fluid,
                                      const Grains<dim>          *grains,
                                      const GrainStatistics<dim> *statistics,
                                      const unsigned int          step)
  {
    if (speed_factor <= 0)
      return "";
    const double fluid_speed = fluid ? fluid->max_velocity() : 0.0;
    const double grain_speed = statistics ? statistics->max_speed : 0.0;
    const double speed       = std::max(fluid_speed, grain_speed);
    if (speed == 0)
      return "";
    const double driven = driven_speed(fluid);
    // Nothing drives any motion: there is no scale to compare with.
    if (driven <= 0)
      return "";
    if (speed / driven > largest_speed_ratio)
    {
      largest_speed_ratio = speed / driven;
      driven_at_largest   = driven;
    }
    if (speed <= speed_factor * driven)
      return "";

    // Where: the cell of the fastest fluid node, or the fastest grain.
    double             local_max = 0;
    dealii::Point<dim> where;
    const bool         in_fluid = fluid_speed >= grain_speed;
    if (in_fluid)
      visit_fluid_values<dim>(*fluid,
                              [&](const dealii::Point<dim> &centre,
                                  const bool                velocity,
                                  double                    value)
                              {
                                if (velocity && std::abs(value) > local_max)
                                {
                                  local_max = std::abs(value);
                                  where     = centre;
                                }
                                return false;
                              });
    else
    {
      const unsigned int velocity = grains->layout().velocity;
      for (const auto &p : grains->particle_handler())
      {
        dealii::Tensor<1, dim> v;
        for (unsigned int d = 0; d < dim; ++d)
          v[d] = p.get_properties()[velocity + d];
        if (v.norm() > local_max)
        {
          local_max = v.norm();
          where     = p.get_location();
        }
      }
    }
    // The rank that holds the maximum tells (the lowest on a tie).
    const unsigned int rank   = dealii::Utilities::MPI::this_mpi_process(comm);
    const double global_max   = dealii::Utilities::MPI::max(local_max, comm);
    const unsigned int teller = dealii::Utilities::MPI::min(
      local_max == global_max ? rank :
                                dealii::Utilities::MPI::n_mpi_processes(comm),
      comm);
    where = dealii::Utilities::MPI::broadcast(comm, where, teller);

    std::ostringstream text;
    text << std::setprecision(3) << "the " << (in_fluid ? "fluid" : "grains")
         << " speed reached " << speed << " m/s near " << coordinates(where)
         << ", over " << speed_factor
         << " times the fastest motion the scene drives (" << driven
         << " m/s: free fall across the box, boundary, initial and "
            "prescribed velocities, forcing); the run is exploding. The last "
            "output (step "
         << step
         << ") holds it. The usual causes: cells too coarse for the flow "
            "(its cell Reynolds number), a step too long (Courant number, "
            "Time step). Divergence speed factor sets the bound (0: off).";
    return text.str();
  }


  template <int dim>
  void
  DivergenceGuard<dim>::print_summary(dealii::ConditionalOStream &out) const
  {
    if (largest_speed_ratio > 0)
      out << "  divergence check: the fastest speed was "
          << std::setprecision(3) << largest_speed_ratio
          << " times the fastest motion the scene drives (" << driven_at_largest
          << " m/s then); a run stops at " << speed_factor << " times\n"
          << std::setprecision(6);
  }


  template class DivergenceGuard<2>;
  template class DivergenceGuard<3>;
} // namespace ImmersedGrains
