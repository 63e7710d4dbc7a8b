// Simulation<dim>::regime() and print_check(): what a scene is, in the
// numbers that decide which physics it needs, and where its choices leave
// the range the model is validated for (doc/validation.md); and
// choose_drag_distribution(), which picks the validated one.
#include <immersed_grains/box_buckets.h>
#include <immersed_grains/coupling/drag_law.h>
#include <immersed_grains/grains/periodic_span.h>
#include <immersed_grains/parameters.h>
#include <immersed_grains/simulation.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>

namespace ImmersedGrains
{
  namespace
  {
    std::string
    number(const double x, const int digits = 3)
    {
      std::ostringstream s;
      s << std::setprecision(digits) << x;
      return s.str();
    }


    /**
     * Grains placed at random in a box that spans a periodic axis of a box
     * domain: a suspension homogeneous across the periodic faces, the
     * scene the filtered and the cell-spread drag were measured on in 3D
     * (doc/validation.md, "Hindered settling").
     */
    template <int dim>
    bool
    placed_as_suspension(const GrainParameters<dim> &grains,
                         const Geometry<dim>        &geometry)
    {
      if (grains.shape != PlacementShape::box)
        return false;
      // Each centre is filled as its own box, as placement.cc does.
      for (const auto &center : grains.centers)
        for (unsigned int d = 0; d < dim; ++d)
          if (spans_periodic_axis(geometry, center, grains.size, d))
            return true;
      return false;
    }


    /**
     * Placed discs that touch this many neighbours each on average, or more,
     * are a packing (mean_touching_neighbours()).
     */
    constexpr double packed_neighbours = 2;


    /**
     * The mean number of neighbours each grain touches, counting as touching
     * two grains whose gap is below 5 % of their radii's sum: about 3-4 in a
     * packing that has settled, below 1 for grains placed at random even at
     * solid fraction 0.5.
     */
    template <int dim>
    double
    mean_touching_neighbours(const std::vector<GrainSeed<dim>> &seeds)
    {
      if (seeds.size() < 2)
        return 0;
      constexpr double                      gap = 0.05;
      std::vector<dealii::BoundingBox<dim>> boxes;
      boxes.reserve(seeds.size());
      dealii::Point<dim> lower = seeds[0].position, upper = lower;
      double             largest = 0;
      for (const auto &seed : seeds)
      {
        dealii::Point<dim> a = seed.position, b = seed.position;
        for (unsigned int d = 0; d < dim; ++d)
        {
          a[d] -= (1 + gap) * seed.radius;
          b[d] += (1 + gap) * seed.radius;
          lower[d] = std::min(lower[d], a[d]);
          upper[d] = std::max(upper[d], b[d]);
        }
        boxes.emplace_back(std::make_pair(a, b));
        largest = std::max(largest, seed.radius);
      }
      BoxBuckets<dim> buckets;
      buckets.reinit(lower, upper, 2 * (1 + gap) * largest, boxes);
      std::vector<unsigned int> near;
      std::size_t               touching = 0;
      for (unsigned int i = 0; i < seeds.size(); ++i)
      {
        buckets.near(seeds[i].position, (1 + gap) * seeds[i].radius, near);
        for (const unsigned int j : near)
          if (j != i && seeds[i].position.distance(seeds[j].position) <
                          (1 + gap) * (seeds[i].radius + seeds[j].radius))
            ++touching;
      }
      return static_cast<double>(touching) / seeds.size();
    }
  } // namespace


