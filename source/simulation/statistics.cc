#include <deal.II/base/mpi.h>
#include <deal.II/base/utilities.h>

#include <immersed_grains/coupling/coupled_step.h>
#include <immersed_grains/fluid/fluid_solver.h>
#include <immersed_grains/grains/grains.h>
#include <immersed_grains/io/progress_line.h>
#include <immersed_grains/simulation.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <map>
#include <sstream>

namespace ImmersedGrains
{
  namespace
  {
    // The timings.csv columns and the TimerOutput sections each one sums.
    const std::vector<std::pair<std::string, std::vector<std::string>>> &
    timing_phases()
    {
      static const std::vector<std::pair<std::string, std::vector<std::string>>>
        phases = {{"setup", {"mesh", "fluid: setup", "grains: setup"}},
                  {"assembly", {"fluid: assembly"}},
                  {"preconditioner", {"fluid: preconditioner"}},
                  {"solve", {"fluid: solve", "fluid: direct solve"}},
                  {"solid_fraction", {"coupling: solid fraction"}},
                  {"interaction_force", {"coupling: interaction force"}},
                  {"grain_velocities",
                   {"grains: free velocities", "grains: gather"}},
                  {"contacts", {"grains: contacts"}},
                  {"sort", {"grains: move and sort"}},
                  {"adaptation", {"adaptation"}},
                  {"output", {"output"}},
                  {"statistics", {"statistics"}}};
      return phases;
    }

    // The interface's core columns, in their documented order
    // (doc/output.md): first in the file, whoever fills them.
    std::vector<std::string>
    core_columns(const unsigned int dim)
    {
      std::vector<std::string> c = {
        "step", "time", "dt", "particles", "solid_volume"};
      const char *axes[] = {"x", "y", "z"};
      for (unsigned int d = 0; d < dim; ++d)
        c.push_back(std::string("centroid_") + axes[d]);
      for (unsigned int d = 0; d < dim; ++d)
        c.push_back(std::string("mean_velocity_") + axes[d]);
      for (const char *name : {"max_speed",
                               "kinetic_energy",
                               "max_overlap",
                               "contacts",
                               "contact_iterations",
                               "fluid_iterations",
                               "cells",
                               "dofs",
                               "wall_time"})
        c.emplace_back(name);
      return c;
    }
  } // namespace


  template <int dim>
  std::vector<std::string>
  Simulation<dim>::statistics_columns()
  {
    // Each object declares the columns it fills.
    const std::vector<std::vector<std::string>> owners = {
      // The run (postprocess()): load_imbalance is the most loaded rank
      // over the mean, cells and grains weighted as for partitioning (1 on
      // one rank or without grains); step_retries, the fluid steps taken
      // again shorter after a failure, since the start.
      {"step",
       "time",
       "dt",
       "cells",
       "wall_time",
       "load_imbalance",
       "step_retries"},
      GrainStatistics<dim>::column_names(),
      GrainStepReport::column_names(),
      FluidSolver<dim>::StepStatistics::column_names(),
      // The mixture's fields (set_fluid_statistics()).
      {"dofs",
       "fluid_volume",
       "fluid_volume_balance",
       "pressure_drop",
       "solid_volume",
       "solid_volume_error",
       "max_reynolds"},
      CoupledStep<dim>::column_names(),
      CloudAnalysis<dim>::column_names()};
    std::vector<std::string> columns = core_columns(dim);
    for (const auto &names : owners)
      for (const auto &name : names)
        if (std::find(columns.begin(), columns.end(), name) == columns.end())
          columns.push_back(name);
    return columns;
  }


