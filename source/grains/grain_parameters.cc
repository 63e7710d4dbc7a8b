#include <deal.II/base/utilities.h>

#include <immersed_grains/grains/grain_parameters.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>

namespace ImmersedGrains
{
  template <int dim>
  void
  GrainParameters<dim>::declare_parameters(dealii::ParameterHandler &prm)
  {
    using namespace dealii::Patterns;
    prm.enter_subsection("Grains");
    {
      prm.declare_entry("Enabled",
                        "false",
                        Bool(),
                        "Simulate grains (rigid discs in 2D, spheres in 3D).");
      prm.declare_entry("Radius", "1e-3", Double(0), "Grain radius r [m].");
      prm.declare_entry("Radii",
                        "",
                        Anything(),
                        "One radius per grain (comma list); overrides Radius "
                        "and Radius distribution. With Shape = ball or box it "
                        "also sets how many grains are placed.");
      prm.declare_entry(
        "Size distribution",
        "constant",
        Selection("constant|uniform|lognormal|classes"),
        "The radii of the grains that Shape = ball, box or lattice places: "
        "constant (Radius); uniform in [Radius - Radius spread, Radius + "
        "Radius spread]; lognormal with median Radius and geometric standard "
        "deviation Radius spread (ln r normal with deviation ln(Radius "
        "spread)), redrawn outside [Minimum radius, Maximum radius], by "
        "default Radius / spread^3 and Radius * spread^3; classes: the radii "
        "Class radii in the volume fractions Class fractions (exact numbers "
        "with Solid fraction, numbers in proportion with Count; statistics "
        "per class: class<k>_particles, _mean_velocity_*, _centroid_*).");
      prm.declare_entry("Radius spread",
                        "0",
                        Double(0),
                        "Size distribution = uniform: the half-width [m]; "
                        "lognormal: the geometric standard deviation (>= 1, "
                        "no unit).");
      prm.declare_entry("Class radii",
                        "",
                        Anything(),
                        "Size distribution = classes: the classes' radii "
                        "[m], a comma list of distinct values.");
      prm.declare_entry("Class fractions",
                        "",
                        Anything(),
                        "Size distribution = classes: each class's share of "
                        "the grains' volume, in the order of Class radii; "
                        "they sum to 1.");
      prm.declare_entry("Radius distribution",
                        "constant",
                        Selection("constant|uniform|normal"),
                        "The older way to draw radii (Size distribution is "
                        "the newer): constant (Radius), uniform in [Minimum "
                        "radius, Maximum radius], or normal with mean Radius "
                        "and Radius deviation, redrawn outside the bounds.");
      prm.declare_entry("Minimum radius", "0", Double(0), "[m], see above.");
      prm.declare_entry("Maximum radius", "0", Double(0), "[m], see above.");
      prm.declare_entry("Radius deviation",
                        "0",
                        Double(0),
                        "Standard deviation of the normal distribution [m].");
      prm.declare_entry("Density",
                        "2500",
                        Double(0),
                        "Grain density rho_p [kg/m^3] (2D: mass per unit "
                        "depth is rho_p pi r^2).");
      prm.declare_entry("Fixed",
                        "false",
                        Bool(),
                        "Every grain is fixed (a fixed bed): it never moves "
                        "and has infinite mass for the contact solver; to "
                        "fix only some, see Fixed region.");
      prm.declare_entry("Fixed region",
                        "",
                        Anything(),
                        "A box 'x0,y0[,z0]; x1,y1[,z1]' (lower and upper "
                        "corner): the grains whose centre lies in it when "
                        "placed are fixed (infinite mass, never moved), the "
                        "others move; e.g. a bed that moving grains are "
                        "poured onto. Empty: none (unless Fixed = true).");
      prm.declare_entry("Max displacement fraction",
                        "0.125",
                        Double(0),
                        "With Adaptive time step, no grain moves more than "
                        "this fraction of the smallest radius in one step.");

      prm.enter_subsection("Placement");
      {
        prm.declare_entry("Shape",
                          "list",
                          Selection("ball|box|list|file|lattice"),
                          "ball/box: random non-overlapping fill (random "
                          "sequential addition), across the periodic faces "
                          "where a box spans a periodic axis of the domain; "
                          "list: Positions; file: "
                          "File; lattice: square (cubic) lattice of spacing "
                          "2 r_max filling the box Center, Size.");
        prm.declare_entry("Center",
                          dim == 2 ? "0.5, 0.5" : "0.5, 0.5, 0.5",
                          Anything(),
                          "Centre of the ball or box (comma list) [m]. For a "
                          "ball or a box, several centres separated by ';' "
                          "fill one region around each, alike (e.g. two "
                          "clouds); the regions must not overlap.");
        prm.declare_entry("Size",
                          "0.25",
                          Anything(),
                          "The ball's radius, or the box's edge lengths as a "
                          "comma list (one value: a cube) [m].");
        prm.declare_entry("Solid fraction",
                          "0.3",
                          Double(),
                          "Volume fraction of the ball or box filled with "
                          "grains when Count = 0.");
        prm.declare_entry("Count",
                          "0",
                          Integer(0),
                          "Number of grains for ball, box and lattice (0: "
                          "from Solid fraction; lattice: fill the box).");
        prm.declare_entry("Positions",
                          "",
                          Anything(),
                          "Shape = list: centres, points separated by ';', "
                          "coordinates by ',' (e.g. 0,0.1; 0,0.2).");
        prm.declare_entry("Velocities",
                          "",
                          Anything(),
                          "Initial velocities, same format: one per grain, "
                          "or one for all, or empty (at rest).");
        prm.declare_entry("Random seed", "1", Integer(0), "Seed of the fill.");
        prm.declare_entry(
          "Fill across periodic faces",
          "true",
          Bool(),
          "Shape = box spanning a periodic axis of a box domain: true draws "
          "the centres over the whole period, each grain clear of its "
          "neighbours' periodic images, so a suspension is homogeneous "
          "across the periodic faces; false keeps every centre its radius "
          "inside the box as at a wall, which leaves a layer one radius "
          "deep empty on each side of the periodic face (in a suspension a "
          "lighter sheet that drives a box-wide flow; doc/contacts.md).");
        prm.declare_entry("File",
                          "",
                          Anything(),
                          "Shape = file: one grain per line, 'x y [z] [r "
                          "[vx vy [vz]]]' separated by spaces or commas; "
                          "'#' starts a comment. A relative path is read "
                          "from the folder of the parameter file. Grains may "
                          "overlap each other and the walls by Contacts/"
                          "Overlap tolerance times their radius, what a run "
                          "that wrote the file (Output/Write grain file) "
                          "leaves.");
      }
      prm.leave_subsection();
    }
    prm.leave_subsection();

    prm.enter_subsection("Contacts");
    {
      prm.declare_entry("Enabled",
                        "true",
                        Bool(),
                        "Resolve grain-grain and grain-wall contacts "
                        "(non-smooth contact dynamics).");
      prm.declare_entry("Restitution",
                        "0",
                        Double(0, 1),
                        "Newton coefficient of restitution e.");
      prm.declare_entry("Friction",
                        "0",
                        Double(0),
                        "Coulomb friction coefficient; > 0 adds rotation.");
      prm.declare_entry(
        "Rolling friction",
        "0",
        Double(0),
        "Rolling friction coefficient mu_r (needs Friction > 0 and Solver "
        "= gauss-seidel): each contact resists its two grains' relative "
        "rolling with a torque of at most mu_r R* N, N its normal force, R* "
        "= r_i r_j / (r_i + r_j) between two grains and r_i against a wall, "
        "as Coulomb's friction resists sliding; standing for the shape and "
        "the contact area that roll a real grain less than a sphere. A "
        "grain rolls down a plane inclined at theta only where tan(theta) "
        "> mu_r (doc/contacts.md). 0: grains roll freely.");
      prm.declare_entry("Tolerance",
                        "1e-6",
                        Double(0),
                        "Gauss-Seidel stops when no impulse changes by more "
                        "than this times the largest impulse in a sweep "
                        "(and, with the subspace correction, a correction "
                        "finds less than its square of the impulses' energy "
                        "left to remove) ...");
      prm.declare_entry("Overlap tolerance",
                        "1e-3",
                        Double(0),
                        "... and the largest overlap at the end of the step "
                        "is below this times the smallest radius.");
      prm.declare_entry("Solver",
                        "gauss-seidel",
                        Selection("gauss-seidel|apgd"),
                        "Iterative method for the contact impulses: "
                        "gauss-seidel (projected Gauss-Seidel, contact after "
                        "contact) or apgd (Nesterov-accelerated projected "
                        "gradient descent with adaptive step and restart, "
                        "Mazhar et al. 2015: all contacts at once, far fewer "
                        "iterations on deep or wide packings; see "
                        "doc/contacts.md). Both solve the same problem and "
                        "stop on the same test (Gauss-Seidel's subspace "
                        "correction adds one).");
      prm.declare_entry("Max iterations",
                        "1000",
                        Integer(1),
                        "Cap on Gauss-Seidel sweeps (or APGD iterations) per "
                        "step, and again for the position correction when a "
                        "step needs one (doc/contacts.md).");
      prm.declare_entry("Alert distance",
                        "0",
                        Double(0),
                        "Pairs closer than this at the start of a step are "
                        "contact candidates [m]; 0: automatic (a tenth of "
                        "the smallest radius plus three times the largest "
                        "free displacement of the step).");
      prm.declare_entry("Warm start",
                        "true",
                        Bool(),
                        "Start from last step's impulses.");
      prm.declare_entry("Sweep order",
                        "height",
                        Selection("height|index"),
                        "Order in which Gauss-Seidel visits the contacts: "
                        "height (sorted along gravity, up and down on "
                        "alternate sweeps: the weight of a pile reaches its "
                        "floor in one sweep) or index (grain order, in "
                        "rounds: the fastest update, for scenes without a "
                        "direction of load, or without gravity).");
      prm.declare_entry("Subspace correction every",
                        "20",
                        Integer(0),
                        "Gauss-Seidel without friction: after every this "
                        "many sweeps of a step that has not converged, and "
                        "to confirm convergence, conjugate gradients on the "
                        "contacts that carry an impulse (doc/contacts.md, "
                        "\"Subspace correction\"): dense packings converge "
                        "on every step, at about three times the cost of "
                        "the capped plain sweeps while they settle, less "
                        "once at rest. 0: never (plain Gauss-Seidel, the "
                        "cheaper and less accurate path).");
      prm.declare_entry("Subspace iterations",
                        "200",
                        Integer(1),
                        "Conjugate-gradient iterations of one subspace "
                        "correction (at most: they stop earlier once the "
                        "residual has fallen by 1e-12). Fewer leave the "
                        "correction unable to confirm convergence on dense "
                        "packings (doc/contacts.md).");
      prm.declare_entry("Stop on failure",
                        "false",
                        Bool(),
                        "Stop the run when the contact solver does not "
                        "converge within Max iterations (otherwise a warning "
                        "in the log and contact_residual in statistics).");
    }
    prm.leave_subsection();

    prm.enter_subsection("Gravity");
    prm.declare_entry("Vector",
                      dim == 2 ? "0, -9.81" : "0, 0, -9.81",
                      Anything(),
                      "Gravitational acceleration g [m/s^2] (comma list).");
    prm.leave_subsection();
  }


