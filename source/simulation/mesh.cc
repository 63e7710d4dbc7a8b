#include <deal.II/base/mpi.h>
#include <deal.II/base/utilities.h>

#include <immersed_grains/fluid/fluid_solver.h>
#include <immersed_grains/grains/grains.h>
#include <immersed_grains/io/progress_line.h>
#include <immersed_grains/simulation.h>

#include <iomanip>
#include <limits>

namespace ImmersedGrains
{


  template <int dim>
  void
  Simulation<dim>::track_grain_travel()
  {
    if (tracks_grain_travel())
      grain_travel +=
        last_step * std::max(step_start_speed, grain_statistics->max_speed);
  }


  template <int dim>
  bool
  Simulation<dim>::tracks_grain_travel() const
  {
    return adaptivity && grains && adaptivity_parameters.follow_grains &&
           adaptivity_parameters.around_grains;
  }


  template <int dim>
  bool
  Simulation<dim>::follows_straight_paths() const
  {
    // (Before the grains and the adaptivity exist: from the parameters.)
    return adaptivity_parameters.enabled && grain_parameters.enabled &&
           fluid_parameters.enabled && adaptivity_parameters.looks_ahead();
  }


  template <int dim>
  void
  Simulation<dim>::update_shortest_cell_edge()
  {
    double h = std::numeric_limits<double>::max();
    for (const auto &cell : triangulation.active_cell_iterators())
      if (cell->is_locally_owned())
        h = std::min(h, cell->minimum_vertex_distance());
    shortest_cell_edge = dealii::Utilities::MPI::min(h, comm);
  }


  template <int dim>
  bool
  Simulation<dim>::adapt_mesh()
  {
    const double                              start = wall_clock();
    typename Adaptivity<dim>::GrainProperties properties;
    if (grains)
    {
      properties.radius   = grains->layout().radius;
      properties.velocity = grains->layout().velocity;
    }
    const auto mark = [&](const bool refine_only)
    {
      dealii::TimerOutput::Scope scope(*timer, "adaptation");
      return adaptivity->mark_cells(grains ? &grains->particle_handler() :
                                             nullptr,
                                    properties,
                                    fluid.get(),
                                    shortest_cell_edge,
                                    refine_only);
    };
    if (!mark(false))
      return false;
    change_mesh([this]()
                { triangulation.execute_coarsening_and_refinement(); });
    // The lookahead band reaches cells several levels coarser than its
    // own: they climb a level per pass.
    unsigned int passes = 1;
    if (adaptivity_parameters.looks_ahead())
      for (; passes <= adaptivity_parameters.max_level && mark(true); ++passes)
        change_mesh([this]()
                    { triangulation.execute_coarsening_and_refinement(); });
    pdetail << "  mesh adapted before step " << step + 1;
    if (passes > 1)
      pdetail << " in " << passes << " passes";
    pdetail << ": " << triangulation.n_global_active_cells() << " cells, "
            << (fluid ? fluid->n_dofs() : 0) << " fluid DoFs, "
            << std::setprecision(3) << wall_clock() - start << " s";
    if (load_balance)
      pdetail << ", load imbalance " << load_balance->imbalance();
    pdetail << '\n' << std::setprecision(6);
    return true;
  }


  template <int dim>
  void
  Simulation<dim>::change_mesh(const std::function<void()> &change)
  {
    {
      dealii::TimerOutput::Scope scope(*timer, "adaptation");
      if (fluid)
        fluid->prepare_for_mesh_change();
      if (grains)
        grains->prepare_for_mesh_change();
      change();
    }
    if (fluid)
      fluid->finish_mesh_change();
    if (grains)
      grains->finish_mesh_change();
    if (coupling)
    {
      {
        dealii::TimerOutput::Scope scope(*timer, "adaptation");
        coupling->setup();
      }
      coupling->project(*grains);
    }
    // The last row's fluid volume as the new mesh holds it: the grains
    // and what is left of the departed ones projected anew, which hold
    // what that row's projection held.
    previous_fluid_volume = coupling && coupling_parameters.two_way ?
                              coupling->fluid_volume() :
                              std::numeric_limits<double>::quiet_NaN();
    update_shortest_cell_edge();
  }


