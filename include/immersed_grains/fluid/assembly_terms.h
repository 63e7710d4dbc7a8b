#ifndef immersed_grains_fluid_assembly_terms_h
#define immersed_grains_fluid_assembly_terms_h

#include <deal.II/base/function.h>
#include <deal.II/base/point.h>
#include <deal.II/base/quadrature_lib.h>
#include <deal.II/base/tensor.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/fe/mapping.h>
#include <deal.II/grid/tria.h>

#include <immersed_grains/fluid/mixture_fields.h>
#include <immersed_grains/mesh/geometry.h>

#include <array>
#include <memory>
#include <vector>

namespace ImmersedGrains
{
  /**
   * The Taylor-Hood shape functions at one quadrature point, by scalar
   * function: each velocity shape function is a scalar Q2 function N_a
   * times a unit vector e_c, each pressure function a Q1 function Np_b.
   * Gradients are stored by coordinate, contiguous in the function index,
   * so that the loops over pairs of functions vectorise.
   */
  template <int dim>
  struct ScalarShapes
  {
    void
    resize(unsigned int n_velocity, unsigned int n_pressure);

    std::vector<double>                  N, Np;
    std::array<std::vector<double>, dim> G, Gp;
  };


  /**
   * The local index of each Taylor-Hood shape function by scalar function:
   * velocity[a][c] for component c of Q2 function a, pressure[b] for Q1
   * function b.
   */
  template <int dim>
  struct ScalarDofs
  {
    explicit ScalarDofs(const dealii::FESystem<dim> &fe);

    std::vector<std::array<unsigned int, dim>> velocity;
    std::vector<unsigned int>                  pressure;
  };


  /** The discrete solution and the mixture at one quadrature point. */
  template <int dim>
  struct PointState
  {
    dealii::Tensor<1, dim> u;         // current iterate
    dealii::Tensor<2, dim> grad_u;    // (grad u)_cd = du_c/dx_d
    dealii::Tensor<1, dim> u_history; // (a1 u^n + a2 u^{n-1}), BDF weights
    dealii::Tensor<1, dim> u_last;    // u^n, where the drag field needs it
    double                 p = 0;
    dealii::Tensor<1, dim> grad_p;

    double                 phi = 1; // fluid fraction
    dealii::Tensor<1, dim> grad_phi;
    double                 beta = 0; // drag coefficient field
    dealii::Tensor<1, dim> grain_velocity;
    double                 beta_last = 0; // its share against u_last
    dealii::Tensor<1, dim> solid_flux;    // (1 - phi) u_p, explicit part
    double                 mass_source           = 0;
    double                 solid_flux_divergence = 0; // -d(phi_s)/dt
    double                 alpha    = 0; // pressure-gradient weight
    double                 mobility = 0; // pressure mobility k
    dealii::Tensor<1, dim> forcing;
  };


  /**
   * What the momentum terms contribute at one point to the velocity rows,
   * for the test function N_a e_c and the trial function N_b e_d:
   *
   *   matrix:   reaction N_a N_b delta_cd + diffusion grad N_a . grad N_b
   *             delta_cd + convection_weight N_a (convection . grad N_b)
   *             delta_cd + convection_weight convection_derivative_cd
   *             N_a N_b,
   *   residual: force_c N_a + stress_c . grad N_a
   *             - pressure (phi dN_a/dx_c + dphi/dx_c N_a).
   *
   * The cell kernel (fluid_assembly.cc) integrates them once, whatever
   * terms contributed, so a term costs its few flops per point.
   */
  template <int dim>
  struct MomentumCoefficients
  {
    double                 reaction          = 0;
    double                 diffusion         = 0;
    double                 convection_weight = 0;
    double                 pressure          = 0;
    dealii::Tensor<1, dim> convection;
    dealii::Tensor<2, dim> convection_derivative;
    dealii::Tensor<1, dim> force;
    dealii::Tensor<2, dim> stress;
  };