  namespace
  {
    /** Grains/Size distribution other than constant, with Radius spread
     *  or Class radii and Class fractions; sets radius_distribution and
     *  the bounds the draws keep to. */
    template <int dim>
    void
    parse_size_distribution(GrainParameters<dim>     &p,
                            dealii::ParameterHandler &prm,
                            const InputLocation      &where)
    {
      const std::string sizes = prm.get("Size distribution");
      where.require(prm.get("Radius distribution") == "constant",
                    "Size distribution",
                    sizes,
                    "Radius distribution = " + prm.get("Radius distribution") +
                      " is set too: set only one of them");
      p.radius_spread           = prm.get_double("Radius spread");
      const std::string &spread = prm.get("Radius spread");
      if (sizes == "uniform")
      {
        where.require(p.radius_spread < p.radius,
                      "Radius spread",
                      spread,
                      "the half-width of a uniform distribution must be "
                      "below Radius (" +
                        prm.get("Radius") + ")");
        p.radius_distribution = RadiusDistribution::uniform;
        p.min_radius          = p.radius - p.radius_spread;
        p.max_radius          = p.radius + p.radius_spread;
      }
      else if (sizes == "lognormal")
      {
        where.require(p.radius_spread >= 1,
                      "Radius spread",
                      spread,
                      "the geometric standard deviation of a lognormal "
                      "distribution is at least 1");
        p.radius_distribution = RadiusDistribution::lognormal;
        // Three geometric deviations each side: 0.27 % of the draws are
        // redrawn, and a spread of 1.5 keeps the size ratio below 12.
        const double reach = std::pow(p.radius_spread, 3);
        if (p.min_radius == 0)
          p.min_radius = p.radius / reach;
        if (p.max_radius == 0)
          p.max_radius = p.radius * reach;
        where.require(p.min_radius <= p.radius && p.radius <= p.max_radius,
                      "Radius",
                      prm.get("Radius"),
                      "the median must lie in [Minimum radius, Maximum "
                      "radius]");
      }
      else
      {
        p.radius_distribution  = RadiusDistribution::classes;
        p.class_radii_text     = prm.get("Class radii");
        p.class_fractions_text = prm.get("Class fractions");
        p.class_radii =
          parse_double_list(p.class_radii_text, where, "Class radii");
        p.class_fractions =
          parse_double_list(p.class_fractions_text, where, "Class fractions");
        where.require(!p.class_radii.empty(),
                      "Class radii",
                      p.class_radii_text,
                      "Size distribution = classes needs at least one radius");
        double sum = 0;
        for (unsigned int k = 0; k < p.class_radii.size(); ++k)
        {
          where.require(p.class_radii[k] > 0,
                        "Class radii",
                        p.class_radii_text,
                        "radii must be positive");
          for (unsigned int j = 0; j < k; ++j)
            where.require(p.class_radii[j] != p.class_radii[k],
                          "Class radii",
                          p.class_radii_text,
                          "two classes have the same radius");
        }
        p.min_radius =
          *std::min_element(p.class_radii.begin(), p.class_radii.end());
        p.max_radius =
          *std::max_element(p.class_radii.begin(), p.class_radii.end());
        // Grains from a list or a file carry their radii: the fractions
        // are for fills (checked with the placement).
        if (p.class_fractions.empty())
          return;
        where.require(p.class_fractions.size() == p.class_radii.size(),
                      "Class fractions",
                      p.class_fractions_text,
                      "needs one fraction per class radius (" +
                        std::to_string(p.class_radii.size()) + ")");
        for (const double f : p.class_fractions)
        {
          where.require(f >= 0,
                        "Class fractions",
                        p.class_fractions_text,
                        "fractions must not be negative");
          sum += f;
        }
        where.require(std::abs(sum - 1) < 1e-6,
                      "Class fractions",
                      p.class_fractions_text,
                      "the volume fractions must sum to 1");
      }
    }


