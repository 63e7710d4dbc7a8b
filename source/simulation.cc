#include <deal.II/base/mpi.h>
#include <deal.II/base/utilities.h>

#include <immersed_grains/fluid/fluid_solver.h>
#include <immersed_grains/grains/grains.h>
#include <immersed_grains/io/field_output.h>
#include <immersed_grains/io/particle_output.h>
#include <immersed_grains/mesh/size_estimate.h>
#include <immersed_grains/simulation.h>

#include <array>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <limits>
#include <sstream>

namespace ImmersedGrains
{
  namespace
  {
    double
    now()
    {
      return std::chrono::duration<double>(
               std::chrono::steady_clock::now().time_since_epoch())
        .count();
    }

    // The statistics.csv columns in their fixed order, the core set (step
    // to wall_time) first.
    std::vector<std::string>
    statistics_columns(const int dim)
    {
      std::vector<std::string> c = {
        "step", "time", "dt", "particles", "solid_volume"};
      const char *axes[] = {"x", "y", "z"};
      for (int d = 0; d < dim; ++d)
        c.push_back(std::string("centroid_") + axes[d]);
      for (int d = 0; d < dim; ++d)
        c.push_back(std::string("mean_velocity_") + axes[d]);
      for (const char *name : {"max_speed",
                               "kinetic_energy",
                               "max_overlap",
                               "contacts",
                               "contact_iterations",
                               "fluid_iterations",
                               "cells",
                               "dofs",
                               "wall_time",
                               "fluid_nonlinear_iterations",
                               "fluid_residual",
                               "fluid_volume",
                               "packing_fraction",
                               "grains_removed",
                               "solid_volume_error",
                               "max_reynolds",
                               "drag_force_on_grains",
                               "momentum_exchange_error",
                               "pressure_drop",
                               "contact_residual",
                               "contact_converged",
                               "max_contact_force",
                               "alert_distance",
                               "grain_substeps",
                               "clamped_fluid_fraction_nodes"})
        c.emplace_back(name);
      // Appended: scripts may read the columns above by position.
      c.emplace_back("fixed_particles");
      for (int d = 0; d < dim; ++d)
        c.push_back(std::string("fixed_centroid_") + axes[d]);
      c.emplace_back("drag_averaged_cells");
      c.emplace_back("preconditioner_builds"); // cumulative
      // Most loaded rank over the mean, cells and grains weighted as for
      // partitioning (1 on one rank or without grains).
      c.emplace_back("load_imbalance");
      for (const auto &name : dim == 2 ? CloudAnalysis<2>::column_names() :
                                         CloudAnalysis<3>::column_names())
        c.push_back(name);
      // Fluid steps taken again shorter after a failure, since the start.
      c.emplace_back("step_retries");
      // The drag impulse the fluid owes the grains at the step's end over
      // the step's, and the books since the start (doc/output.md).
      c.emplace_back("momentum_exchange_owed");
      c.emplace_back("momentum_exchange_drift");
      return c;
    }

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

    std::vector<std::string>
    timing_columns()
    {
      std::vector<std::string> c = {"step", "time"};
      for (const auto &phase : timing_phases())
        c.push_back(phase.first);
      c.emplace_back("other");
      c.emplace_back("total");
      return c;
    }
  } // namespace


  template <int dim>
  void
  Simulation<dim>::declare_parameters(dealii::ParameterHandler &prm)
  {
    using namespace dealii::Patterns;
    prm.declare_entry("Dimension",
                      "2",
                      Integer(2, 3),
                      "Space dimension of the scene: 2 (discs per unit depth) "
                      "or 3 (spheres).");
    prm.declare_entry("Output directory",
                      "",
                      Anything(),
                      "Where statistics.csv, log.txt and fields go; empty: "
                      "output/<parameter file name without .prm>.");
    prm.declare_entry("End time", "1", Double(0), "Simulated time [s].");
    prm.declare_entry("Time step",
                      "0.01",
                      Double(0),
                      "Time step [s]; with Adaptive time step, the largest.");
    prm.declare_entry(
      "Adaptive time step",
      "false",
      Bool(),
      "Shorten the step to follow the motion. With grains coupled to a "
      "fluid and Coupling/Grain sub-steps on: the fluid step is set by the "
      "flow, at most Courant number times the shortest cell edge over the "
      "largest grain speed (the solid fraction moves by at most that part "
      "of a cell per fluid step) and, with advection, over the largest "
      "fluid speed; from rest, the step in which free fall (gravity less "
      "buoyancy) crosses that part of a cell; the grains sub-step inside it "
      "so that none moves more than Grains/Max displacement fraction of "
      "the smallest radius per sub-step. Otherwise the whole step follows "
      "the grains: no grain moves more than that fraction of the smallest "
      "radius, nor more than half the shortest cell edge, in one step. "
      "Either way a step is at most twice the last (variable-step BDF2 "
      "is stable below 1 + sqrt 2).");
    prm.declare_entry(
      "Courant number",
      "0.1",
      Double(0),
      "With Adaptive time step: the largest fraction of the shortest cell "
      "edge that grains (and, with advection, the fluid) cross in one fluid "
      "step (doc/performance.md measures the error against cost).");
    prm.declare_entry(
      "Step retries",
      "3",
      Integer(0, 20),
      "With Adaptive time step: a fluid step that fails (its linear or "
      "nonlinear solve does not converge, or meets a value that is not "
      "finite) is taken again from where it started with half the step, up "
      "to this many times, before the run stops. The steps after a retry "
      "grow back by at most a factor of 2 each. The statistics column "
      "step_retries counts them.");
    prm.declare_entry(
      "Divergence speed factor",
      "100",
      Double(0),
      "A run stops with a message, after a last output, when a fluid or "
      "grain speed exceeds this many times the fastest motion the scene "
      "drives: free fall across the box along gravity, the boundary and "
      "initial velocities, a prescribed grain velocity, and the speeds a "
      "body force or an open-face pressure reaches across the box "
      "(doc/stability.md). Such a run is exploding without being NaN yet, "
      "and its adaptive steps shrink towards zero. 0 switches the check "
      "off.");

    prm.enter_subsection("Output");
    {
      prm.declare_entry("Write fields every",
                        "0",
                        Integer(0),
                        "Write the fields and the grains every this many "
                        "steps (0: only the initial and the final state).");
      prm.declare_entry(
        "Format",
        "vtu",
        Selection("vtu|hdf5"),
        "vtu: a VTU piece per rank and time with a PVTU record, listed in "
        "fields.pvd and particles.pvd; hdf5: one HDF5 file per time written "
        "by all ranks together, listed in fields.xdmf and particles.xdmf "
        "(for runs with many ranks or large meshes: two files per output "
        "whatever the number of ranks). ParaView opens both.");
      prm.declare_entry("Terminal output",
                        "normal",
                        Selection("normal|verbose|quiet|test"),
                        "normal: the log on screen with a progress line "
                        "(rewritten in place on a terminal, a line every "
                        "Progress every seconds otherwise), the details (a "
                        "line per step, every mesh change) only in log.txt; "
                        "verbose: the details on screen too, no progress "
                        "line; quiet: only errors; test: "
                        "only the Test columns of each statistics row, with "
                        "6 digits (for the test suite).");
      prm.declare_entry("Progress every seconds",
                        "10",
                        Double(0),
                        "With Terminal output = normal and the screen not a "
                        "terminal (a file, a pipe, mpirun, CI): a progress "
                        "line every this many seconds of wall time (0: "
                        "none). On a terminal the line is rewritten in place "
                        "four times a second.");
      prm.declare_entry("Test columns",
                        "step, time, solid_volume",
                        Anything(),
                        "Statistics columns printed per step in test mode.");
      prm.declare_entry("Test every steps",
                        "1",
                        Integer(1),
                        "Test mode prints every this many steps (and the "
                        "last).");
      prm.declare_entry("Test checks",
                        "",
                        Anything(),
                        "Conditions on statistics columns at the end of the "
                        "run, printed as yes/no in test mode, separated by "
                        "';': 'column < v', 'column > v', 'column in [a, "
                        "b]'.");
      prm.declare_entry("Pressure drop points",
                        "",
                        Anything(),
                        "Two points 'x1,y1[,z1]; x2,y2[,z2]' of the mesh: the "
                        "statistics column pressure_drop is p(first) - "
                        "p(second) [Pa] (a fixed bed's pressure drop, say).");
    }
    prm.leave_subsection();

    Geometry<dim>::declare_parameters(prm);
    FluidParameters<dim>::declare_parameters(prm);
    Coupling<dim>::Parameters::declare_parameters(prm);
    GrainParameters<dim>::declare_parameters(prm);
    Adaptivity<dim>::Parameters::declare_parameters(prm);
    LoadBalance<dim>::Parameters::declare_parameters(prm);
    Checkpoint::Parameters::declare_parameters(prm);
    CloudAnalysis<dim>::Parameters::declare_parameters(prm);
  }