  template <int dim>
  SceneRegime
  Simulation<dim>::regime() const
  {
    SceneRegime regime;
    auto        line = [&](const std::string &name,
                    const std::string &value,
                    const std::string &meaning)
    {
      regime.lines.push_back(name + ": " + value +
                             (meaning.empty() ? "" : " (" + meaning + ")"));
    };

    // The finest cell the scene will have.
    const unsigned int levels = adaptivity_parameters.enabled ?
                                  adaptivity_parameters.max_level :
                                  geometry.initial_refinement;
    const double       h      = geometry.shortest_cell_edge(levels);
    line("finest cell", number(h) + " m", "");

    const bool   with_fluid  = fluid_parameters.enabled;
    const bool   with_grains = grain_parameters.enabled;
    const double r =
      mean_grain_radius > 0 ? mean_grain_radius : grain_parameters.radius;
    const double rho     = fluid_parameters.density;
    const double mu      = fluid_parameters.viscosity;
    const double g       = grain_parameters.gravity.norm();
    const double d       = 2 * r;
    const double l       = coupling_parameters.projection.smoothing_length;
    const bool   coupled = with_fluid && with_grains;
    const bool   two_way = coupled && coupling_parameters.two_way;

    double reynolds = 0, cloud_reynolds = 0;
    if (with_grains)
    {
      line("grains",
           std::to_string(placed_grains) + ", mean radius " + number(r) + " m",
           "");
      line("cell / grain diameter", number(h / d), "");
    }
    if (coupled && g > 0)
    {
      // The lone grain's terminal velocity under the scene's drag law.
      const auto   law    = DragLaw::create(coupling_parameters.drag_law);
      const double volume = grain_volume<dim>(r);
      const double area   = grain_projected_area<dim>(r);
      const double mass   = grain_parameters.density * volume;
      const double weight =
        std::abs(grain_parameters.density - rho) * volume * g;
      double U = 0, gamma = 0;
      for (unsigned int k = 0; k < 200; ++k)
      {
        gamma = law->coefficient({r, area, volume, 1.0, U, rho, mu});
        const double next = weight / gamma;
        if (std::abs(next - U) <= 1e-12 * next)
          break;
        U = 0.5 * (U + next);
      }
      const double tau = mass / gamma;
      reynolds         = 2 * r * rho * U / mu;
      line("lone grain's terminal velocity",
           number(U) + " m/s",
           "its drag law");
      line("grain Reynolds number", number(reynolds), "2 r rho U / mu");
      line("grain relaxation time", number(tau) + " s", "tau_p = m / gamma");
      line("Stokes number", number(tau * U / d), "tau_p U / d");
      line("time step / tau_p",
           number(time_step / tau),
           adaptive_time_step ? "the first step; later ones follow the flow" :
                                "");
      if (coupling_parameters.drag_distribution == "filtered" && l > 0)
        line("cell / filter length", number(h / l), "");
      if (grain_parameters.shape == PlacementShape::ball &&
          !grain_parameters.size.empty())
      {
        const double R = grain_parameters.size[0];
        if (dim == 3)
        {
          // The Hadamard-Rybczynski drop of the cloud's excess density,
          // its interior as viscous as the liquid.
          const double excess = grain_parameters.solid_fraction *
                                std::abs(grain_parameters.density - rho);
          const double cloud_velocity = 4. / 15 * excess * g * R * R / mu;
          cloud_reynolds              = rho * cloud_velocity * R / mu;
          line("cloud Reynolds number",
               number(cloud_reynolds),
               "rho U R / mu with the Hadamard-Rybczynski U = " +
                 number(cloud_velocity) + " m/s");
        }
        else
          line("cloud Reynolds number",
               "not estimated in 2D",
               "a 2D cloud's velocity depends on the box; statistics.csv "
               "has cloud_velocity_y");
      }
    }

    // What is on and off.
    auto on = [](const bool b) { return std::string(b ? "on" : "off"); };
    if (with_fluid)
    {
      std::string why;
      // A 2D cloud's Reynolds number is not estimated: no advice there.
      const bool cloud_unknown =
        dim == 2 && grain_parameters.shape == PlacementShape::ball;
      if (fluid_parameters.advection && coupled && !cloud_unknown &&
          std::max(reynolds, cloud_reynolds) < 1e-3)
        why = "; the flow is Stokes here (Reynolds numbers below 1e-3): "
              "Advection = false gives the same answer for less";
      regime.switches.push_back(
        "fluid: " +
        std::string(fluid_parameters.advection ? "Navier-Stokes" : "Stokes") +
        (fluid_parameters.time_derivative ? ", unsteady" : ", steady") + why);
    }
    else
      regime.switches.push_back("fluid: off (grains in vacuum)");
    if (with_grains)
      regime.switches.push_back(
        "contacts: " + on(grain_parameters.contacts_enabled) +
        (grain_parameters.contacts_enabled ?
           ", friction " + number(grain_parameters.contact.friction) :
           std::string()));
    if (coupled)
      regime.switches.push_back(
        "coupling: " +
        std::string(coupling_parameters.tracers ?
                      "tracers" :
                      (two_way ? "two-way" : "one-way")) +
        ", drag law " + coupling_parameters.drag_law + ", drag distribution " +
        coupling_parameters.drag_distribution +
        (drag_distribution_choice.empty() ?
           std::string() :
           " (auto: " + drag_distribution_choice + ")") +
        ", self-disturbance correction " +
        on(coupling_parameters.self_correction) + ", grain sub-steps " +
        on(coupling_parameters.grain_substeps) +
        (dim == 2 ?
           std::string(", closure porosity ") +
             (coupling_parameters.projection.closure_porosity.sphere_packing ?
                "of the sphere packing" :
                "the area fraction") :
           std::string()));
    regime.switches.push_back(
      "adaptivity: " + on(adaptivity_parameters.enabled) +
      "; adaptive time step: " + on(adaptive_time_step));

    // Outside the validated range (doc/validation.md).
    const bool spread_in_cells =
      coupling_parameters.drag_distribution != "filtered";
    if (two_way && dim == 3 && spread_in_cells &&
        !coupling_parameters.self_correction && h < 8 * d)
      regime.warnings.push_back(
        "cells of " + number(h / d, 2) +
        " grain diameters with Drag distribution = " +
        coupling_parameters.drag_distribution +
        ": each grain feels its own disturbance of the velocity (a lone "
        "grain settles 10-17 % too fast at 2-8 diameters, a suspension 10 % "
        "at 4 and 24 % at 2, doc/validation.md); use Drag distribution = "
        "filtered with Smoothing length of at least 8 grain radii, or "
        "coarser cells");
    if (two_way && dim == 3 && spread_in_cells &&
        coupling_parameters.self_correction && h < 2 * d)
      regime.warnings.push_back(
        "cells of " + number(h / d, 2) +
        " grain diameters with the self-disturbance correction: it is "
        "validated on cells of 2 diameters and more, and on smaller ones "
        "takes out more than the grain's own disturbance (a lone grain "
        "settles at 0.85 of its velocity on cells of one diameter, 0.60 on "
        "half a diameter, doc/stability.md); use Drag distribution = "
        "filtered with Smoothing length of at least 8 grain radii");
    // A 2D cloud (a ball of discs) moves collectively, and each disc's own
    // excess, a few times its lone velocity, is a share of the cloud's
    // that falls as the ball grows: measured 11 % of the velocity with 11
    // discs, 4 % with 30, 1.7 % with 100 and 0.8 % with 321
    // (benchmarks/clouds/small_balls_2d.py). The cell spread is validated
    // on clouds of 321 discs (cloud_single_fluid_2d) and on lattices. A
    // filter half the box wide, which puts separate discs right, takes a
    // ball's collective flow away whatever its size (a ball of 11 discs
    // fell 27 times slower than with the cell spread), so a small ball keeps
    // the cell spread and is told its error.
    const bool ball_2d   = grain_parameters.shape == PlacementShape::ball;
    const bool cloud_2d  = ball_2d && placed_grains >= 100;
    const auto disc_word = [](const unsigned int n)
    { return std::to_string(n) + (n == 1 ? " disc" : " discs"); };
    if (two_way && dim == 2 && spread_in_cells && ball_2d && !cloud_2d)
      regime.warnings.push_back(
        "2D with Drag distribution = " + coupling_parameters.drag_distribution +
        " and a ball of " + disc_word(placed_grains) +
        " (fewer than 100): each disc feels its own disturbance, which "
        "decays only logarithmically in 2D (a lone disc settles 4 times too "
        "fast on cells of 5 diameters), and in a ball that is a share of "
        "the ball's velocity which falls as the ball grows: about 11 % with "
        "11 discs, 4 % with 30, 1.7 % with 100 (doc/validation.md, \"Small "
        "2D balls\"): where that error matters, use a ball of 100 discs or "
        "more. A filter half the box wide, which suits discs that do not "
        "move together, takes a ball's collective flow away (a ball of 11 "
        "discs fell 27 times slower than with the cell spread); for such "
        "discs use a list or box placement (Drag distribution = auto then "
        "filters them)");
    if (two_way && dim == 2 && !spread_in_cells && ball_2d)
      regime.warnings.push_back(
        "2D with Drag distribution = filtered and a ball of " +
        disc_word(placed_grains) + ": the filter of Smoothing length " +
        number(l) +
        " m spreads each drag over its length, and with it the ball's "
        "collective flow (a ball of 101 discs fell 17 % slower with a filter "
        "of 4 diameters than with the cell spread, 160 times slower with one "
        "half the box wide, doc/validation.md, \"Small 2D balls\"); use "
        "Drag distribution = auto (the cell spread, validated on clouds of "
        "321 discs)");
    // A packing screens each disc's disturbance: its filter must keep the
    // pore pressure, which varies over a few diameters (column_collapse_2d).
    const bool packed_2d = dim == 2 && touching_neighbours >= packed_neighbours;
    if (two_way && packed_2d && spread_in_cells &&
        grain_parameters.shape != PlacementShape::lattice)
      regime.warnings.push_back(
        "2D packed discs (" + number(touching_neighbours, 2) +
        " touching neighbours each) with Drag distribution = " +
        coupling_parameters.drag_distribution +
        ": the coupling is unstable on a packing spread in cells (a "
        "collapsing column's discs reached 11 m/s within 25 ms, "
        "doc/validation.md, \"Column collapse in a viscous liquid\"); use "
        "Drag distribution = auto (a filter of three diameters)");
    if (two_way && packed_2d && !spread_in_cells && l > 8 * d)
      regime.warnings.push_back(
        "2D packed discs (" + number(touching_neighbours, 2) +
        " touching neighbours each) with a filter of Smoothing length " +
        number(l) + " m, " + number(l / d, 2) +
        " diameters: where the packing shears or fails, it spreads the "
        "pore pressure that holds or lifts it flat (a loose and a dense "
        "column collapse alike with half the box, "
        "doc/validation.md, \"Column collapse in a viscous liquid\"); use "
        "about three diameters, or Drag distribution = auto");
    if (two_way && dim == 2 && spread_in_cells && !ball_2d && !packed_2d &&
        grain_parameters.shape != PlacementShape::lattice)
      regime.warnings.push_back(
        "2D with Drag distribution = " + coupling_parameters.drag_distribution +
        ": a disc's own disturbance decays only logarithmically, and a lone "
        "disc settles 2.4-4 times too fast whatever the cell; discs placed "
        "at random settle about twice too fast, from the flows each cell's "
        "random share of discs drives (doc/validation.md); use Drag "
        "distribution = auto (the default), or Drag distribution = filtered "
        "with Smoothing length about half the box (lone discs and 2D "
        "suspensions then lie within 0.5 % of the closure)");
    const double shortest_side = geometry.shortest_side();
    if (two_way && !spread_in_cells && dim == 2 && !ball_2d && !packed_2d &&
        l < shortest_side / 4)
      regime.warnings.push_back(
        "Smoothing length " + number(l) + " m is " +
        number(l / shortest_side, 2) +
        " of the box's shortest side: in 2D a disc feels its own "
        "disturbance out to the filter's length (a lone disc settles 2.8 % "
        "too fast with a quarter of the box, discs at random 21-73 % with 8 "
        "grain radii, doc/validation.md); use about half the box's "
        "shortest side, or Drag distribution = auto");
    if (two_way && !spread_in_cells && dim == 3 && l < 4 * d &&
        !coupling_parameters.self_correction)
      regime.warnings.push_back(
        "Smoothing length " + number(l) + " m is " + number(l / r, 2) +
        " grain radii: below 8 radii a grain feels its own disturbance "
        "(suspensions at solid fractions 0.01-0.3 settle 0.4-2.6 % too fast "
        "at 4 radii and 0.7-3.5 % at 2, within 1 % at 8, "
        "doc/validation.md); use at least 8 radii");
    // A packed 2D bed (placed at an area fraction whose fluid fraction lies
    // below the bound, or on a touching lattice) read by area.
    const bool by_fraction = (grain_parameters.shape == PlacementShape::ball ||
                              grain_parameters.shape == PlacementShape::box) &&
                             grain_parameters.count == 0;
    const double placed_solid =
      grain_parameters.shape == PlacementShape::lattice ?
        std::acos(-1.0) / 4 :
        (by_fraction ? grain_parameters.solid_fraction : 0.0);
    if (two_way && dim == 2 &&
        !coupling_parameters.projection.closure_porosity.sphere_packing &&
        1 - placed_solid < coupling_parameters.projection.min_fluid_fraction)
      regime.warnings.push_back(
        "grains placed at area fraction " + number(placed_solid, 2) +
        " with Closure porosity in 2D = area fraction: the drag law and the "
        "fluid see the bound 1 - Minimum fluid fraction instead of the "
        "packing (doc/theory.md, \"Dense 2D beds\"); use Closure porosity "
        "in 2D = sphere packing for a packed 2D bed");
    // The solid fraction of a ball or box placement, however it was given.
    double placed_fraction = by_fraction ? grain_parameters.solid_fraction : 0;
    if (!by_fraction && !grain_parameters.size.empty() &&
        (grain_parameters.shape == PlacementShape::ball ||
         grain_parameters.shape == PlacementShape::box))
    {
      double region = 1;
      if (grain_parameters.shape == PlacementShape::ball)
        region = grain_volume<dim>(grain_parameters.size[0]);
      else
        for (unsigned int c = 0; c < dim; ++c)
          region *=
            grain_parameters
              .size[std::min<std::size_t>(c, grain_parameters.size.size() - 1)];
      placed_fraction = placed_grains * grain_volume<dim>(r) / region;
    }
    if (two_way && dim == 3 && spread_in_cells && placed_grains > 0 &&
        placed_as_suspension(grain_parameters, geometry))
      regime.warnings.push_back(
        "grains placed at random across a periodic box (solid fraction " +
        number(placed_fraction, 2) +
        ") with Drag distribution = " + coupling_parameters.drag_distribution +
        ": each cell's random share of grains drives a flow that the "
        "closure already holds, so a suspension on cells of 4 diameters "
        "settles 2-10 % slow with the self-disturbance correction and "
        "6-12 % too fast without it at solid fractions 0.005-0.3 (on cells "
        "of 2 diameters at 0.3: 13.5 % and 36 % too fast; doc/validation.md, "
        "\"Dense suspensions\"); use Drag distribution = auto or filtered "
        "with Smoothing length of at least 8 grain radii (within 1 % of the "
        "closure)");
    // Grains of several sizes: which drag the law gives each (Yin &
    // Sundaresan's correction against the Sauter mean diameter, or one
    // size's drag for each), and where the correction was fitted.
    if (two_way && grain_seeds.size() > 1)
    {
      double smallest = std::numeric_limits<double>::max(), largest = 0;
      for (const auto &seed : grain_seeds)
      {
        smallest = std::min(smallest, seed.radius);
        largest  = std::max(largest, seed.radius);
      }
      const double ratio = largest / smallest;
      // Set from the law when the parameters were read.
      const bool polydisperse_law =
        coupling_parameters.projection.with_mean_diameter;
      if (ratio >= 1.5 && !polydisperse_law)
        regime.warnings.push_back(
          "grains of diameter ratio " + number(ratio, 2) +
          " under Drag law = " + coupling_parameters.drag_law +
          ", a law for one size: each grain's drag reads the fluid fraction "
          "as if every grain had its diameter, where lattice-Boltzmann "
          "simulations of mixtures give a larger grain more drag and a "
          "smaller one less (radii 1:2 at solid fraction 0.1: under "
          "Beetstra's law the large grains settle 35 % faster and the small "
          "23 % slower than under Yin & Sundaresan's, doc/theory.md); use "
          "Drag law = Yin-Sundaresan");
      if (ratio > 4 && polydisperse_law)
        regime.warnings.push_back(
          "grains of diameter ratio " + number(ratio, 2) +
          " under Drag law = " + coupling_parameters.drag_law +
          ": the polydisperse correction is fitted on mixtures of diameter "
          "ratio up to 4 (doc/theory.md)");
      if (coupling_parameters.drag_law == "van der Hoef-Beetstra" &&
          placed_fraction > 0 && placed_fraction < 0.1)
        regime.warnings.push_back(
          "grains of several sizes placed at solid fraction " +
          number(placed_fraction, 2) +
          " under Drag law = van der Hoef-Beetstra: its correction was "
          "fitted at solid fractions 0.1-0.6 and keeps the factor d/<d> in "
          "the dilute limit, where a grain should have its Stokes drag "
          "(doc/theory.md); use Drag law = Yin-Sundaresan");
    }
    if (coupled && h < d && l < d)
      regime.warnings.push_back(
        "cells of " + number(h / d, 2) +
        " grain diameters without a Smoothing length of a diameter or more: "
        "the projected solid fraction peaks far above the packing it "
        "stands for (doc/validation.md); set Coupling/Smoothing length to a "
        "grain diameter or two");
    return regime;
  }


