#include <deal.II/base/mpi.h>
#include <deal.II/base/utilities.h>

#include <immersed_grains/coupling/coupled_step.h>
#include <immersed_grains/fluid/fluid_solver.h>
#include <immersed_grains/grains/grains.h>
#include <immersed_grains/io/field_output.h>
#include <immersed_grains/io/grain_file.h>
#include <immersed_grains/io/particle_output.h>
#include <immersed_grains/io/progress_line.h>
#include <immersed_grains/simulation.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <tuple>
#include <utility>

namespace ImmersedGrains
{
  namespace
  {
    // The step a checkpoint holds (the first entry of its state.txt).
    int
    step_of(const std::string &checkpoint_directory)
    {
      std::ifstream state(checkpoint_directory + "/state.txt");
      int           step = -1;
      state >> step;
      AssertThrow(state && step >= 0,
                  dealii::ExcMessage("Checkpoint: cannot read " +
                                     checkpoint_directory + "/state.txt"));
      return step;
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
    DivergenceGuard<dim>::declare_parameters(prm);

    prm.enter_subsection("Output");
    {
      prm.declare_entry("Write fields every",
                        "0",
                        Integer(0),
                        "Write the fields and the grains every this many "
                        "steps (0: only the initial and the final state).");
      prm.declare_entry(
        "Write grain file",
        "false",
        Bool(),
        "At the end of the run, write every grain to grains.txt in the "
        "output directory, a line 'x y [z] r vx vy [vz]' each, the format "
        "Grains/Placement/Shape = file reads: a packing one run prepares is "
        "the initial state of the next.");
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
                        "b]'; max(column) or min(column) for its extreme "
                        "over the rows the run wrote.");
      prm.declare_entry(
        "Boundary forces",
        "",
        Anything(),
        "Boundary ids (comma list) whose force from the fluid is recorded: "
        "columns boundary_force_<id>_x, _y[, _z], the integral of -phi "
        "sigma n over those faces [N; N/m in 2D], sigma = -p I + mu (grad u "
        "+ grad u^T) with p the pressure without its hydrostatic part, n "
        "the fluid's outward normal. An id that meets no other boundary "
        "with a given velocity (an obstacle) gets the reaction of the "
        "discrete momentum equation, which converges with the flow's "
        "order; others the traction integrated over the faces.");
      prm.declare_entry(
        "Boundary contact forces",
        "",
        Anything(),
        "Boundary ids (comma list) whose force from the grains' contacts is "
        "recorded: columns boundary_contact_force_<id>_x, _y[, _z] [N; N/m "
        "in 2D], the impulse the contacts of a fluid step (all its grain "
        "sub-steps) gave those faces, normal and tangential, divided by the "
        "step. A bed at rest on a floor weighs on it with its weight less "
        "what the liquid and the side walls carry. Ids of wall, slip or "
        "inflow boundaries (those the grains meet), with contacts on.");
      prm.declare_entry(
        "Boundary fluxes",
        "",
        Anything(),
        "Boundary ids (comma list) whose fluid volume flux is recorded: "
        "columns boundary_flux_<id>, the integral of phi u.n over those "
        "faces [m^3/s; m^2/s in 2D], n the outward normal (negative "
        "through an inflow).");
      prm.declare_entry(
        "Probes",
        "",
        Anything(),
        "Named points 'name: x, y[, z]' separated by ';': columns "
        "probe_<name>_pressure (the pressure without its hydrostatic part, "
        "Pa) and probe_<name>_solid_fraction (1 - phi) there.");
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
      , statistics(statistics_columns())
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
      , wall_start(wall_clock())
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
    adaptive_time_step = prm.get_bool("Adaptive time step");
    courant_number     = prm.get_double("Courant number");
    divergence_guard.parse_parameters(prm);
    step_retries = prm.get_integer("Step retries");
    top.require(courant_number > 0 || !adaptive_time_step,
                "Courant number",
                prm.get("Courant number"),
                "must be positive with Adaptive time step");

    // Before Output: its Test columns and Test checks may name the size
    // classes' columns.
    grain_parameters.parse_parameters(prm, file);
    statistics.add_columns(
      GrainStatistics<dim>::class_column_names(grain_parameters.n_classes()));

    prm.enter_subsection("Output");
    {
      const InputLocation where{file, "Output"};
      write_fields_every      = prm.get_integer("Write fields every");
      write_grain_file_at_end = prm.get_bool("Write grain file");
      output_format =
        prm.get("Format") == "hdf5" ? OutputFormat::hdf5 : OutputFormat::vtu;
      const std::string mode = prm.get("Terminal output");
      test_output            = mode == "test";
      quiet                  = mode != "normal" && mode != "verbose";
      verbose                = mode == "verbose";
      progress_interval      = prm.get_double("Progress every seconds");
      progress               = std::make_unique<ProgressLine>(
        log,
        progress_interval,
        !quiet && !verbose &&
          dealii::Utilities::MPI::this_mpi_process(comm) == 0);
      parse_output_points(prm, where);
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
      InputLocation{file, "Output"}.require(geometry.contains(point),
                                            "Pressure drop points",
                                            pressure_drop_text,
                                            "a point lies outside the mesh");
    const std::tuple<const char *,
                     const std::vector<dealii::types::boundary_id> *,
                     const std::string *>
      boundary_outputs[] = {
        {"Boundary forces", &boundary_force_ids, &boundary_force_text},
        {"Boundary fluxes", &boundary_flux_ids, &boundary_flux_text}};
    for (const auto &[name, ids, text] : boundary_outputs)
      for (const auto id : *ids)
        InputLocation{file, "Output"}.require(
          geometry.boundary_types.count(id) == 1,
          name,
          *text,
          "boundary id " + std::to_string(id) + " is not on the mesh");
    for (const auto id : boundary_contact_force_ids)
    {
      const auto type = geometry.boundary_types.find(id);
      InputLocation{file, "Output"}.require(
        type != geometry.boundary_types.end(),
        "Boundary contact forces",
        boundary_contact_force_text,
        "boundary id " + std::to_string(id) + " is not on the mesh");
      InputLocation{file, "Output"}.require(
        type->second != BoundaryType::open &&
          type->second != BoundaryType::periodic,
        "Boundary contact forces",
        boundary_contact_force_text,
        "boundary id " + std::to_string(id) +
          " is open or periodic: grains do not meet it");
    }
    InputLocation{file, "Output"}.require(
      boundary_contact_force_ids.empty() ||
        (grain_parameters.enabled && grain_parameters.contacts_enabled),
      "Boundary contact forces",
      boundary_contact_force_text,
      "needs grains with contacts (Grains/Enabled, Contacts/Enabled)");
    for (const auto &[name, point] : probes)
      InputLocation{file, "Output"}.require(geometry.contains(point),
                                            "Probes",
                                            probe_text,
                                            "probe '" + name +
                                              "' lies outside the mesh");
    fluid_parameters.parse_parameters(prm, file, geometry);
    // Each of these outputs is a field of the fluid's.
    for (const auto &[name, text] :
         {std::pair{"Boundary forces", &boundary_force_text},
          std::pair{"Boundary fluxes", &boundary_flux_text},
          std::pair{"Probes", &probe_text}})
      InputLocation{file, "Output"}.require(
        fluid_parameters.enabled || dealii::Utilities::trim(*text).empty(),
        name,
        *text,
        "needs the fluid (Fluid/Enabled = true)");
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
    // An 'auto' correction: the rule of Coupling::Parameters, on in 3D with
    // the cell spread, applied again now that 'auto' has become a choice.
    prm.enter_subsection("Coupling");
    if (prm.get("Self-disturbance correction") == "auto")
      coupling_parameters.self_correction =
        dim == 3 && coupling_parameters.drag_distribution == "cell";
    prm.leave_subsection();

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
    if (resumed_step < 0)
      checkpoint->discard_earlier_runs();
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
    if (!geometry.is_box())
      pcout << " (" << geometry.mesh_file << ")";
    for (const auto &[id, type] : geometry.boundary_types)
      pcout << (geometry.is_box() ? " " : " " + std::to_string(id) + ": ")
            << to_string(type);
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
      if (!boundary_contact_force_ids.empty())
        grains->record_boundary_contact_forces();
      const auto &c = grain_parameters.contact;
      pcout << "  grains: " << grains->particle_handler().n_global_particles()
            << ", " << grains->layout().n_properties << " properties per grain";
      if (grain_parameters.contacts_enabled)
      {
        pcout << "; contacts: e = " << c.restitution << ", mu = " << c.friction;
        if (c.rolling_friction > 0)
          pcout << ", rolling mu_r = " << c.rolling_friction;
        pcout << ", tolerance " << c.tolerance;
      }
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
      coupling->set_fraction_rate(fluid_parameters.advection &&
                                  fluid_parameters.skew_symmetric_advection);
      coupling->attach(*fluid);
      coupling->project(*grains);
      if (!coupled_step)
        coupled_step = std::make_unique<CoupledStep<dim>>(
          pcout,
          coupling_parameters.projection.closure_porosity.sphere_packing);
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
    {
      load_state(resume_from);
      // The last row's measures, as the run being resumed had them.
      if (grains)
        grain_statistics =
          std::make_unique<GrainStatistics<dim>>(grains->compute_statistics());
    }
    else
      maybe_adapt_mesh();
  }


  template <int dim>
  void
  Simulation<dim>::run()
  {
    const std::string resume_from = resume_point();
    // Created only now: a TimerOutput alive while a parse error unwinds
    // would print its own complaint beside the one-line message.
    // Each rank times its own phases; the summary gathers them once at the
    // end (print_wall_time_statistics). Given the communicator, every
    // section's entry and exit would be a barrier and a reduction, which
    // the grains' sub-steps enter tens of thousands of times
    // (doc/performance.md, "Two ranks").
    timer =
      std::make_unique<dealii::TimerOutput>(pcout,
                                            dealii::TimerOutput::never,
                                            dealii::TimerOutput::wall_times);
    bool in_step = false;
    try
    {
      start(resume_from);
      while (!finished())
      {
        maybe_adapt_mesh();
        const double dt = next_time_step();
        ++step;
        in_step = true;
        solve_time_step_or_retry(dt);
        stop_if_diverging();
        track_grain_travel();
        in_step = false;
        maybe_write_fields(finished());
        record_timings();
        maybe_write_checkpoint();
      }
      if (grains && write_grain_file_at_end)
        write_grain_file(*grains, output_directory + "/grains.txt", time, comm);
    }
    catch (const std::exception &e)
    {
      rethrow_failure(e, in_step);
    }
    print_summary();
  }


  template <int dim>
  std::string
  Simulation<dim>::resume_point()
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
    // Before anything in the output directory is touched.
    if (!resume_from.empty())
    {
      step_of(resume_from);
      check_saved_physics(resume_from);
    }
    return resume_from;
  }


