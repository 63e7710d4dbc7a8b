#ifndef immersed_grains_fluid_fluid_parameters_h
#define immersed_grains_fluid_fluid_parameters_h

#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/parsed_function.h>

#include <immersed_grains/mesh/geometry.h>

#include <memory>
#include <string>

namespace ImmersedGrains
{
  /** Which approximation of the Schur complement S = B A^{-1} B^T. */
  enum class SchurApproximation
  {
    cahouet_chabard, // S^{-1} ~ M_{phi/mu}^{-1} + L_{phi^2/c}^{-1}
    pressure_mass,   // viscous limit only
    pressure_laplace // mass/drag limit only
  };

  /**
   * Everything in `subsection Fluid`. The prescribed fields (fluid
   * fraction, drag coefficient, grain velocity) describe the mixture when
   * no grains are simulated; with grains they come from the projection.
   */
  template <int dim>
  struct FluidParameters
  {
    static void
    declare_parameters(dealii::ParameterHandler &prm);

    void
    parse_parameters(dealii::ParameterHandler &prm,
                     const std::string        &file,
                     const Geometry<dim>      &geometry);

    bool   enabled   = true;
    double density   = 1.0;
    double viscosity = 1.0;
    bool   advection = true;
    // Advection form: phi rho (u.grad)u plus rho u R / 2, R the fluid's
    // pointwise mass residual (doc/theory.md).
    bool skew_symmetric_advection = false;
    // b of the open faces' inflow term -b rho phi min(u.n, 0) u.v / 2.
    double       backflow_stabilization = 1;
    bool         time_derivative        = true;
    unsigned int bdf_order              = 2;
    bool         newton                 = false;
    // One solve per step with the extrapolated advecting velocity.
    bool extrapolated_advection = true;
    // How the continuum drag is integrated (the entry "Drag coefficient
    // averaging").
    enum class DragAveraging
    {
      quadrature,
      cell,
      jump
    };
    DragAveraging drag_averaging = DragAveraging::jump;
    // With 'jump', the contrast (beta_max h^2 + phi mu)/(beta_min h^2 +
    // phi mu) inside a cell above which its drag is averaged.
    double       drag_jump_contrast       = 10;
    double       nonlinear_tolerance      = 1e-8;
    unsigned int max_nonlinear_iterations = 20;

    bool         direct_solver         = false;
    double       linear_tolerance      = 1e-8;
    unsigned int max_linear_iterations = 500;
    // FGMRES goes on while its velocity error, estimated as the velocity
    // part of P^-1 r, exceeds this fraction of the largest velocity (0:
    // never).
    double             velocity_error_tolerance = 0.05;
    SchurApproximation schur_approximation =
      SchurApproximation::cahouet_chabard;
    // The velocity block's approximate inverse: AMG V-cycles, one ILU
    // (where mass and drag dominate viscosity and advection, A is nearly
    // diagonal and an ILU is as good as a V-cycle at a fraction of its
    // cost), or chosen per build by the block's viscous number
    // (fluid_linear_solver.cc).
    enum class VelocityPreconditioner
    {
      automatic,
      amg,
      ilu
    };
    VelocityPreconditioner velocity_preconditioner =
      VelocityPreconditioner::automatic;
    // With `auto`, the ILU is chosen below this viscous number.
    double       velocity_ilu_threshold    = 1;
    unsigned int velocity_ilu_sweeps       = 1;
    unsigned int velocity_amg_cycles       = 1; // auto: 2 if steady
    unsigned int velocity_inner_iterations = 0;
    double       velocity_inner_tolerance  = 1e-6;
    unsigned int pressure_mass_iterations  = 3;
    double       pressure_mass_tolerance   = 3e-4;
    // The two-level correction (coarse_schur_correction.h): whether (auto
    // resolved), and how many times the box's coarse mesh is refined for
    // its space.
    bool         coarse_correction            = false;
    unsigned int coarse_correction_refinement = 2;
    double       preconditioner_rebuild_ratio = 1.5; // 0: every solve

    // Prescribed fields; shared so that a test can substitute exact ones.
    std::shared_ptr<dealii::Functions::ParsedFunction<dim>> fluid_fraction;
    std::shared_ptr<dealii::Functions::ParsedFunction<dim>> drag_coefficient;
    std::shared_ptr<dealii::Functions::ParsedFunction<dim>> grain_velocity;
    std::shared_ptr<dealii::Functions::ParsedFunction<dim>> forcing;
    // Whether the forcing's expression is a constant (numbers only).
    bool forcing_is_constant = false;
    std::shared_ptr<dealii::Functions::ParsedFunction<dim>> boundary_velocity;
    // The boundary velocity on inflow faces is phi u, not u.
    bool superficial_inflow = false;
    std::shared_ptr<dealii::Functions::ParsedFunction<dim>>
      open_boundary_pressure;
    std::shared_ptr<dealii::Functions::ParsedFunction<dim>> initial_velocity;
  };
} // namespace ImmersedGrains

#endif
