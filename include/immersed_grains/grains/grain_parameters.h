#ifndef immersed_grains_grains_grain_parameters_h
#define immersed_grains_grains_grain_parameters_h

#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/point.h>
#include <deal.II/base/tensor.h>

#include <immersed_grains/contact/contact_solver.h>
#include <immersed_grains/parameters.h>

#include <string>
#include <vector>

namespace ImmersedGrains
{
  /** How the radii of randomly placed grains are drawn (`Size
   *  distribution`, or the older `Radius distribution`). */
  enum class RadiusDistribution
  {
    constant,  // every grain has Radius
    uniform,   // uniform in [min_radius, max_radius]
    normal,    // normal(Radius, Radius deviation), redrawn outside the bounds
    lognormal, // median Radius, geometric deviation Radius spread,
               // redrawn outside [min_radius, max_radius]
    classes    // Class radii in the volume fractions Class fractions
  };

  /** Where the initial grains come from (`subsection Placement`). */
  enum class PlacementShape
  {
    ball,    // random non-overlapping fill of a ball (disc in 2D)
    box,     // random non-overlapping fill of a box
    list,    // Positions (and Velocities) in the .prm
    file,    // a text/CSV file: x, y[, z][, r[, vx, vy[, vz]]] per line
    lattice, // square/cubic lattice of spacing 2 r_max filling the box
  };

  /**
   * Everything in `subsection Grains`, `subsection Contacts` and
   * `subsection Gravity`. Values are in SI units; the text of each entry is
   * kept where a later check (placement) must name it in an InputError.
   */
  template <int dim>
  struct GrainParameters
  {
    static void
    declare_parameters(dealii::ParameterHandler &prm);

    void
    parse_parameters(dealii::ParameterHandler &prm, const std::string &file);

    std::string file; // the parameter file, for messages

    // Grains
    bool                enabled = false;
    double              radius  = 1e-3;
    std::vector<double> radii; // one per grain, or empty
    std::string         radii_text;
    RadiusDistribution  radius_distribution = RadiusDistribution::constant;
    double              min_radius          = 1e-3;
    double              max_radius          = 1e-3;
    double              radius_deviation    = 0;
    /// Size distribution: uniform's half-width or lognormal's geometric
    /// standard deviation.
    double              radius_spread = 0;
    std::vector<double> class_radii;     // Size distribution = classes
    std::vector<double> class_fractions; // their volume fractions, sum 1
    std::string         class_radii_text, class_fractions_text;
    double              density          = 2500;
    bool                fixed            = false;
    double              max_displacement = 0.125; // of the smallest radius
    /// Fixed region: grains whose centre lies in this closed box at
    /// placement are fixed (a bed others fall onto); none if not set.
    bool               has_fixed_region = false;
    dealii::Point<dim> fixed_region_lower, fixed_region_upper;
    std::string        fixed_region_text;

    /** The size classes whose statistics are written (Size distribution =
     *  classes), 0 otherwise. */
    unsigned int
    n_classes() const;

    /** The class of a grain of radius @p r: the class radius within a
     *  relative 1e-9 of it, or -1 (a grain read from a file or a list
     *  with another radius). */
    int
    class_of(double r) const;

    /** The largest radius the distribution draws (the lattice's
     *  spacing). */
    double
    largest_drawn_radius() const;

    /** Whether a grain placed at @p x is fixed (Fixed, or Fixed region). */
    bool
    fixed_at_placement(const dealii::Point<dim> &x) const;

    // Grains/Placement
    PlacementShape                  shape = PlacementShape::list;
    dealii::Point<dim>              center; // the first of centers
    std::vector<dealii::Point<dim>> centers;
    std::vector<double>             size; // ball: 1 value; box: dim values
    double                          solid_fraction = 0.3;
    unsigned int                    count          = 0;
    std::vector<dealii::Point<dim>> positions;
    std::vector<dealii::Point<dim>> velocities; // as points: one per grain
    unsigned int                    random_seed = 1;
    // A box spanning a periodic axis is filled across its periodic faces.
    bool        fill_across_periodic_faces = true;
    std::string placement_file;
    // placement_file read from the parameter file's folder if relative.
    std::string placement_path;
    // The entry texts, for messages naming them.
    std::string size_text, solid_fraction_text, count_text, positions_text,
      velocities_text, center_text;

    // Contacts
    bool                       contacts_enabled = true;
    Contact::ContactParameters contact;
    double                     alert_distance  = 0; // [m]; 0: automatic
    bool                       stop_on_failure = false;
    /// Contacts/Sweep order = height: Gauss-Seidel along gravity.
    bool sweep_along_gravity = true;

    // Gravity
    dealii::Tensor<1, dim> gravity;
  };

  /** Volume of a grain of radius r: pi r^2 (disc per unit depth) in 2D. */
  template <int dim>
  inline double
  grain_volume(const double r)
  {
    return dim == 2 ? M_PI * r * r : 4. / 3. * M_PI * r * r * r;
  }

  /** Area a grain of radius r shows the flow: 2 r (disc per unit depth) in
   *  2D, pi r^2 in 3D. */
  template <int dim>
  inline double
  grain_projected_area(const double r)
  {
    return dim == 2 ? 2 * r : M_PI * r * r;
  }

  /** Moment of inertia per unit mass, I / m: r^2/2 disc, 2 r^2/5 sphere. */
  template <int dim>
  inline double
  inertia_per_mass(const double r)
  {
    return (dim == 2 ? 0.5 : 0.4) * r * r;
  }
} // namespace ImmersedGrains

#endif