  template <int dim>
  void
  Simulation<dim>::parse_output_points(dealii::ParameterHandler &prm,
                                       const InputLocation      &where)
  {
    static const char *const axes[] = {"_x", "_y", "_z"};
    std::vector<std::string> columns;
    // Boundary ids, a comma list of whole numbers.
    const auto parse_ids = [&](const std::string &name, std::string &text)
    {
      text = prm.get(name);
      std::vector<dealii::types::boundary_id> ids;
      for (const double id : parse_double_list(text, where, name))
      {
        where.require(id >= 0 && id == std::floor(id) &&
                        id < dealii::numbers::internal_face_boundary_id,
                      name,
                      text,
                      "boundary ids are whole numbers from 0");
        ids.push_back(static_cast<dealii::types::boundary_id>(id));
      }
      return ids;
    };
    boundary_force_ids = parse_ids("Boundary forces", boundary_force_text);
    for (const auto id : boundary_force_ids)
      for (unsigned int d = 0; d < dim; ++d)
        columns.push_back("boundary_force_" + std::to_string(id) + axes[d]);
    boundary_contact_force_ids =
      parse_ids("Boundary contact forces", boundary_contact_force_text);
    for (const auto id : boundary_contact_force_ids)
      for (unsigned int d = 0; d < dim; ++d)
        columns.push_back("boundary_contact_force_" + std::to_string(id) +
                          axes[d]);
    boundary_flux_ids = parse_ids("Boundary fluxes", boundary_flux_text);
    for (const auto id : boundary_flux_ids)
      columns.push_back("boundary_flux_" + std::to_string(id));
    probe_text = prm.get("Probes");
    for (const std::string &entry :
         dealii::Utilities::split_string_list(probe_text, ';'))
    {
      const auto        colon = entry.find(':');
      const std::string name =
        colon == std::string::npos ?
          "" :
          dealii::Utilities::trim(entry.substr(0, colon));
      where.require(!name.empty() &&
                      name.find_first_not_of(
                        "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
                        "0123456789_") == std::string::npos,
                    "Probes",
                    probe_text,
                    "'" + entry +
                      "' is not 'name: x, y[, z]' with a name of letters, "
                      "digits and _");
      for (const auto &[other, point] : probes)
        where.require(other != name,
                      "Probes",
                      probe_text,
                      "probe '" + name + "' is named twice");
      probes.emplace_back(
        name, parse_point<dim>(entry.substr(colon + 1), where, "Probes"));
      columns.push_back("probe_" + name + "_pressure");
      columns.push_back("probe_" + name + "_solid_fraction");
    }
    statistics.add_columns(columns);
  }


  template <int dim>
  std::vector<std::string>
  Simulation<dim>::timing_columns()
  {
    std::vector<std::string> c = {"step", "time"};
    for (const auto &phase : timing_phases())
      c.push_back(phase.first);
    c.emplace_back("other");
    c.emplace_back("total");
    return c;
  }


  template <int dim>
  void
  Simulation<dim>::postprocess(const double dt)
  {
    dealii::TimerOutput::Scope scope(*timer, "statistics");
    statistics.set("step", step);
    statistics.set("time", time);
    statistics.set("dt", dt);
    statistics.set("cells", triangulation.n_global_active_cells());
    statistics.set("load_imbalance",
                   load_balance ? load_balance->imbalance() : 1.0);
    statistics.set("step_retries", retries_taken);
    if (fluid)
      set_fluid_statistics();
    if (grains)
      set_grain_statistics();
    statistics.set("wall_time", wall_clock() - wall_start);
    statistics.write_row();
    for (TestCheck &c : test_checks)
      c.record(statistics);

    print_test_row(false);
    pdetail << "step " << step << " t=" << time << " dt=" << dt;
    if (fluid)
      pdetail << " fluid iterations=" << statistics.get("fluid_iterations");
    if (grains)
      pdetail << " grains=" << grain_statistics->n_grains
              << " contacts=" << statistics.get("contacts")
              << " sweeps=" << statistics.get("contact_iterations")
              << " Ekin=" << grain_statistics->kinetic_energy;
    pdetail << '\n';
    print_progress(false);
  }