  template <int dim>
  void
  Simulation<dim>::start(const std::string &resume_from)
  {
    prepare_output_directory(resume_from.empty() ? -1 : step_of(resume_from));
    setup(resume_from);
    start_time = time;
    // The scales a diverging run is told by: free fall across the domain
    // along gravity and the grains' initial speeds.
    const auto  &g           = grain_parameters.gravity;
    double       fall_height = 0;
    const double norm        = g.norm();
    for (unsigned int d = 0; d < dim && norm > 0; ++d)
      fall_height += std::abs(g[d]) / norm *
                     (geometry.upper_corner[d] - geometry.lower_corner[d]);
    divergence_guard.start(g,
                           fall_height,
                           grains ? grains->max_speed() : 0.0,
                           comm);
    progress->start(wall_start, start_time);
    if (resume_from.empty())
    {
      postprocess(0);
      maybe_write_fields(true);
    }
    record_timings();
  }


  template <int dim>
  bool
  Simulation<dim>::finished() const
  {
    // Steps end exactly on End time; a last short step is allowed.
    return time >= end_time * (1 - 1e-12);
  }


  template <int dim>
  [[noreturn]] void
  Simulation<dim>::rethrow_failure(const std::exception &e, const bool in_step)
  {
    // A run that fails ends with main's one-line message; destroyed
    // here, where no exception is in flight, the timer does not add its
    // own complaint. A step that fails (a solver that does not converge,
    // grains lost) leaves what it reached as a last output to look at,
    // and says which step it was: on one rank, where the failure is
    // known to have reached every process.
    const bool  serial = dealii::Utilities::MPI::n_mpi_processes(comm) == 1;
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


  template <int dim>
  void
  Simulation<dim>::print_summary()
  {
    print_test_row(true);
    if (test_output && dealii::Utilities::MPI::this_mpi_process(comm) == 0)
      print_test_checks(std::cout, test_checks, statistics);
    print_progress(true);
    divergence_guard.print_summary(pdetail);
    if (capped_contact_steps > 0)
      pcout << "  note: the contact solver stopped at Contacts/Max "
            << "iterations in " << capped_contact_steps << " step"
            << (capped_contact_steps > 1 ? "s" : "")
            << " of this run (contact_converged = 0 in statistics.csv)\n";
    if (grains)
    {
      const auto [solves, searches] = grains->neighbour_searches();
      if (solves > 0)
        pcout << "  contacts: " << solves << " solves, " << searches
              << " of them searched for grain pairs anew (the others kept "
              << "the neighbour list)\n";
    }
    pcout << "  done: " << step << " steps, wall time "
          << wall_clock() - wall_start << " s; output in " << output_directory
          << "/\n";
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
        // inside (CoupledStep::advance()).
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
        ++retries_taken;
      }
    }
    last_step = step_length;
  }