  template <int dim>
  Simulation<dim>::Simulation(dealii::ParameterHandler &prm,
                              const std::string        &file,
                              MPI_Comm                  comm)
      : comm(comm)
      , parameter_file(file)
      , pcout(log.stream(), dealii::Utilities::MPI::this_mpi_process(comm) == 0)
      , pdetail(log.details(),
                dealii::Utilities::MPI::this_mpi_process(comm) == 0)
      , statistics(statistics_columns(dim))
      , timings(timing_columns())
      , triangulation(
          comm,
          // Level differences at vertices only: with the island
          // rules too, coarsening the children of a cell whose
          // neighbours are refined made it an unrefined island,
          // refined again by the next adaptation, and so on:
          // the mesh around still grains never settled.
          typename dealii::Triangulation<dim>::MeshSmoothing(
            dealii::Triangulation<dim>::limit_level_difference_at_vertices))
      , wall_start(now())
      , last_timing_wall(wall_start)
  {
    const InputLocation top{file, ""};
    output_directory = prm.get("Output directory");
    if (output_directory.empty())
      output_directory =
        "output/" + std::filesystem::path(file).stem().string();
    end_time  = prm.get_double("End time");
    time_step = prm.get_double("Time step");
    top.require(time_step > 0,
                "Time step",
                prm.get("Time step"),
                "must be positive");
    adaptive_time_step      = prm.get_bool("Adaptive time step");
    courant_number          = prm.get_double("Courant number");
    divergence_speed_factor = prm.get_double("Divergence speed factor");
    step_retries            = prm.get_integer("Step retries");
    top.require(courant_number > 0 || !adaptive_time_step,
                "Courant number",
                prm.get("Courant number"),
                "must be positive with Adaptive time step");

    prm.enter_subsection("Output");
    {
      const InputLocation where{file, "Output"};
      write_fields_every = prm.get_integer("Write fields every");
      output_format =
        prm.get("Format") == "hdf5" ? OutputFormat::hdf5 : OutputFormat::vtu;
      const std::string mode = prm.get("Terminal output");
      test_output            = mode == "test";
      quiet                  = mode != "normal" && mode != "verbose";
      verbose                = mode == "verbose";
      progress_interval      = prm.get_double("Progress every seconds");
      test_columns =
        dealii::Utilities::split_string_list(prm.get("Test columns"));
      for (const auto &c : test_columns)
        where.require(statistics.has(c),
                      "Test columns",
                      prm.get("Test columns"),
                      "no statistics column named '" + c + "'");
      test_every = prm.get_integer("Test every steps");
      pressure_drop_points =
        parse_point_list<dim>(prm.get("Pressure drop points"),
                              where,
                              "Pressure drop points");
      where.require(pressure_drop_points.empty() ||
                      pressure_drop_points.size() == 2,
                    "Pressure drop points",
                    prm.get("Pressure drop points"),
                    "needs two points separated by ';'");
      pressure_drop_text = prm.get("Pressure drop points");
      test_checks        = parse_test_checks(prm.get("Test checks"),
                                      statistics,
                                      where,
                                      "Test checks");
    }
    prm.leave_subsection();

    geometry.parse_parameters(prm, file);
    for (const auto &point : pressure_drop_points)
      for (unsigned int d = 0; d < dim; ++d)
        InputLocation{file, "Output"}.require(point[d] >=
                                                  geometry.lower_corner[d] &&
                                                point[d] <=
                                                  geometry.upper_corner[d],
                                              "Pressure drop points",
                                              pressure_drop_text,
                                              "a point lies outside the mesh");
    fluid_parameters.parse_parameters(prm, file, geometry);
    grain_parameters.parse_parameters(prm, file);
    coupling_parameters.parse_parameters(prm, file);
    adaptivity_parameters.parse_parameters(prm, file, fluid_parameters.enabled);
    // A placement or contact law written for grains that are off would be
    // ignored without a word, and a scene without fluid or grains would
    // write empty results: both are mistakes, not choices.
    InputLocation{file, "Grains"}.require(
      fluid_parameters.enabled || grain_parameters.enabled,
      "Enabled",
      "false",
      "nothing to simulate: Fluid/Enabled is false as well");
    if (!grain_parameters.enabled)
      for (const auto &entry : entries_set_in(file))
        if ((entry.rfind("Grains/", 0) == 0 && entry != "Grains/Enabled") ||
            entry.rfind("Contacts/", 0) == 0)
          InputLocation{file, "Grains"}.fail(
            "Enabled",
            "false",
            "the scene sets " + entry +
              " but grains are off; set Enabled = true in subsection Grains, "
              "or remove what is set for them");
    load_balance_parameters.parse_parameters(prm, file);
    checkpoint_parameters.parse_parameters(prm, file);
    cloud_parameters.parse_parameters(prm, file, grain_parameters);
    if (cloud_parameters.enabled)
    {
      cloud_analysis =
        std::make_unique<CloudAnalysis<dim>>(cloud_parameters, comm);
      statistics.set("breakup_time", -1); // not yet
    }
    if (grain_parameters.enabled)
      grain_seeds = place_grains(grain_parameters, geometry);
    for (const auto &seed : grain_seeds)
    {
      largest_grain_radius = std::max(largest_grain_radius, seed.radius);
      mean_grain_radius += seed.radius / grain_seeds.size();
    }
    placed_grains = grain_seeds.size();
    choose_drag_distribution(file);

    // Stop here, before anything large is allocated or written, if the
    // scene cannot fit: the kernel would kill it half-way instead.
    // An adaptive mesh is counted as its grain band will make it around
    // the initial grains: its initial mesh alone says nothing of the
    // levels it will reach.
    const bool adapted_estimate = adaptivity_parameters.enabled &&
                                  adaptivity_parameters.around_grains &&
                                  !grain_seeds.empty();
    if (adapted_estimate)
    {
      GrainBand band;
      band.min_level  = adaptivity_parameters.min_level;
      band.max_level  = adaptivity_parameters.max_level;
      band.band_width = adaptivity_parameters.band_width;
      band.smallest_cell =
        adaptivity_parameters.min_cell_size * 2 * largest_grain_radius;
      if (adaptivity_parameters.looks_ahead())
      {
        band.lookahead = adaptivity_parameters.band_lookahead;
        // Gravity's main axis: where the grains go is not known before
        // they move, and most scenes' grains settle or rise.
        for (unsigned int d = 1; d < dim; ++d)
          if (std::abs(grain_parameters.gravity[d]) >
              std::abs(grain_parameters.gravity[band.path_axis]))
            band.path_axis = d;
      }
      std::vector<dealii::Point<dim>> positions;
      positions.reserve(grain_seeds.size());
      for (const auto &seed : grain_seeds)
        positions.push_back(seed.position);
      size_estimate = estimate_adapted_size(geometry,
                                            band,
                                            fluid_parameters.enabled,
                                            positions);
    }
    else
      size_estimate =
        estimate_size(geometry, fluid_parameters.enabled, grain_seeds.size());
    available_memory = machine_memory(comm);
    if (size_estimate.peak_bytes > 0.9 * available_memory)
    {
      std::ostringstream problem;
      problem << std::setprecision(3) << size_estimate.cells << " cells and "
              << size_estimate.dofs << " DoFs"
              << (size_estimate.adapted ? " (the band around the grains)" : "")
              << " need about " << size_estimate.peak_bytes / (1 << 30)
              << " GiB, more than the " << available_memory / (1 << 30)
              << " GiB of memory here; lower it or Mesh/Subdivisions ("
              << prm.get({"Mesh"}, "Subdivisions") << ")";
      if (size_estimate.adapted)
        InputLocation{file, "Adaptivity"}.fail(
          "Max level",
          std::to_string(adaptivity_parameters.max_level),
          problem.str());
      InputLocation{file, "Mesh"}.fail("Initial refinement",
                                       std::to_string(
                                         geometry.initial_refinement),
                                       problem.str());
    }
  }