  template <int dim>
  void
  Simulation<dim>::set_fluid_statistics()
  {
    // The coupling knows its fluid fraction node by node; prescribed
    // fields are integrated by quadrature, over the mesh as mapped (not
    // the coarse mesh's volume: a curved boundary's changes with
    // refinement).
    double       volume       = geometry.volume();
    const double fluid_volume = coupling && coupling_parameters.two_way ?
                                  coupling->fluid_volume() :
                                  fluid->integrate_fluid_fraction(&volume);
    statistics.set("dofs", fluid->n_dofs());
    statistics.set("fluid_volume", fluid_volume);
    // Each boundary's flux once, for its column and the balance both.
    std::map<dealii::types::boundary_id, double> fluxes;
    const auto flux_through = [&](const dealii::types::boundary_id id)
    {
      auto found = fluxes.find(id);
      if (found == fluxes.end())
        found = fluxes.emplace(id, fluid->boundary_flux(id)).first;
      return found->second;
    };
    {
      // The fluid gained in the domain over the step against what flowed
      // in through open and inflow faces; with grains leaving, the water
      // that replaces them (Coupling::project_departed()).
      double net_outflow = 0, crossing = 0;
      for (const auto &[id, type] : geometry.boundary_types)
        if (type == BoundaryType::open || type == BoundaryType::velocity)
        {
          const double flux = flux_through(id);
          net_outflow += flux;
          crossing += std::abs(flux);
        }
      const double dt = statistics.get("dt");
      const double imbalance =
        fluid_volume - previous_fluid_volume + dt * net_outflow;
      statistics.set("fluid_volume_balance",
                     std::isfinite(imbalance) && dt * crossing > 0 ?
                       imbalance / (dt * crossing) :
                       0.0);
      previous_fluid_volume = fluid_volume;
    }
    if (!pressure_drop_points.empty())
      statistics.set("pressure_drop",
                     fluid->pressure_at(pressure_drop_points[0]) -
                       fluid->pressure_at(pressure_drop_points[1]));
    statistics.set("solid_volume",
                   coupling ? coupling->solid_volume() : volume - fluid_volume);
    static const char *const axes[] = {"_x", "_y", "_z"};
    const auto forces = fluid->boundary_forces(boundary_force_ids);
    for (unsigned int k = 0; k < boundary_force_ids.size(); ++k)
      for (unsigned int d = 0; d < dim; ++d)
        statistics.set("boundary_force_" +
                         std::to_string(boundary_force_ids[k]) + axes[d],
                       forces[k][d]);
    for (const auto id : boundary_flux_ids)
      statistics.set("boundary_flux_" + std::to_string(id), flux_through(id));
    for (const auto &[name, point] : probes)
    {
      statistics.set("probe_" + name + "_pressure", fluid->pressure_at(point));
      statistics.set("probe_" + name + "_solid_fraction",
                     1 - fluid->fluid_fraction_at(point));
    }
  }


  template <int dim>
  void
  Simulation<dim>::set_grain_statistics()
  {
    if (!grain_statistics)
      grain_statistics = std::make_unique<GrainStatistics<dim>>();
    *grain_statistics = grains->compute_statistics();
    const auto &s     = *grain_statistics;
    s.set_statistics(statistics, !fluid);
    if (!boundary_contact_force_ids.empty())
    {
      static const char *const axes[] = {"_x", "_y", "_z"};
      const auto               on_boundaries =
        grains->boundary_contact_forces(boundary_contact_force_ids);
      for (unsigned int k = 0; k < boundary_contact_force_ids.size(); ++k)
        for (unsigned int d = 0; d < dim; ++d)
          statistics.set("boundary_contact_force_" +
                           std::to_string(boundary_contact_force_ids[k]) +
                           axes[d],
                         on_boundaries[k][d]);
    }
    if (coupling && s.solid_volume > 0)
    {
      // Conservation of the projection: what the fluid sees against what
      // the grains were when it was made (those that left through an open
      // boundary in the step's moves included).
      const double projected_grains =
        s.solid_volume + coupling->removed_since_projection(*grains);
      statistics.set("solid_volume_error",
                     std::abs(coupling->solid_volume() - projected_grains) /
                       projected_grains);
      statistics.set("max_reynolds", coupling->max_reynolds());
    }
    if (cloud_analysis)
      set_cloud_statistics();
  }