    /** Grains/Fixed region: two corners, or empty. */
    template <int dim>
    void
    parse_fixed_region(GrainParameters<dim> &p, const InputLocation &where)
    {
      const std::string &text = p.fixed_region_text;
      p.has_fixed_region      = false;
      if (dealii::Utilities::trim(text).empty())
        return;
      // parse_point would name only one corner; the message names the whole
      // entry.
      const auto corners = dealii::Utilities::split_string_list(text, ';');
      where.require(corners.size() == 2,
                    "Fixed region",
                    text,
                    "expected two corners 'x0,y0" +
                      std::string(dim == 3 ? ",z0" : "") + "; x1,y1" +
                      std::string(dim == 3 ? ",z1" : "") + "'");
      dealii::Point<dim> corner[2];
      for (unsigned int c = 0; c < 2; ++c)
      {
        const auto values = dealii::Utilities::split_string_list(corners[c]);
        where.require(values.size() == dim,
                      "Fixed region",
                      text,
                      "corner '" + corners[c] + "' needs " +
                        std::to_string(dim) + " comma-separated coordinates");
        for (unsigned int d = 0; d < dim; ++d)
        {
          std::istringstream in(values[d]);
          std::string        trailing;
          where.require((in >> corner[c][d]) && !(in >> trailing) &&
                          std::isfinite(corner[c][d]),
                        "Fixed region",
                        text,
                        "'" + values[d] + "' is not a number");
        }
      }
      for (unsigned int d = 0; d < dim; ++d)
        where.require(corner[0][d] < corner[1][d],
                      "Fixed region",
                      text,
                      "the first corner must lie below the second in every "
                      "coordinate");
      where.require(!p.fixed,
                    "Fixed region",
                    text,
                    "Fixed = true already fixes every grain; set Fixed = "
                    "false to fix only those in the region");
      p.fixed_region_lower = corner[0];
      p.fixed_region_upper = corner[1];
      p.has_fixed_region   = true;
    }
  } // namespace