  /**
   * A cell's integrals in scalar blocks: K (one velocity component against
   * itself, the same for all), W (Newton's component couplings, dim x dim
   * blocks), B (velocity component c against pressure, also the
   * continuity block's transpose), C (pressure against pressure), the
   * residual rows, and the Schur-approximation pieces Mp (weighted
   * pressure mass) and R (mass-and-drag diagonal).
   */
  struct CellIntegrals
  {
    void
    resize(unsigned int dim,
           unsigned int n_velocity,
           unsigned int n_pressure,
           bool         newton);
    void
    clear(bool preconditioner_pieces);

    unsigned int        n_s = 0, n_p = 0;
    std::vector<double> K, W, B, C, rhs_u, rhs_p, Mp, R;
  };


  /** What a cell-level term needs to know of the cell. */
  template <int dim>
  struct CellContext
  {
    typename dealii::Triangulation<dim>::active_cell_iterator cell;
    // The shape functions and the weights at the cell's quadrature points.
    const std::vector<ScalarShapes<dim>> *shapes = nullptr;
    const std::vector<double>            *JxW    = nullptr;
    // The current iterate's coefficients on the cell (local numbering).
    const std::vector<double> *local_solution        = nullptr;
    bool                       preconditioner_pieces = false;
  };


  /**
   * One term of the averaged Navier-Stokes weak form (doc/theory.md). The
   * assembly keeps a list of the terms a scene needs, so a term it
   * switches off is not visited: Stokes has no advection term, a steady
   * scene no time derivative, a scene without grains no grain drag.
   * point() adds to the coefficients at each quadrature point (and, for
   * the pressure term, to the pressure blocks directly); cell() adds what
   * is not a volume integral of the fields (grains at points, faces).
   */
  template <int dim>
  class AssemblyTerm
  {
  public:
    virtual ~AssemblyTerm() = default;

    virtual void
    point(const PointState<dim>     &state,
          const ScalarShapes<dim>   &shapes,
          double                     JxW,
          MomentumCoefficients<dim> &coefficients,
          CellIntegrals             &integrals) const;

    virtual void
    cell(const CellContext<dim> &context, CellIntegrals &integrals) const;

    /** Whether point() writes convection (or its derivative). */
    virtual bool
    convects() const;
    virtual bool
    linearises_convection() const;
  };


  /** phi rho (a0 u + a1 u^n + a2 u^{n-1}) / dt: BDF1 or BDF2. */
  template <int dim>
  class TimeDerivativeTerm : public AssemblyTerm<dim>
  {
  public:
    TimeDerivativeTerm(double density, double a0, double inv_dt);
    void
    point(const PointState<dim> &,
          const ScalarShapes<dim> &,
          double,
          MomentumCoefficients<dim> &,
          CellIntegrals &) const override;

  private:
    const double density, a0, inv_dt;
  };


  /** beta (u - u_p): a drag coefficient field (filtered drag, or given). */
  template <int dim>
  class DragFieldTerm : public AssemblyTerm<dim>
  {
  public:
    void
    point(const PointState<dim> &,
          const ScalarShapes<dim> &,
          double,
          MomentumCoefficients<dim> &,
          CellIntegrals &) const override;
  };


  /** (phi mu grad u, grad v): the mixture's viscous stress. */
  template <int dim>
  class ViscousTerm : public AssemblyTerm<dim>
  {
  public:
    explicit ViscousTerm(double viscosity);
    void
    point(const PointState<dim> &,
          const ScalarShapes<dim> &,
          double,
          MomentumCoefficients<dim> &,
          CellIntegrals &) const override;

  private:
    const double viscosity;
  };


  /**
   * phi rho (grad u) u, linearised about the iterate: Picard (the Oseen
   * operator phi rho (grad du) u) or Newton (plus phi rho (grad u) du).
   */
  template <int dim>
  class AdvectionTerm : public AssemblyTerm<dim>
  {
  public:
    AdvectionTerm(double density, bool newton, bool skew_symmetric);
    void
    point(const PointState<dim> &,
          const ScalarShapes<dim> &,
          double,
          MomentumCoefficients<dim> &,
          CellIntegrals &) const override;
    bool
    convects() const override;
    bool
    linearises_convection() const override;

  private:
    const double density;
    const bool   newton;
    // Fluid/Advection form = skew-symmetric.
    const bool skew_symmetric;
  };


