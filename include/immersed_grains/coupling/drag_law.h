#ifndef immersed_grains_coupling_drag_law_h
#define immersed_grains_coupling_drag_law_h

#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace ImmersedGrains
{
  /**
   * What a drag law needs to know about one grain. `area` and `volume` are
   * the dim-ball's projection and measure: 2r and pi r^2 in 2D (discs per
   * unit depth), pi r^2 and 4/3 pi r^3 in 3D.
   */
  struct DragInput
  {
    double radius;
    double area;
    double volume;
    double fluid_fraction; // phi
    double slip_speed;     // |w| = |v_i - u_f(x_i)|
    double density;        // fluid
    double viscosity;      // fluid
    // The Sauter mean diameter of the grains around this one, sum V / sum
    // (V / d) over the solid fraction's kernel; 0: the grain's own (only
    // laws that say needs_mean_diameter() get it).
    double mean_diameter = 0;
  };

  /**
   * A drag closure D = gamma(phi, |w|) w on one grain, w its slip velocity.
   * Laws return the coefficient gamma [kg/s] (never D/|w| computed through a
   * division by Re: at the seed's Re ~ 1e-6 that would lose digits), so
   * that the implicit scheme can use beta_i = gamma directly.
   *
   * Each law is one small file in source/coupling/drag_laws/ with its
   * equation and reference, registered by name with
   * IMMERSED_GRAINS_REGISTER_DRAG_LAW; `Coupling/Drag law` selects it.
   */
  class DragLaw
  {
  public:
    virtual ~DragLaw() = default;

    /** gamma such that the drag force on the grain is gamma * w. */
    virtual double
    coefficient(const DragInput &input) const = 0;

    /**
     * Whether the law reads DragInput::mean_diameter: a polydisperse law,
     * for which the coupling projects the grains' surface as a field beside
     * their volume.
     */
    virtual bool
    needs_mean_diameter() const
    {
      return false;
    }

    /** Particle Reynolds number 2 r rho |w| phi / mu (the seed's
     *  definition, Constant et al. 2019; doc/references.md). */
    static double
    reynolds(const DragInput &input);

    /** Names of all registered laws, sorted, '|'-separated. */
    static std::string
    names();

    /** The law registered under @p name; throws if there is none. */
    static std::unique_ptr<DragLaw>
    create(const std::string &name);

    using Factory = std::function<std::unique_ptr<DragLaw>()>;

    /** Used by the registration macro. */
    static bool
    register_law(const std::string &name,
                 const std::string &description,
                 Factory            factory);

    /** Name -> description, for the parameter documentation. */
    static std::map<std::string, std::string>
    descriptions();
  };
} // namespace ImmersedGrains

#define IMMERSED_GRAINS_REGISTER_DRAG_LAW(classname, name, description) \
  namespace                                                             \
  {                                                                     \
    const bool registered_##classname =                                 \
      ::ImmersedGrains::DragLaw::register_law(                          \
        name,                                                           \
        description,                                                    \
        []                                                              \
        {                                                               \
          return std::unique_ptr<::ImmersedGrains::DragLaw>(            \
            new ::ImmersedGrains::classname());                         \
        });                                                             \
  }

#endif