  template <int dim>
  bool
  GrainParameters<dim>::fixed_at_placement(const dealii::Point<dim> &x) const
  {
    if (fixed)
      return true;
    if (!has_fixed_region)
      return false;
    for (unsigned int d = 0; d < dim; ++d)
      if (x[d] < fixed_region_lower[d] || x[d] > fixed_region_upper[d])
        return false;
    return true;
  }


  template <int dim>
  unsigned int
  GrainParameters<dim>::n_classes() const
  {
    return radius_distribution == RadiusDistribution::classes ?
             class_radii.size() :
             0;
  }


  template <int dim>
  int
  GrainParameters<dim>::class_of(const double r) const
  {
    for (unsigned int k = 0; k < n_classes(); ++k)
      if (std::abs(r - class_radii[k]) <= 1e-9 * class_radii[k])
        return k;
    return -1;
  }


  template <int dim>
  double
  GrainParameters<dim>::largest_drawn_radius() const
  {
    return radius_distribution == RadiusDistribution::constant ? radius :
                                                                 max_radius;
  }


  template <int dim>
  void
  GrainParameters<dim>::parse_parameters(dealii::ParameterHandler &prm,
                                         const std::string        &file_name)
  {
    file = file_name;
    prm.enter_subsection("Grains");
    {
      const InputLocation where{file, "Grains"};
      enabled    = prm.get_bool("Enabled");
      radius     = prm.get_double("Radius");
      radii_text = prm.get("Radii");
      radii      = parse_double_list(radii_text, where, "Radii");
      for (const double r : radii)
        where.require(r > 0, "Radii", radii_text, "radii must be positive");
      where.require(radius > 0,
                    "Radius",
                    prm.get("Radius"),
                    "must be positive");
      const std::string distribution = prm.get("Radius distribution");
      radius_distribution =
        (distribution == "uniform" ? RadiusDistribution::uniform :
         distribution == "normal"  ? RadiusDistribution::normal :
                                     RadiusDistribution::constant);
      min_radius              = prm.get_double("Minimum radius");
      max_radius              = prm.get_double("Maximum radius");
      radius_deviation        = prm.get_double("Radius deviation");
      const std::string sizes = prm.get("Size distribution");
      if (sizes != "constant")
        parse_size_distribution(*this, prm, where);
      else if (radius_distribution != RadiusDistribution::constant)
        where.require(min_radius > 0 && max_radius >= min_radius,
                      "Maximum radius",
                      prm.get("Maximum radius"),
                      "needs 0 < Minimum radius (" + prm.get("Minimum radius") +
                        ") <= Maximum radius for Radius distribution = " +
                        distribution);
      if (radius_distribution == RadiusDistribution::normal)
        where.require(radius >= min_radius && radius <= max_radius,
                      "Radius",
                      prm.get("Radius"),
                      "the mean of the normal distribution must lie in "
                      "[Minimum radius, Maximum radius]");
      density = prm.get_double("Density");
      where.require(density > 0,
                    "Density",
                    prm.get("Density"),
                    "must be positive");
      fixed             = prm.get_bool("Fixed");
      fixed_region_text = prm.get("Fixed region");
      parse_fixed_region(*this, where);
      max_displacement = prm.get_double("Max displacement fraction");
      where.require(max_displacement > 0,
                    "Max displacement fraction",
                    prm.get("Max displacement fraction"),
                    "must be positive");

      prm.enter_subsection("Placement");
      {
        const InputLocation place{file, "Grains/Placement"};
        const std::string   s = prm.get("Shape");
        shape                 = (s == "ball"    ? PlacementShape::ball :
                                 s == "box"     ? PlacementShape::box :
                                 s == "file"    ? PlacementShape::file :
                                 s == "lattice" ? PlacementShape::lattice :
                                                  PlacementShape::list);
        center_text           = prm.get("Center");
        centers = parse_point_list<dim>(center_text, place, "Center");
        place.require(!centers.empty() &&
                        (centers.size() == 1 || shape == PlacementShape::ball ||
                         shape == PlacementShape::box),
                      "Center",
                      center_text,
                      centers.empty() ? "needs a point" :
                                        "several centres (';') need Shape = "
                                        "ball or box");
        center    = centers[0];
        size_text = prm.get("Size");
        size      = parse_double_list(size_text, place, "Size");
        if (shape == PlacementShape::ball)
          place.require(size.size() == 1,
                        "Size",
                        size_text,
                        "a ball takes one value, its radius");
        if (shape == PlacementShape::box || shape == PlacementShape::lattice)
        {
          place.require(size.size() == 1 || size.size() == dim,
                        "Size",
                        size_text,
                        "a box takes one edge length or " +
                          std::to_string(dim));
          if (size.size() == 1)
            size.assign(dim, size[0]);
        }
        for (const double v : size)
          place.require(v > 0, "Size", size_text, "must be positive");
        solid_fraction_text = prm.get("Solid fraction");
        solid_fraction      = prm.get_double("Solid fraction");
        count_text          = prm.get("Count");
        count               = prm.get_integer("Count");
        positions_text      = prm.get("Positions");
        positions = parse_point_list<dim>(positions_text, place, "Positions");
        velocities_text = prm.get("Velocities");
        velocities =
          parse_point_list<dim>(velocities_text, place, "Velocities");
        random_seed                = prm.get_integer("Random seed");
        fill_across_periodic_faces = prm.get_bool("Fill across periodic faces");
        placement_file             = prm.get("File");
        {
          std::filesystem::path path(placement_file);
          if (path.is_relative())
            path = std::filesystem::path(file).parent_path() / path;
          placement_path = path.lexically_normal().string();
        }
        if (enabled && radius_distribution == RadiusDistribution::classes &&
            radii.empty() &&
            (shape == PlacementShape::ball || shape == PlacementShape::box ||
             shape == PlacementShape::lattice))
          where.require(!class_fractions.empty(),
                        "Class fractions",
                        class_fractions_text,
                        "a fill with Size distribution = classes needs the "
                        "classes' volume fractions");
        if (enabled && shape == PlacementShape::list)
          place.require(!positions.empty(),
                        "Positions",
                        positions_text,
                        "Shape = list needs at least one position");
        if (enabled && shape == PlacementShape::file)
          place.require(!placement_file.empty(),
                        "File",
                        placement_file,
                        "Shape = file needs a file name");
        if (enabled &&
            (shape == PlacementShape::ball || shape == PlacementShape::box) &&
            count == 0 && radii.empty())
          place.require(solid_fraction > 0 && solid_fraction < 1,
                        "Solid fraction",
                        solid_fraction_text,
                        "must lie in (0, 1)");
      }
      prm.leave_subsection();
    }
    prm.leave_subsection();

    prm.enter_subsection("Contacts");
    {
      const InputLocation where{file, "Contacts"};
      contacts_enabled          = prm.get_bool("Enabled");
      contact.restitution       = prm.get_double("Restitution");
      contact.friction          = prm.get_double("Friction");
      contact.rolling_friction  = prm.get_double("Rolling friction");
      contact.tolerance         = prm.get_double("Tolerance");
      contact.overlap_tolerance = prm.get_double("Overlap tolerance");
      contact.max_iterations    = prm.get_integer("Max iterations");
      contact.method =
        (prm.get("Solver") == "apgd" ? Contact::ContactMethod::apgd :
                                       Contact::ContactMethod::gauss_seidel);
      contact.warm_start        = prm.get_bool("Warm start");
      contact.subspace_interval = prm.get_integer("Subspace correction every");
      contact.subspace_iterations = prm.get_integer("Subspace iterations");
      alert_distance              = prm.get_double("Alert distance");
      stop_on_failure             = prm.get_bool("Stop on failure");
      sweep_along_gravity         = prm.get("Sweep order") == "height";
      where.require(contact.rolling_friction == 0 || contact.friction > 0,
                    "Rolling friction",
                    prm.get("Rolling friction"),
                    "needs Friction > 0 (without friction the grains do "
                    "not rotate)");
      where.require(contact.rolling_friction == 0 ||
                      contact.method == Contact::ContactMethod::gauss_seidel,
                    "Rolling friction",
                    prm.get("Rolling friction"),
                    "needs Solver = gauss-seidel");
      where.require(contact.tolerance > 0,
                    "Tolerance",
                    prm.get("Tolerance"),
                    "must be positive");
      where.require(contact.overlap_tolerance > 0,
                    "Overlap tolerance",
                    prm.get("Overlap tolerance"),
                    "must be positive");
    }
    prm.leave_subsection();

    prm.enter_subsection("Gravity");
    {
      const InputLocation where{file, "Gravity"};
      const auto g = parse_point<dim>(prm.get("Vector"), where, "Vector");
      for (unsigned int d = 0; d < dim; ++d)
        gravity[d] = g[d];
    }
    prm.leave_subsection();
  }


  template struct GrainParameters<2>;
  template struct GrainParameters<3>;
} // namespace ImmersedGrains