  template <int dim>
  Simulation<dim>::~Simulation() = default;


  template <int dim>
  void
  Simulation<dim>::prepare_output_directory(const int resumed_step)
  {
    const bool root = dealii::Utilities::MPI::this_mpi_process(comm) == 0;
    if (root)
    {
      std::error_code error;
      std::filesystem::create_directories(output_directory, error);
      AssertThrow(!error,
                  dealii::ExcMessage("Cannot create the output directory '" +
                                     output_directory +
                                     "': " + error.message()));
      // A copy of the scene beside its results, unless the scene is
      // already there (a parameter file kept in its output directory).
      const std::filesystem::path copy =
        output_directory + "/" +
        std::filesystem::path(parameter_file).filename().string();
      if (!std::filesystem::exists(copy) ||
          !std::filesystem::equivalent(parameter_file, copy))
        std::filesystem::copy_file(
          parameter_file,
          copy,
          std::filesystem::copy_options::overwrite_existing);
    }
    MPI_Barrier(comm);
    log.open(
      output_directory + "/log.txt", root, !quiet, verbose, resumed_step >= 0);
    statistics.open(output_directory + "/statistics.csv", root, resumed_step);
    timings.open(output_directory + "/timings.csv", root, resumed_step);
    field_output =
      std::make_unique<FieldOutput<dim>>(output_directory, output_format, comm);
    particle_output = std::make_unique<ParticleOutput<dim>>(output_directory,
                                                            output_format,
                                                            comm);
  }