  template <int dim>
  void
  Simulation<dim>::solve_time_step(const double dt)
  {
    if (coupling)
    {
      const CoupledStepReport<dim> report = coupled_step->advance(
        *coupling, *fluid, *grains, time, dt, previous_step, step == 1, step);
      preconditioner_builds += report.fluid.preconditioner_builds;
      report.fluid.set_statistics(statistics, preconditioner_builds);
      CoupledStep<dim>::set_statistics(report, statistics);
      record_contacts(report.grains);
    }
    else
    {
      if (fluid)
      {
        const auto report = fluid->solve_time_step(time + dt, dt);
        preconditioner_builds += report.preconditioner_builds;
        report.set_statistics(statistics, preconditioner_builds);
      }
      if (grains)
        record_contacts(grains->advance(dt));
    }
    time += dt;
    previous_step = dt;
    postprocess(dt);
  }


  template <int dim>
  void
  Simulation<dim>::record_contacts(const GrainStepReport &report)
  {
    report.set_statistics(statistics);
    // A deep bed can meet the cap on many steps: the first few are
    // worth a line each, the rest a count at the end and the column
    // contact_converged.
    constexpr unsigned int warnings_shown = 5;
    const auto            &c              = report.contacts;
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


  template <int dim>
  void
  Simulation<dim>::stop_if_diverging()
  {
    std::string problem = divergence_guard.find_not_finite(
      fluid.get(), grains.get(), grain_statistics.get(), step);
    if (problem.empty())
      problem = divergence_guard.find_speeding(fluid.get(),
                                               grains.get(),
                                               grain_statistics.get(),
                                               step);
    if (!problem.empty())
      stop_run(problem);
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