  /** -(f, v): a body force per unit volume of the mixture. */
  template <int dim>
  class ForcingTerm : public AssemblyTerm<dim>
  {
  public:
    void
    point(const PointState<dim> &,
          const ScalarShapes<dim> &,
          double,
          MomentumCoefficients<dim> &,
          CellIntegrals &) const override;
  };


  /**
   * The pressure and the mixture's continuity, a saddle point with
   * symmetric coupling:
   *   velocity rows  -(p, div(phi v)) + (alpha grad p, v),
   *   pressure rows  -(q, div(phi u) - g) + (grad q, s + alpha u - k grad p),
   * with div(phi v) = phi div v + grad phi . v, s the solid flux
   * integrated by parts (walls let no grain through), alpha and k the
   * pressure weight and mobility of the grains tied to the fluid by
   * their implicit drag (doc/theory.md 3).
   */
  template <int dim>
  class PressureContinuityTerm : public AssemblyTerm<dim>
  {
  public:
    void
    point(const PointState<dim> &,
          const ScalarShapes<dim> &,
          double,
          MomentumCoefficients<dim> &,
          CellIntegrals &) const override;
  };


  /**
   * The grains' implicit drag at their points: beta_i (u(x_i) - v_i)
   * tested with N_a(x_i) (deal.II step-70's way), or, with the cell
   * spread, the sum over the cell's grains of beta_i against the cell
   * mean of the velocity and of the test functions.
   */
  template <int dim>
  class GrainDragTerm : public AssemblyTerm<dim>
  {
  public:
    GrainDragTerm(const PointDragSource<dim>  &source,
                  const dealii::FESystem<dim> &fe,
                  const ScalarDofs<dim>       &dofs,
                  bool                         cell_averaged,
                  double                      &max_beta);
    void
    cell(const CellContext<dim> &, CellIntegrals &) const override;

  private:
    const PointDragSource<dim>         &source;
    const dealii::FiniteElement<dim>   &element;
    const ScalarDofs<dim>              &dofs;
    const bool                          cell_averaged;
    double                             &max_beta;
    mutable std::vector<PointDrag<dim>> drags;
    mutable std::vector<double>         shape;
  };


  /**
   * Open faces: the weakly imposed pressure <phi p_open, v.n>. Open and
   * velocity faces: the solid flux that leaves, -<q, s.n>, where the solid
   * crosses them (prescribed mixture fields). Grains meet velocity faces
   * as walls and leave through open ones whole when their centre crosses,
   * their volume then taken out as a sink: no solid flux of theirs passes
   * a boundary.
   */
  template <int dim>
  class BoundaryFluxTerm : public AssemblyTerm<dim>
  {
  public:
    BoundaryFluxTerm(const dealii::Mapping<dim>  &mapping,
                     const dealii::FESystem<dim> &fe,
                     const ScalarDofs<dim>       &dofs,
                     const Geometry<dim>         &geometry,
                     const MixtureFields<dim>    &mixture_fields,
                     dealii::Function<dim>       &open_pressure,
                     double                       time,
                     bool                         solid_crosses_boundaries,
                     double                       backflow_weight);
    void
    cell(const CellContext<dim> &, CellIntegrals &) const override;

    /** Whether any face of the geometry is open, or carries a velocity
     * that the solid crosses. */
    static bool
    needed(const Geometry<dim> &geometry, bool solid_crosses_boundaries);

  private:
    const Geometry<dim> &geometry;
    const bool           solid_crosses_boundaries;
    // b rho of the backflow term on open faces (0: none, as for Stokes).
    const double                                 backflow_weight;
    const MixtureFields<dim>                    &mixture_fields;
    dealii::Function<dim>                       &open_pressure;
    const double                                 time;
    const dealii::QGauss<dim - 1>                quadrature;
    mutable dealii::FEFaceValues<dim>            fe_face_values;
    std::vector<std::vector<dealii::Point<dim>>> reference_points;
    const ScalarDofs<dim>                       &dofs;
    mutable MixtureValues<dim>                   mixture;
  };
} // namespace ImmersedGrains

#endif