  template <int dim>
  void
  Simulation<dim>::print_check(std::ostream &out) const
  {
    if (dealii::Utilities::MPI::this_mpi_process(comm) != 0)
      return;
    const SceneRegime scene = regime();
    out << parameter_file << ": checked, nothing written.\n"
        << "  size: " << number(size_estimate.cells) << " cells, "
        << number(size_estimate.dofs) << " fluid DoFs, peak memory about "
        << number(size_estimate.peak_bytes / (1 << 30)) << " GiB"
        << (size_estimate.adapted ? " (the adaptive mesh around the initial "
                                    "grains)" :
                                    "")
        << "\n  regime:\n";
    for (const auto &l : scene.lines)
      out << "    " << l << '\n';
    out << "  switched:\n";
    for (const auto &s : scene.switches)
      out << "    " << s << '\n';
    if (scene.warnings.empty())
      out << "  no choice outside the validated range\n";
    for (const auto &w : scene.warnings)
      out << "  warning: " << w << '\n';
  }


  template <int dim>
  void
  Simulation<dim>::choose_drag_distribution(const std::string &file)
  {
    auto &c = coupling_parameters;
    if (dim == 2)
      touching_neighbours = mean_touching_neighbours(grain_seeds);
    if (c.drag_distribution != "auto")
      return;
    // Where each is validated (doc/validation.md). In 3D the cell spread
    // with the self-disturbance correction for lone grains, clouds placed
    // as a ball (their collective flow is what a filter would smooth) and
    // given grains and boxes walled around (a falling layer has no
    // reference that tells the two apart: Lethe's scene reads 20 % faster
    // filtered, doc/performance.md); for grains placed at random across a
    // periodic box (suspensions, beds settling from them) a filter of 8
    // radii, within 1 % of the closure from solid fraction 0.005 to 0.3 on
    // cells of 8-32 radii, where the corrected cell spread settles
    // 2-10 % slow (each cell's random share of grains drives a flow that
    // the closure holds already). In 2D the cell spread for clouds placed as a
    // ball (cloud_single_fluid_2d, 321 discs) and lattices, which give every
    // cell the same discs (hindered_settling_2d_lattice). Elsewhere in 2D a
    // disc's own disturbance decays only logarithmically, so that a lone
    // disc settles 2.4-4 times too fast in cells and discs placed at random
    // about twice: a filter half the box wide puts both within 0.5 % of the
    // closure (settling_lone_disc_2d_filtered_*, hindered_settling_2d_*).
    // Packed grains, in 3D as in 2D, are filtered so that the pore pressure
    // through the packing is resolved: a column of beads on a filter of six
    // mean radii lets a block slide off along one band of cells under a
    // suction of several times its weight, on 8 or 10 radii of the largest
    // bead it creeps alike (doc/scenes/column_collapse_2d.md).
    const auto shape = grain_parameters.shape;
    const auto set   = entries_set_in(file);
    const bool given_length =
      c.projection.smoothing_length > 0 &&
      std::find(set.begin(), set.end(), "Coupling/Smoothing length") !=
        set.end();
    c.drag_distribution = "cell";
    if (dim == 3)
    {
      const bool suspension = placed_as_suspension(grain_parameters, geometry);
      drag_distribution_choice =
        !c.two_way ? "3D, the fluid does not feel the grains" :
        placed_grains == 0 ?
                     "3D, no grains placed" :
        shape == PlacementShape::ball ?
                     "3D, a ball placement (a cloud)" :
                     "3D, grains neither packed nor placed at random across a "
                     "periodic box";
      if (!c.two_way || placed_grains == 0)
        return;
      // Counted only where the placement may be a packing: a suspension of
      // a million grains is spared the search.
      if (!suspension && shape != PlacementShape::ball &&
          shape != PlacementShape::lattice)
        touching_neighbours = mean_touching_neighbours(grain_seeds);
      const bool packed = touching_neighbours >= packed_neighbours;
      if (!suspension && !packed)
        return;
      const std::string what =
        suspension ? "3D grains placed at random across a periodic box" :
                     "3D packed grains (" + number(touching_neighbours, 2) +
                       " touching neighbours each)";
      c.drag_distribution = "filtered";
      if (given_length)
      {
        drag_distribution_choice =
          what + ", a filter of the Smoothing length given";
        return;
      }
      c.projection.smoothing_length = 8 * largest_grain_radius;
      drag_distribution_choice =
        what + ": a filter of 8 radii of the largest grain, " +
        number(c.projection.smoothing_length) + " m";
      return;
    }
    drag_distribution_choice = placed_grains == 0 ?
                                 "2D, no grains placed" :
                                 "2D, the fluid does not feel the grains";
    if (!c.two_way || placed_grains == 0)
      return;
    // A ball is placed as a cloud; below 100 discs regime() warns that
    // it is too small to be one.
    drag_distribution_choice = "2D, a ball placement (a cloud) of " +
                               std::to_string(placed_grains) +
                               (placed_grains == 1 ? " disc" : " discs");
    if (shape == PlacementShape::ball)
      return;
    drag_distribution_choice = "2D lattice: the same discs in every cell";
    if (shape == PlacementShape::lattice)
      return;
    c.drag_distribution = "filtered";
    // In a packing each disc's disturbance is screened by the discs it
    // touches, so the wide filter a free disc needs is not needed; what the
    // filter must keep is the pore pressure that varies across the packing
    // over a few diameters, and half the box would spread it flat
    // (column_collapse_2d: with it, loose and dense columns collapse alike).
    // Three diameters, as on the packed bed (coupled_packed_bed_2d): shorter
    // filters pass the packing's bound where cells are finer than the
    // discs.
    if (touching_neighbours >= packed_neighbours && !given_length)
    {
      c.projection.smoothing_length = 6 * mean_grain_radius;
      drag_distribution_choice =
        "2D packed discs (" + number(touching_neighbours, 2) +
        " touching neighbours each): a filter of three mean diameters, " +
        number(c.projection.smoothing_length) + " m";
      return;
    }
    if (given_length)
    {
      drag_distribution_choice =
        "2D discs not in a cloud, a filter of the Smoothing length given";
      return;
    }
    c.projection.smoothing_length = geometry.shortest_side() / 2;
    drag_distribution_choice =
      "2D discs not in a cloud: a filter half the box's shortest side, " +
      number(c.projection.smoothing_length) + " m";
  }


  template SceneRegime
  Simulation<2>::regime() const;
  template SceneRegime
  Simulation<3>::regime() const;
  template void
  Simulation<2>::print_check(std::ostream &) const;
  template void
  Simulation<3>::print_check(std::ostream &) const;
  template void
  Simulation<2>::choose_drag_distribution(const std::string &);
  template void
  Simulation<3>::choose_drag_distribution(const std::string &);
} // namespace ImmersedGrains