  template <int dim>
  void
  Simulation<dim>::maybe_adapt_mesh()
  {
    if (adaptivity && step > 0)
    {
      double reach = 0;
      if (tracks_grain_travel())
      {
        // The step about to be taken counts: the band must hold the
        // grains until its end, at least at their largest speed now (the
        // last row's, reduced over the ranks).
        // (next_time_step() reduces over the grains and the fluid: once.)
        const double dt_next = next_time_step();
        step_start_speed     = grain_statistics->max_speed;
        const double ahead   = step_start_speed * dt_next;
        reach                = grain_travel + ahead;
        // Within the lookahead the band holds every grain that strays
        // from its straight path by less than the allowance, however far
        // it went along it.
        const double horizon = adaptivity->lookahead_horizon();
        if (horizon > 0 && time + dt_next - band_made_at <= horizon)
        {
          const auto &drift = grains->straight_path_drift();
          reach =
            std::min(reach, drift.displacement + dt_next * drift.velocity);
        }
        // Along its path the lookahead covers a grain too. (Band width = 0
        // asks for no margin: nothing to warn about.)
        const double covered =
          2 * adaptivity->travel_allowance(shortest_cell_edge) +
          (follows_straight_paths() ?
             adaptivity_parameters.band_lookahead * shortest_cell_edge :
             0.0);
        if (!warned_band_outrun && adaptivity_parameters.band_width > 0 &&
            ahead > covered)
        {
          warned_band_outrun = true;
          pcout << "  warning: step " << step + 1
                << ": the fastest grain crosses " << std::setprecision(3)
                << ahead / shortest_cell_edge
                << " of the finest cells in one fluid step, more than the "
                   "band around the grains (Adaptivity/Band width = "
                << adaptivity_parameters.band_width;
          if (follows_straight_paths())
            pcout << ", Band lookahead = "
                  << adaptivity_parameters.band_lookahead;
          pcout << "): grains leave the refined cells between adaptations; "
                   "widen the band or shorten the step (Courant number, Time "
                   "step)\n"
                << std::setprecision(6);
        }
      }
      if (adaptivity->due(
            step, reach, shortest_cell_edge, static_cast<bool>(grains)))
      {
        // The band is made around where the grains are now.
        grain_travel = 0;
        if (grains)
          grains->reset_straight_paths();
        band_made_at = time;
        if (adapt_mesh())
          return;
      }
    }
    if (!load_balance)
      return;
    // Collective: every rank computes the same global figure.
    const double before = load_balance->imbalance();
    if (before <= load_balance_parameters.max_imbalance)
      return;
    change_mesh([this]() { triangulation.repartition(); });
    pdetail << "  mesh repartitioned before step " << step + 1
            << ": load imbalance " << std::setprecision(3) << before << " -> "
            << load_balance->imbalance() << '\n'
            << std::setprecision(6);
  }



#define IMMERSED_GRAINS_INSTANTIATE(dim)                                     \
  template bool Simulation<dim>::adapt_mesh();                               \
  template void Simulation<dim>::change_mesh(const std::function<void()> &); \
  template void Simulation<dim>::maybe_adapt_mesh();                         \
  template void Simulation<dim>::track_grain_travel();                       \
  template bool Simulation<dim>::tracks_grain_travel() const;                \
  template bool Simulation<dim>::follows_straight_paths() const;             \
  template void Simulation<dim>::update_shortest_cell_edge();

  IMMERSED_GRAINS_INSTANTIATE(2)
  IMMERSED_GRAINS_INSTANTIATE(3)
} // namespace ImmersedGrains