  template <int dim>
  void
  Simulation<dim>::setup(const std::string &resume_from)
  {
    const bool resumed = !resume_from.empty();
    {
      dealii::TimerOutput::Scope scope(*timer, "mesh");
      if (resumed)
      {
        geometry.create_coarse_mesh(triangulation);
        triangulation.load(resume_from + "/mesh");
      }
      else
        geometry.create_mesh(triangulation);
    }
    update_shortest_cell_edge();
    pcout << "immersed-grains: " << dim << "D scene " << parameter_file
          << " on " << dealii::Utilities::MPI::n_mpi_processes(comm)
          << " MPI rank(s)\n";
    if (resumed)
      pcout << "  resumed from " << resume_from << '\n';
    pcout << "  mesh: " << triangulation.n_global_active_cells()
          << " cells, boundary conditions:";
    for (const auto t : geometry.boundary_types)
      pcout << ' ' << to_string(t);
    pcout << '\n';
    pcout << "  estimate: " << size_estimate.cells << " cells, "
          << size_estimate.dofs << " DoFs, peak memory about "
          << std::setprecision(3) << size_estimate.peak_bytes / (1 << 30)
          << " GiB of " << available_memory / (1 << 30) << " GiB"
          << (size_estimate.adapted ? " (adapted around the initial grains)" :
                                      "")
          << '\n'
          << std::setprecision(6);

    if (fluid_parameters.enabled)
    {
      fluid = std::make_unique<FluidSolver<dim>>(
        fluid_parameters, geometry, triangulation, *timer, pdetail);
      fluid->setup_dofs();
      if (resumed)
        fluid->deserialize();
      else
        fluid->set_initial_condition();
      pcout << "  fluid: "
            << (fluid_parameters.advection ? "Navier-Stokes" : "Stokes")
            << (fluid_parameters.time_derivative ?
                  (fluid_parameters.bdf_order == 2 ? ", BDF2" : ", BDF1") :
                  ", steady")
            << ", Q2-Q1, " << fluid->n_dofs() << " DoFs, "
            << (fluid_parameters.direct_solver ? "direct solver" :
                                                 "FGMRES + block AMG")
            << '\n';
    }

    if (grain_parameters.enabled)
    {
      grains = std::make_unique<Grains<dim>>(grain_parameters,
                                             geometry,
                                             triangulation,
                                             fluid_parameters.enabled,
                                             *timer,
                                             follows_straight_paths());
      // A resumed run does not place its grains again.
      if (resumed)
        grains->deserialize();
      else
        grains->initialize(grain_seeds);
      const auto &c = grain_parameters.contact;
      pcout << "  grains: " << grains->particle_handler().n_global_particles()
            << ", " << grains->layout().n_properties << " properties per grain";
      if (grain_parameters.contacts_enabled)
        pcout << "; contacts: e = " << c.restitution << ", mu = " << c.friction
              << ", tolerance " << c.tolerance;
      else
        pcout << "; contacts off";
      pcout << '\n';
      grain_seeds.clear();
    }

    if (fluid && grains)
    {
      coupling =
        std::make_unique<Coupling<dim>>(coupling_parameters,
                                        grain_parameters,
                                        geometry,
                                        triangulation,
                                        fluid_parameters.density,
                                        fluid_parameters.viscosity,
                                        fluid_parameters.time_derivative,
                                        fluid_parameters.advection,
                                        *timer);
      coupling->setup();
      coupling->attach(*fluid);
      coupling->project(*grains);
      // Once per run, in the log and on the screen: a choice outside what
      // the model is validated for (immersed-grains --check lists them).
      if (!resumed)
        for (const auto &warning : regime().warnings)
          pcout << "  warning: " << warning << '\n';
      pcout << "  coupling: drag law " << coupling_parameters.drag_law
            << (coupling_parameters.tracers ?
                  ", tracers" :
                  (coupling_parameters.two_way ? ", two-way" : ", one-way"))
            << ", drag distribution " << coupling_parameters.drag_distribution
            << (drag_distribution_choice.empty() ?
                  std::string() :
                  " (auto: " + drag_distribution_choice + ")")
            << (coupling_parameters.projection.closure_porosity.sphere_packing ?
                  ", porosity of the equivalent sphere packing" :
                  "")
            << '\n';
    }
    if (cloud_analysis)
      pcout << "  cloud analysis: clusters of grains closer than "
            << cloud_parameters.link_distance << " diameters, grown from "
            << "grains with at least " << cloud_parameters.core_neighbours
            << " such neighbours; break-up at "
            << cloud_parameters.placed_clouds + 1 << " clusters of "
            << cloud_parameters.minimum_cluster_fraction * 100
            << " % of the grains\n";

    // Grains make cells unequal work; on one rank there is nothing to
    // balance.
    if (fluid && grains && load_balance_parameters.grain_weight > 0 &&
        dealii::Utilities::MPI::n_mpi_processes(comm) > 1)
      load_balance =
        std::make_unique<LoadBalance<dim>>(load_balance_parameters,
                                           triangulation,
                                           grains->particle_handler());
    if (adaptivity_parameters.enabled)
    {
      adaptivity =
        std::make_unique<Adaptivity<dim>>(adaptivity_parameters,
                                          geometry,
                                          triangulation,
                                          adaptivity_parameters.min_cell_size *
                                            2 * largest_grain_radius);
      // Each pass refines a cell by one level at most: repeat until the
      // mesh around the initial grains stops changing.
      unsigned int passes = 0;
      while (!resumed && passes < 2 * (adaptivity_parameters.max_level + 1) &&
             adapt_mesh())
        ++passes;
    }
    if (resumed)
      load_state(resume_from);
    else
      maybe_adapt_mesh();
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
    const double                              start = now();
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
            << std::setprecision(3) << now() - start << " s";
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
        // grains until its end. (The last step's statistics hold the
        // grains' largest speed, reduced over the ranks; a checkpoint
        // carries it.)
        // (next_time_step() reduces over the grains and the fluid: once.)
        const double dt_next = next_time_step();
        step_start_speed     = statistics.get("max_speed");
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


  template <int dim>
  void
  Simulation<dim>::maybe_write_checkpoint()
  {
    if (checkpoint->due(step, now()))
      write_checkpoint();
  }


  template <int dim>
  void
  Simulation<dim>::write_checkpoint()
  {
    dealii::TimerOutput::Scope scope(*timer, "output");
    const std::string          directory = checkpoint->begin(step);
    // The fluid's states first, then the grains: loading follows this
    // order.
    if (fluid)
      fluid->prepare_for_serialization();
    if (grains)
      grains->prepare_for_serialization();
    triangulation.save(directory + "/mesh");
    Checkpoint::maybe_die_while_writing(step);
    if (grains)
    {
      std::ofstream out(
        directory + "/contacts_" +
        std::to_string(dealii::Utilities::MPI::this_mpi_process(comm)) +
        ".txt");
      grains->save_contact_memory(out);
      AssertThrow(out, dealii::ExcMessage("Cannot write " + directory));
    }
    field_output->series().save(directory + "/fields_xdmf.txt");
    particle_output->series().save(directory + "/particles_xdmf.txt");
    // Written last: its presence marks the set complete (Checkpoint).
    save_state(directory);
    const std::string saved = checkpoint->commit(step, now());

    // Go on from what was just written, as a run resumed from it would: a
    // loaded triangulation numbers its cells afresh, and with them the
    // DoFs and the order of the grains, while one that was refined and
    // coarsened keeps the gaps of its history; the two would round
    // differently from here on. (The preconditioner is rebuilt too.)
    const bool echo = pcout.is_active();
    pcout.set_condition(false);
    pdetail.set_condition(false);
    coupling.reset();
    adaptivity.reset();
    load_balance.reset();
    grains.reset();
    fluid.reset();
    triangulation.clear();
    setup(saved);
    pcout.set_condition(echo);
    pdetail.set_condition(echo);
  }


  namespace
  {
    // What decides the layout of the saved fields and grains: a run with
    // other physics would read them as something else (a frictionless
    // pile's 4 numbers per grain read as 7 gave grains at infinite speed).
    template <int dim>
    std::string
    physics_description(const bool                  fluid,
                        const GrainParameters<dim> &grains,
                        const bool                  straight_paths)
    {
      std::string text =
        std::string("fluid ") + (fluid ? "on" : "off") + ", grains ";
      if (!grains.enabled)
        return text + "off";
      const GrainPropertyLayout layout =
        make_grain_property_layout(grains, fluid, straight_paths);
      text += "with " + std::to_string(layout.n_properties) + " properties (";
      for (unsigned int k = 0; k < layout.names.size(); ++k)
        if (k == 0 || layout.names[k] != layout.names[k - 1])
          text += (k == 0 ? "" : ", ") + layout.names[k];
      return text + ")";
    }
  } // namespace


  template <int dim>
  std::string
  Simulation<dim>::saved_physics_description() const
  {
    return physics_description(fluid_parameters.enabled,
                               grain_parameters,
                               follows_straight_paths());
  }


  template <int dim>
  bool
  Simulation<dim>::physics_reachable(const std::string &saved) const
  {
    // Every combination of the settings that decide the layout.
    for (unsigned int k = 0; k < 64; ++k)
    {
      GrainParameters<dim> grains = grain_parameters;
      grains.enabled              = k & 1;
      grains.contacts_enabled     = k & 2;
      grains.contact.friction     = (k & 4) ? 1.0 : 0.0;
      grains.has_fixed_region     = k & 8;
      const bool fluid            = k & 16;
      const bool straight_paths   = k & 32;
      if (physics_description(fluid, grains, straight_paths) == saved)
        return true;
    }
    return false;
  }


  template <int dim>
  void
  Simulation<dim>::check_saved_physics(const std::string &directory) const
  {
    // Checkpoints written before this file existed are taken as they are,
    // unless the grains now follow straight paths, which no grain of such
    // a set carries (Band lookahead came after the file).
    std::ifstream in(directory + "/physics.txt");
    std::string   saved;
    if (!std::getline(in, saved))
    {
      if (follows_straight_paths())
        InputLocation{parameter_file, "Checkpoint"}.fail(
          "Resume",
          checkpoint_parameters.resume == Checkpoint::Resume::always ? "true" :
                                                                       "auto",
          directory +
            " was written before the grains carried their straight paths "
            "(it has no physics.txt), which Adaptivity/Band lookahead = " +
            std::to_string(adaptivity_parameters.band_lookahead) +
            " needs: resume with Band lookahead = 0, or start afresh with "
            "Resume = false");
      return;
    }
    const std::string wanted = saved_physics_description();
    if (saved != wanted && !physics_reachable(saved))
      InputLocation{parameter_file, "Checkpoint"}.fail(
        "Resume",
        checkpoint_parameters.resume == Checkpoint::Resume::always ? "true" :
                                                                     "auto",
        directory + " was written with " + saved +
          ", a layout no setting of this version gives (this version's, "
          "for this scene: " +
          wanted +
          "): it was written by another version of immersed-grains; resume "
          "it with that version, or start afresh with Resume = false");
    if (saved != wanted)
      InputLocation{parameter_file, "Checkpoint"}.fail(
        "Resume",
        checkpoint_parameters.resume == Checkpoint::Resume::always ? "true" :
                                                                     "auto",
        directory + " was written with " + saved + "; this scene has " +
          wanted +
          ": resume with the settings it was written with (Fluid/Enabled, "
          "Grains/Enabled, Contacts/Enabled, Contacts/Friction, a fixed "
          "region and Adaptivity/Band lookahead decide these), or start "
          "afresh with Resume = false");
  }


  template <int dim>
  void
  Simulation<dim>::save_state(const std::string &directory) const
  {
    MPI_Barrier(comm);
    if (dealii::Utilities::MPI::this_mpi_process(comm) != 0)
      return;
    std::ofstream out(directory + "/state.txt.part");
    out << step << '\n'
        << std::hexfloat << time << '\n'
        << std::dec << dealii::Utilities::MPI::n_mpi_processes(comm) << ' '
        << clamped_nodes_before << ' ' << preconditioner_builds << '\n';
    if (fluid)
      fluid->save_state(out);
    else
      out << "none\n";
    for (const auto *records : {&field_output->series().records(),
                                &particle_output->series().records()})
    {
      out << records->size() << '\n';
      for (const auto &[t, file] : *records)
        out << std::hexfloat << t << ' ' << file << '\n';
    }
    out << "grain_travel " << std::hexfloat << grain_travel << '\n';
    {
      const StraightPathDrift drift =
        grains ? grains->straight_path_drift() : StraightPathDrift();
      out << "band_lookahead " << std::hexfloat
          << (adaptivity ? adaptivity->lookahead_horizon() : 0.0) << ' '
          << band_made_at << ' ' << drift.displacement << ' ' << drift.velocity
          << '\n';
    }
    out << "momentum_exchange " << std::hexfloat << exchanged_impulse;
    for (unsigned int d = 0; d < dim; ++d)
      out << ' ' << exchange_imbalance[d];
    out << '\n';
    statistics.save_values(out);
    out.close();
    AssertThrow(out, dealii::ExcMessage("Cannot write " + directory));
    std::ofstream physics(directory + "/physics.txt");
    physics << saved_physics_description() << '\n';
    physics.close();
    AssertThrow(physics, dealii::ExcMessage("Cannot write " + directory));
    std::filesystem::rename(directory + "/state.txt.part",
                            directory + "/state.txt");
  }


  template <int dim>
  void
  Simulation<dim>::load_state(const std::string &directory)
  {
    // Every rank reads the same file.
    std::ifstream in(directory + "/state.txt");
    std::string   text;
    unsigned int  saved_ranks = 0;
    in >> step >> text >> saved_ranks >> clamped_nodes_before >>
      preconditioner_builds;
    time = std::strtod(text.c_str(), nullptr);
    if (fluid)
      fluid->load_state(in);
    else
      in >> text;
    for (auto *records : {&field_output->series().records(),
                          &particle_output->series().records()})
    {
      std::size_t n = 0;
      in >> n;
      records->clear();
      for (std::size_t k = 0; k < n; ++k)
      {
        std::string file;
        in >> text >> file;
        records->emplace_back(std::strtod(text.c_str(), nullptr), file);
      }
    }
    // Lines added to state.txt after its first version: KEYWORD and
    // @p n values (hexfloat), or absent in older checkpoints, which then
    // leaves the stream where it was and returns nothing.
    const auto optional_line =
      [&in, &text](const std::string &keyword, const unsigned int n)
    {
      std::vector<double> values;
      const auto          position = in.tellg();
      if (in >> text && text == keyword)
        for (unsigned int k = 0; k < n && in >> text; ++k)
          values.push_back(std::strtod(text.c_str(), nullptr));
      if (values.size() != n)
      {
        values.clear();
        in.clear();
        in.seekg(position);
      }
      return values;
    };
    // Absent from checkpoints written before Adaptivity/Every steps = auto:
    // the next adaptation then comes a little later than it would have.
    const auto travel = optional_line("grain_travel", 1);
    grain_travel      = travel.empty() ? 0 : travel[0];
    // Absent before Adaptivity/Band lookahead: the band then lasts until
    // the grains have travelled its allowance.
    const auto lookahead = optional_line("band_lookahead", 4);
    if (!lookahead.empty())
    {
      if (adaptivity)
        adaptivity->set_lookahead_horizon(lookahead[0]);
      band_made_at = lookahead[1];
      if (grains)
        grains->straight_path_drift() = {lookahead[2], lookahead[3]};
    }
    // Absent before momentum_exchange_drift: its books start at the resume.
    const auto exchange = optional_line("momentum_exchange", 1 + dim);
    exchanged_impulse   = exchange.empty() ? 0 : exchange[0];
    for (unsigned int d = 0; d < dim; ++d)
      exchange_imbalance[d] = exchange.empty() ? 0 : exchange[1 + d];
    statistics.load_values(in);
    AssertThrow(!in.bad(),
                dealii::ExcMessage("Checkpoint: cannot read " + directory));
    field_output->series().load(directory + "/fields_xdmf.txt");
    particle_output->series().load(directory + "/particles_xdmf.txt");

    if (grains)
    {
      // The same ranks: each its own warm-start impulses, exactly as it
      // left them. Others: every rank all of them (it uses those of its
      // contacts).
      const unsigned int n_ranks =
        dealii::Utilities::MPI::n_mpi_processes(comm);
      const unsigned int me = dealii::Utilities::MPI::this_mpi_process(comm);
      for (unsigned int r = 0; r < saved_ranks; ++r)
        if (saved_ranks != n_ranks || r == me)
        {
          std::ifstream contacts(directory + "/contacts_" + std::to_string(r) +
                                 ".txt");
          grains->load_contact_memory(contacts);
        }
    }
  }


  template <int dim>
  void
  Simulation<dim>::run()
  {
    checkpoint = std::make_unique<Checkpoint>(checkpoint_parameters,
                                              output_directory,
                                              comm);
    const std::string resume_from =
      checkpoint_parameters.resume == Checkpoint::Resume::never ?
        std::string() :
        checkpoint->newest();
    if (checkpoint_parameters.resume == Checkpoint::Resume::always &&
        resume_from.empty())
      InputLocation{parameter_file, "Checkpoint"}.fail(
        "Resume",
        "true",
        "no complete checkpoint in " + output_directory + "/checkpoints");
    int resumed_step = -1;
    if (!resume_from.empty())
    {
      std::ifstream state(resume_from + "/state.txt");
      state >> resumed_step;
      AssertThrow(state && resumed_step >= 0,
                  dealii::ExcMessage("Checkpoint: cannot read " + resume_from +
                                     "/state.txt"));
      // Before anything in the output directory is touched.
      check_saved_physics(resume_from);
    }

    // Created only now: a TimerOutput alive while a parse error unwinds
    // would print its own complaint beside the one-line message.
    timer = std::make_unique<dealii::TimerOutput>(
      comm, pcout, dealii::TimerOutput::never, dealii::TimerOutput::wall_times);
    const bool serial  = dealii::Utilities::MPI::n_mpi_processes(comm) == 1;
    bool       in_step = false;
    try
    {
      prepare_output_directory(resumed_step);
      if (resume_from.empty())
        checkpoint->discard_earlier_runs();
      setup(resume_from);
      start_time          = time;
      initial_grain_speed = grains ? grains->max_speed() : 0.0;
      last_progress_wall  = now();
      if (resume_from.empty())
      {
        postprocess(0, 0);
        maybe_write_fields(true);
      }
      record_timings();

      // Steps end exactly on End time; a last short step is allowed.
      while (time < end_time * (1 - 1e-12))
      {
        maybe_adapt_mesh();
        const double dt = next_time_step();
        ++step;
        in_step = true;
        solve_time_step_or_retry(dt);
        stop_if_not_finite();
        stop_if_speeding();
        if (tracks_grain_travel())
          grain_travel +=
            last_step * std::max(step_start_speed, statistics.get("max_speed"));
        in_step = false;
        maybe_write_fields(time >= end_time * (1 - 1e-12));
        record_timings();
        maybe_write_checkpoint();
      }
    }
    catch (const std::exception &e)
    {
      // A run that fails ends with main's one-line message; destroyed
      // here, where no exception is in flight, the timer does not add its
      // own complaint. A step that fails (a solver that does not converge,
      // grains lost) leaves what it reached as a last output to look at,
      // and says which step it was: on one rank, where the failure is
      // known to have reached every process.
      std::string message;
      if (const auto *d = dynamic_cast<const dealii::ExceptionBase *>(&e))
      {
        std::ostringstream info;
        d->print_info(info);
        message = one_line(info.str());
      }
      else if (dynamic_cast<const FluidStepFailure *>(&e) != nullptr)
        message = one_line(e.what());
      if (in_step && serial && !message.empty())
      {
        try
        {
          maybe_write_fields(true);
          message += " The last output (step " + std::to_string(step) +
                     ") holds " +
                     (dynamic_cast<const FluidStepFailure *>(&e) != nullptr ?
                        "the state the failed step started from." :
                        "the failed step.");
        }
        catch (...)
        {
        }
        std::ostringstream where;
        where << "step " << step << " (t = " << time << " s): ";
        timer.reset();
        throw std::runtime_error(where.str() + message);
      }
      timer.reset();
      throw;
    }
    print_test_row(true);
    if (test_output && dealii::Utilities::MPI::this_mpi_process(comm) == 0)
      print_test_checks(std::cout, test_checks, statistics);

    print_progress(true);
    if (largest_speed_ratio > 0)
      pdetail << "  divergence check: the fastest speed was "
              << std::setprecision(3) << largest_speed_ratio
              << " times the fastest motion the scene drives ("
              << driven_at_largest << " m/s then); a run stops at "
              << divergence_speed_factor << " times\n"
              << std::setprecision(6);
    if (capped_contact_steps > 0)
      pcout << "  note: the contact solver stopped at Contacts/Max "
            << "iterations in " << capped_contact_steps << " step"
            << (capped_contact_steps > 1 ? "s" : "")
            << " of this run (contact_converged = 0 in statistics.csv)\n";
    pcout << "  done: " << step << " steps, wall time " << now() - wall_start
          << " s; output in " << output_directory << "/\n";
    timer->print_wall_time_statistics(comm);
  }


  template <int dim>
  double
  Simulation<dim>::next_time_step() const
  {
    double dt = time_step;
    if (adaptive_time_step)
    {
      if (coupling && coupling_parameters.grain_substeps)
      {
        // Multi-rate: the fluid follows the flow, the grains sub-step
        // inside (solve_coupled_time_step).
        const double h = grains->shortest_cell_edge();
        const double v = grains->max_speed();
        if (v > 0)
          dt = std::min(dt, courant_number * h / v);
        else if (const double g = buoyant_gravity(); g > 0)
          // From rest the rule above sets no step, and the first one would
          // be the whole Time step, however far the grains then fall in it.
          // Free fall is the fastest they can start: the step in which it
          // crosses the Courant number of a cell, 1/2 g dt^2 = C h.
          dt = std::min(dt, std::sqrt(2 * courant_number * h / g));
      }
      else if (grains)
        dt = grains->stable_time_step(dt);
      if (fluid && fluid_parameters.advection)
      {
        const double u = fluid->max_velocity();
        if (u > 0)
          dt = std::min(dt, courant_number * shortest_cell_edge / u);
      }
    }
    // A step grows by at most a factor of 2 over the last: variable-step
    // BDF2 is zero-stable only below a ratio of 1 + sqrt(2), and its
    // extrapolated start (1 + w) u^n - w u^{n-1} amplifies the last step's
    // error by the ratio w. The same rule brings the step back after a
    // retry.
    if (adaptive_time_step && last_step > 0)
      dt = std::min(dt, 2 * last_step);
    // An adaptive run does not end on a sliver: what is left of the run,
    // if less than two steps, is split into two equal ones.
    const double remaining = end_time - time;
    if (adaptive_time_step && remaining > dt * (1 + 1e-6) && remaining < 2 * dt)
      dt = remaining / 2;
    return std::min(dt, remaining);
  }


  template <int dim>
  double
  Simulation<dim>::buoyant_gravity() const
  {
    const double rho = fluid_parameters.enabled ? fluid_parameters.density : 0;
    return grain_parameters.gravity.norm() *
           std::abs(1 - rho / grain_parameters.density);
  }


  template <int dim>
  void
  Simulation<dim>::solve_time_step_or_retry(const double dt)
  {
    double step_length = dt;
    for (unsigned int retry = 0;; ++retry)
    {
      try
      {
        solve_time_step(step_length);
        break;
      }
      catch (const FluidStepFailure &failure)
      {
        // Every rank fails together: the solvers' decisions rest on
        // global norms.
        if (!adaptive_time_step || retry == step_retries)
          throw;
        std::ostringstream warning;
        warning << "  warning: step " << step << ": "
                << one_line(failure.what())
                << " Taken again with half the step, " << step_length / 2
                << " s.\n";
        pcout << warning.str();
        step_length /= 2;
        statistics.set("step_retries", statistics.get("step_retries") + 1);
      }
    }
    last_step = step_length;
  }


  template <int dim>
  void
  Simulation<dim>::solve_time_step(const double dt)
  {
    unsigned int fluid_iterations = 0;
    double       new_time         = time + dt;
    if (coupling)
    {
      const GrainStepReport report =
        solve_coupled_time_step(dt, fluid_iterations);
      record_grain_step(report);
    }
    else if (fluid)
    {
      const auto stats = fluid->solve_time_step(new_time, dt);
      fluid_iterations = stats.linear_iterations;
      statistics.set("fluid_nonlinear_iterations", stats.nonlinear_iterations);
      statistics.set("fluid_residual", stats.final_residual);
      statistics.set("drag_averaged_cells", stats.drag_averaged_cells);
      preconditioner_builds += stats.preconditioner_builds;
      statistics.set("preconditioner_builds", preconditioner_builds);
    }
    if (grains && !coupling)
      record_grain_step(grains->advance(dt));
    time = new_time;
    postprocess(dt, fluid_iterations);
  }


  template <int dim>
  GrainStepReport
  Simulation<dim>::solve_coupled_time_step(const double  dt,
                                           unsigned int &fluid_iterations)
  {
    // The seed's step: grains -> solid fraction -> fluid with implicit drag
    // -> interaction force -> grain velocities with implicit drag ->
    // contacts with the drag-augmented mass -> positions.
    grains->gather();
    coupling->project(*grains);
    {
      // Grains packed beyond 1 - Minimum fluid fraction: the fluid sees the
      // minimum there. Said when it starts, counted every step.
      const unsigned int clamped = coupling->solid_fraction().n_clamped();
      statistics.set("clamped_fluid_fraction_nodes", clamped);
      if (clamped > 0 && clamped_nodes_before == 0)
      {
        pcout << "  warning: step " << step << ": the grains pack beyond "
              << "the bound of Coupling/Minimum fluid fraction at " << clamped
              << " solid-fraction node(s); the fluid sees the bound there "
              << "(column clamped_fluid_fraction_nodes)\n";
        if (dim == 2 &&
            !coupling_parameters.projection.closure_porosity.sphere_packing)
          pcout << "  (discs pack to area fractions up to 0.91: for a "
                << "packed 2D bed set Coupling/Closure porosity in 2D = "
                << "sphere packing, doc/theory.md)\n";
      }
      clamped_nodes_before = clamped;
    }
    // (Collective: decided by the layout, which every rank shares, not by
    // this rank's grains.)
    if (step == 1 &&
        grains->layout().contact_impulse != GrainPropertyLayout::absent)
    {
      // No contact impulse is known yet: a contact solve in the initial
      // fluid predicts the first, so that grains resting on each other at
      // the start are held from the first step (prepare_fluid_drag()), and
      // starts the relaxed prediction there.
      coupling->set_substep_grain_forces(*grains, *fluid, dt);
      grains->compute_free_velocities(dt);
      grains->resolve_contacts(dt);
      auto &arrays             = grains->step_arrays();
      arrays.predicted_impulse = arrays.contact_impulse;
      auto &c                  = arrays.contact;
      c.velocity               = c.start_velocity;
    }
    // (The dt column still holds the last step's, restored on resume.)
    coupling->prepare_fluid_drag(*grains, *fluid, dt, statistics.get("dt"));
    const auto stats = fluid->solve_time_step(time + dt, dt);
    fluid_iterations = stats.linear_iterations;
    statistics.set("fluid_nonlinear_iterations", stats.nonlinear_iterations);
    statistics.set("fluid_residual", stats.final_residual);
    statistics.set("drag_averaged_cells", stats.drag_averaged_cells);
    preconditioner_builds += stats.preconditioner_builds;
    statistics.set("preconditioner_builds", preconditioner_builds);
    coupling->set_grain_forces(*grains, *fluid, dt);
    grains->compute_free_velocities(dt);
    // Grains that this step would move too far take equal sub-steps
    // through its fluid; the first with the force the fluid's implicit
    // update assumed.
    const unsigned int substeps =
      coupling->grain_substeps() ? grains->substeps(dt) : 1;
    const double substep = dt / substeps;
    statistics.set("grain_substeps", substeps);
    if (substeps > 1)
      grains->compute_free_velocities(substep);
    GrainStepReport report = grains->resolve_contacts(substep);
    // Newton's third law between the phases: the drag the fluid receives
    // over the step, integrated through its own fields, against the drag
    // the grains' implicit updates received, summed over the sub-steps
    // (with more than one, the later ones re-evaluate the drag the fluid's
    // prediction assumed; the difference is owed to the fluid, and repaid
    // in the next step unless Coupling/Repay drag mismatch = false).
    const dealii::Tensor<1, dim> on_fluid =
      coupling->drag_on_fluid(*grains, *fluid);
    dealii::Tensor<1, dim> on_grains =
      coupling->account_drag_on_grains(*grains, substep);
    dealii::Tensor<1, dim> owed;
    if (substeps == 1)
      owed = coupling->settle_exchange_owed(*grains);
    report.removed = grains->move_and_scatter(substep);
    for (unsigned int k = 1; k < substeps; ++k)
    {
      grains->gather();
      coupling->set_substep_grain_forces(*grains, *fluid, substep);
      grains->compute_free_velocities(substep);
      GrainStepReport later = grains->resolve_contacts(substep, true);
      on_grains += coupling->account_drag_on_grains(*grains, substep);
      if (k + 1 == substeps)
        owed = coupling->settle_exchange_owed(*grains);
      later.removed = grains->move_and_scatter(substep);
      report.add_substep(later);
    }
    // The step's mean drag on the grains.
    on_grains /= substeps;
    statistics.set("drag_force_on_grains", on_grains.norm());
    const double exchanged = dt * on_grains.norm();
    statistics.set("momentum_exchange_error",
                   exchanged > 0 ?
                     (on_fluid + on_grains).norm() / on_grains.norm() :
                     0.0);
    statistics.set("momentum_exchange_owed",
                   exchanged > 0 ? owed.norm() / exchanged : 0.0);
    exchange_imbalance += dt * (on_fluid + on_grains);
    exchanged_impulse += exchanged;
    statistics.set("momentum_exchange_drift",
                   exchanged_impulse > 0 ?
                     (exchange_imbalance - owed).norm() / exchanged_impulse :
                     0.0);
    return report;
  }


  template <int dim>
  void
  Simulation<dim>::record_grain_step(const GrainStepReport &report)
  {
    {
      const auto &c = report.contacts;
      statistics.set("max_overlap", c.max_overlap);
      statistics.set("contacts", c.n_active);
      statistics.set("contact_iterations", c.iterations);
      statistics.set("contact_residual", c.residual);
      statistics.set("contact_converged", c.converged);
      statistics.set("max_contact_force", report.max_contact_force);
      statistics.set("alert_distance", report.alert_distance);
      // A deep bed can meet the cap on many steps: the first few are
      // worth a line each, the rest a count at the end and the column
      // contact_converged.
      constexpr unsigned int warnings_shown = 5;
      if (!c.converged && grain_parameters.contacts_enabled &&
          ++capped_contact_steps <= warnings_shown)
        pcout << "  warning: step " << step << ": the contact solver stopped "
              << "after " << c.iterations << " sweeps, residual " << c.residual
              << ", overlap " << c.max_overlap << " m"
              << (capped_contact_steps == warnings_shown ?
                    " (no more such lines; contact_converged = 0 in "
                    "statistics.csv marks every such step)" :
                    "")
              << "\n";
    }
  }


  template <int dim>
  void
  Simulation<dim>::postprocess(const double       dt,
                               const unsigned int fluid_iterations)
  {
    dealii::TimerOutput::Scope scope(*timer, "statistics");
    statistics.set("step", step);
    statistics.set("time", time);
    statistics.set("dt", dt);
    statistics.set("cells", triangulation.n_global_active_cells());
    statistics.set("load_imbalance",
                   load_balance ? load_balance->imbalance() : 1.0);
    statistics.set("fluid_iterations", fluid_iterations);
    if (fluid)
    {
      double volume = 1;
      for (unsigned int d = 0; d < dim; ++d)
        volume *= geometry.upper_corner[d] - geometry.lower_corner[d];
      // The coupling knows its fluid fraction node by node; prescribed
      // fields are integrated by quadrature.
      const double fluid_volume = coupling && coupling_parameters.two_way ?
                                    coupling->fluid_volume() :
                                    fluid->integrate_fluid_fraction();
      statistics.set("dofs", fluid->n_dofs());
      statistics.set("fluid_volume", fluid_volume);
      if (!pressure_drop_points.empty())
        statistics.set("pressure_drop",
                       fluid->pressure_at(pressure_drop_points[0]) -
                         fluid->pressure_at(pressure_drop_points[1]));
      statistics.set("solid_volume",
                     coupling ? coupling->solid_volume() :
                                volume - fluid_volume);
    }
    if (grains)
      set_grain_statistics();
    statistics.set("wall_time", now() - wall_start);
    statistics.write_row();

    print_test_row(false);
    pdetail << "step " << step << " t=" << time << " dt=" << dt;
    if (fluid)
      pdetail << " fluid iterations=" << fluid_iterations;
    if (grains)
      pdetail << " grains=" << statistics.get("particles")
              << " contacts=" << statistics.get("contacts")
              << " sweeps=" << statistics.get("contact_iterations")
              << " Ekin=" << statistics.get("kinetic_energy");
    pdetail << '\n';
    print_progress(false);
  }


  template <int dim>
  void
  Simulation<dim>::print_progress(const bool last)
  {
    if (quiet || verbose || dealii::Utilities::MPI::this_mpi_process(comm) != 0)
      return;
    const double wall     = now();
    const double interval = log.on_terminal() ? 0.25 : progress_interval;
    if (!last && (interval <= 0 || wall - last_progress_wall < interval))
      return;
    if (last && !log.on_terminal() && wall - last_progress_wall < 1)
      return; // the last line written is recent enough
    last_progress_wall = wall;

    // The remaining wall time, from the pace of this run so far.
    const double       done    = time - start_time;
    const double       elapsed = wall - wall_start;
    std::ostringstream line;
    line << std::setprecision(3) << "t = " << time << " / " << end_time
         << " s, step " << step;
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
    line << std::fixed << std::setprecision(0) << ", wall " << elapsed << " s";
    if (!last && done > 0 && end_time > time)
      line << ", ETA " << elapsed * (end_time - time) / done << " s";
    log.progress(line.str());
  }


  template <int dim>
  void
  Simulation<dim>::set_grain_statistics()
  {
    const GrainStatistics<dim> s      = grains->compute_statistics();
    const char                *axes[] = {"x", "y", "z"};
    statistics.set("particles", s.n_grains);
    if (!fluid)
      statistics.set("solid_volume", s.solid_volume);
    if (coupling && s.solid_volume > 0)
    {
      // Conservation of the projection: what the fluid sees against what
      // the grains are.
      statistics.set("solid_volume_error",
                     std::abs(statistics.get("solid_volume") - s.solid_volume) /
                       s.solid_volume);
      statistics.set("max_reynolds", coupling->max_reynolds());
    }
    for (unsigned int d = 0; d < dim; ++d)
    {
      statistics.set(std::string("centroid_") + axes[d], s.centroid[d]);
      statistics.set(std::string("mean_velocity_") + axes[d],
                     s.mean_velocity[d]);
    }
    statistics.set("fixed_particles", s.n_fixed);
    for (unsigned int d = 0; d < dim; ++d)
      statistics.set(std::string("fixed_centroid_") + axes[d],
                     s.fixed_centroid[d]);
    statistics.set("max_speed", s.max_speed);
    statistics.set("kinetic_energy", s.kinetic_energy);
    statistics.set("packing_fraction", s.packing_fraction);
    statistics.set("grains_removed", grains->n_removed());
    if (cloud_analysis)
      set_cloud_statistics();
  }


  template <int dim>
  void
  Simulation<dim>::set_cloud_statistics()
  {
    const CloudMeasures<dim> m =
      cloud_analysis->analyse(grains->particle_handler(),
                              grains->layout(),
                              2 * largest_grain_radius);
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
    if (m.n_clusters > cloud_parameters.placed_clouds &&
        statistics.get("breakup_time") < 0)
    {
      statistics.set("breakup_time", time);
      pcout << "The cloud has broken up at t = " << time << " s (step " << step
            << "): " << m.n_clusters << " clusters of at least "
            << cloud_parameters.minimum_cluster_fraction * 100
            << " % of the grains each, " << m.n_leaked
            << " grains outside the largest\n";
    }
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
    const double wall = now();
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


  template <int dim>
  void
  Simulation<dim>::stop_if_not_finite()
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
      !grains || (std::isfinite(statistics.get("kinetic_energy")) &&
                  (statistics.get("particles") == 0 ||
                   std::isfinite(statistics.get("centroid_x"))));
    if (fluid_finite && grains_finite)
      return;

    std::string        field;
    dealii::Point<dim> where;
    bool               found = false;
    if (!fluid_finite)
      visit_fluid_values(
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
    std::ostringstream text;
    if (teller == n_ranks)
      text << "a global sum of the fluid or of the grains";
    else
    {
      text << "the " << field << " near (";
      for (unsigned int d = 0; d < dim; ++d)
        text << (d > 0 ? ", " : "") << where[d];
      text << ")";
    }
    const std::string place =
      dealii::Utilities::MPI::broadcast(comm,
                                        text.str(),
                                        teller == n_ranks ? 0 : teller);
    stop_run(place +
             " is not finite (NaN or Inf); the run diverged there. The last "
             "output (step " +
             std::to_string(step) +
             ") holds it; a shorter Time step, or Adaptive time step = "
             "true, usually keeps it finite.");
  }


  template <int dim>
  void
  Simulation<dim>::visit_fluid_values(
    const std::function<bool(const dealii::Point<dim> &, bool, double)> &visit)
    const
  {
    const auto &dof_handler = fluid->get_dof_handler();
    const auto &solution    = fluid->get_solution();
    const auto &fe          = dof_handler.get_fe();
    std::vector<dealii::types::global_dof_index> indices(fe.n_dofs_per_cell());
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
  void
  Simulation<dim>::stop_run(const std::string &what)
  {
    maybe_write_fields(true);
    std::ostringstream message;
    message << "step " << step << " (t = " << time << " s): " << what;
    throw std::runtime_error(message.str());
  }


  template <int dim>
  double
  Simulation<dim>::driven_speed() const
  {
    const auto  &g    = grain_parameters.gravity;
    double       drop = 0; // the box's extent along gravity
    const double norm = g.norm();
    for (unsigned int d = 0; d < dim && norm > 0; ++d)
      drop += std::abs(g[d]) / norm *
              (geometry.upper_corner[d] - geometry.lower_corner[d]);
    return std::max({std::sqrt(2 * norm * drop),
                     initial_grain_speed,
                     fluid ? fluid->driven_speed() : 0.0});
  }


  template <int dim>
  void
  Simulation<dim>::stop_if_speeding()
  {
    if (divergence_speed_factor <= 0)
      return;
    const double fluid_speed = fluid ? fluid->max_velocity() : 0.0;
    const double grain_speed = grains ? statistics.get("max_speed") : 0.0;
    const double speed       = std::max(fluid_speed, grain_speed);
    if (speed == 0)
      return;
    const double driven = driven_speed();
    // Nothing drives any motion: there is no scale to compare with.
    if (driven <= 0)
      return;
    if (speed / driven > largest_speed_ratio)
    {
      largest_speed_ratio = speed / driven;
      driven_at_largest   = driven;
    }
    if (speed <= divergence_speed_factor * driven)
      return;

    // Where: the cell of the fastest fluid node, or the fastest grain.
    double             local_max = 0;
    dealii::Point<dim> where;
    const bool         in_fluid = fluid_speed >= grain_speed;
    if (in_fluid)
      visit_fluid_values(
        [&](const dealii::Point<dim> &centre, const bool velocity, double value)
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
         << " speed reached " << speed << " m/s near (";
    for (unsigned int d = 0; d < dim; ++d)
      text << (d > 0 ? ", " : "") << where[d];
    text << "), over " << divergence_speed_factor
         << " times the fastest motion the scene drives (" << driven
         << " m/s: free fall across the box, boundary, initial and "
            "prescribed velocities, forcing); the run is exploding. The last "
            "output (step "
         << step
         << ") holds it. The usual causes: cells too coarse for the flow "
            "(its cell Reynolds number), a step too long (Courant number, "
            "Time step). Divergence speed factor sets the bound (0: off).";
    stop_run(text.str());
  }


  template <int dim>
  void
  Simulation<dim>::maybe_write_fields(const bool force)
  {
    if (!force && (write_fields_every == 0 || step % write_fields_every != 0))
      return;
    dealii::TimerOutput::Scope scope(*timer, "output");
    if (fluid)
      field_output->write(triangulation,
                          time,
                          step,
                          [this](dealii::DataOut<dim> &d)
                          { fluid->add_data_vectors(d); });
    if (grains)
      particle_output->write(grains->particle_handler(),
                             grains->layout().names,
                             grains->layout().interpretations,
                             time,
                             step);
  }


  template class Simulation<2>;
  template class Simulation<3>;
} // namespace ImmersedGrains