  template <int dim>
  void
  Simulation<dim>::set_cloud_statistics()
  {
    const CloudMeasures<dim> m =
      cloud_analysis->analyse(grains->particle_handler(), grains->layout());
    const char *axes[] = {"x", "y", "z"};
    statistics.set("cloud_grains", m.n_cloud_grains);
    for (unsigned int d = 0; d < dim; ++d)
    {
      statistics.set(std::string("cloud_centroid_") + axes[d], m.centroid[d]);
      statistics.set(std::string("cloud_velocity_") + axes[d], m.velocity[d]);
      statistics.set(std::string("cloud_extent_") + axes[d], m.extent[d]);
    }
    statistics.set("leaked", m.n_leaked);
    statistics.set("clusters", m.n_clusters);
    if (m.n_clusters > cloud_parameters.placed_clouds && breakup_time < 0)
    {
      breakup_time = time;
      pcout << "The cloud has broken up at t = " << time << " s (step " << step
            << "): " << m.n_clusters << " clusters of at least "
            << cloud_parameters.minimum_cluster_fraction * 100
            << " % of the grains each, " << m.n_leaked
            << " grains outside the largest\n";
    }
    statistics.set("breakup_time", breakup_time);
  }


  template <int dim>
  void
  Simulation<dim>::print_progress(const bool last)
  {
    if (!progress->due(last))
      return;
    std::ostringstream line;
    line << std::setprecision(3);
    if (fluid)
      line << " (dt " << statistics.get("dt");
    if (fluid && grains)
      line << ", " << static_cast<long long>(statistics.get("grain_substeps"))
           << " grain sub-steps";
    if (fluid)
      line << ")";
    // Counts as integers (a double stream would write 1.04e+03).
    const auto count = [this](const char *column)
    { return static_cast<long long>(statistics.get(column)); };
    if (grains)
      line << ", " << count("particles") << " grains";
    line << ", " << count("cells") << " cells";
    if (fluid)
      line << ", " << count("fluid_iterations") << " fluid its";
    if (grains && grain_parameters.contacts_enabled)
      line << ", " << count("contact_iterations") << " sweeps";
    progress->print(time, end_time, step, line.str(), last);
  }


  template <int dim>
  void
  Simulation<dim>::record_timings()
  {
    // Wall seconds spent in each phase since the last row, the slowest
    // rank's (a step waits for it).
    const auto totals =
      timer->get_summary_data(dealii::TimerOutput::total_wall_time);
    std::vector<double> spent;
    for (const auto &[column, sections] : timing_phases())
    {
      double sum = 0;
      for (const auto &section : sections)
        if (const auto it = totals.find(section); it != totals.end())
          sum += it->second;
      spent.push_back(sum - timer_totals[column]);
      timer_totals[column] = sum;
    }
    const double wall = wall_clock();
    spent.push_back(wall - last_timing_wall);
    last_timing_wall = wall;
    dealii::Utilities::MPI::max(dealii::ArrayView<const double>(spent),
                                comm,
                                dealii::ArrayView<double>(spent));

    timings.set("step", step);
    timings.set("time", time);
    double phases = 0;
    for (unsigned int i = 0; i < timing_phases().size(); ++i)
    {
      timings.set(timing_phases()[i].first, spent[i]);
      phases += spent[i];
    }
    timings.set("total", spent.back());
    timings.set("other", std::max(0.0, spent.back() - phases));
    timings.write_row();
  }


  template <int dim>
  void
  Simulation<dim>::print_test_row(const bool last) const
  {
    if (!test_output || dealii::Utilities::MPI::this_mpi_process(comm) != 0)
      return;
    // Rows every Test every steps, the last one always (once).
    const bool regular = step % test_every == 0;
    if (last ? !regular : regular)
      statistics.print(std::cout, test_columns);
  }



#define IMMERSED_GRAINS_INSTANTIATE(dim)                                    \
  template std::vector<std::string> Simulation<dim>::statistics_columns();  \
  template std::vector<std::string> Simulation<dim>::timing_columns();      \
  template void                     Simulation<dim>::parse_output_points(   \
    dealii::ParameterHandler &, const InputLocation &); \
  template void Simulation<dim>::postprocess(double);                       \
  template void Simulation<dim>::set_fluid_statistics();                    \
  template void Simulation<dim>::set_grain_statistics();                    \
  template void Simulation<dim>::set_cloud_statistics();                    \
  template void Simulation<dim>::print_progress(bool);                      \
  template void Simulation<dim>::print_test_row(bool) const;                \
  template void Simulation<dim>::record_timings();

  IMMERSED_GRAINS_INSTANTIATE(2)
  IMMERSED_GRAINS_INSTANTIATE(3)
} // namespace ImmersedGrains
