#ifndef immersed_grains_fluid_fluid_solver_h
#define immersed_grains_fluid_fluid_solver_h

#include <deal.II/base/conditional_ostream.h>
#include <deal.II/base/function.h>
#include <deal.II/base/index_set.h>
#include <deal.II/base/timer.h>
#include <deal.II/distributed/solution_transfer.h>
#include <deal.II/distributed/tria.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/fe/mapping.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/trilinos_block_sparse_matrix.h>
#include <deal.II/lac/trilinos_parallel_block_vector.h>
#include <deal.II/numerics/data_out.h>

#include <immersed_grains/fluid/fluid_parameters.h>
#include <immersed_grains/fluid/mixture_fields.h>
#include <immersed_grains/linear_algebra/ghost_exchange.h>
#include <immersed_grains/linear_algebra/owned_vector_memory.h>
#include <immersed_grains/mesh/cell_point_shapes.h>
#include <immersed_grains/mesh/geometry.h>

#include <functional>
#include <memory>
#include <stdexcept>

namespace ImmersedGrains
{
  class Statistics;
  class BlockSchurPreconditioner;
  class CoarseSchurCorrection;
  template <int dim>
  class CellScatter;
  class ComponentBlock;
  template <int dim>
  class CellGather;
  template <int dim>
  class AssemblyTerm;
  template <int dim>
  struct ScalarDofs;

  /**
   * A fluid step that failed (its linear or nonlinear solve did not
   * converge, or met a value that is not finite); the solver is back in
   * the state before the step, so that the caller may try a shorter one.
   */
  class FluidStepFailure : public std::runtime_error
  {
  public:
    using std::runtime_error::runtime_error;
  };

  /**
   * The volume-averaged (VANS) fluid: interstitial velocity u and pressure p
   * (minus its hydrostatic part) on Taylor-Hood Q2-Q1, solving
   *
   *   phi rho (du/dt + u.grad u) - div(phi mu grad u) + phi grad p
   *                                          + beta (u - u_p) = f,
   *   div(phi u) + div((1 - phi) u_p) = 0,
   *
   * with the mixture fields (phi, beta, u_p) supplied by a MixtureFields
   * object (doc/theory.md derives the weak form). Files:
   * fluid_solver.cc (set-up, boundary conditions, output, errors),
   * fluid_assembly.cc (one cell loop: matrix, residual, preconditioner
   * matrices), fluid_linear_solver.cc (FGMRES + block preconditioner).
   */
  template <int dim>
  class FluidSolver
  {
  public:
    using VectorType = dealii::TrilinosWrappers::MPI::BlockVector;
    using MatrixType = dealii::TrilinosWrappers::BlockSparseMatrix;

    FluidSolver(
      const FluidParameters<dim>                        &parameters,
      const Geometry<dim>                               &geometry,
      dealii::parallel::distributed::Triangulation<dim> &triangulation,
      dealii::TimerOutput                               &timer,
      dealii::ConditionalOStream                        &pcout);
    ~FluidSolver();

    /** Distributes DoFs, builds constraints and sparsity. */
    void
    setup_dofs();

    /** Sets u from Fluid/Initial velocity, p = 0. */
    void
    set_initial_condition();

    /** Before the triangulation changes: the solution and its BDF history
     *  are attached to the cells (the triangulation's flags are final). */
    void
    prepare_for_mesh_change();

    /** After it changed: DoFs, constraints and matrices anew, the three
     *  states interpolated onto the new mesh; the step sizes and the step
     *  count carry on, the preconditioner is rebuilt at the next solve. */
    void
    finish_mesh_change();

    /** Before the triangulation is saved: the three states attached to
     *  it (after the grains' data if both are saved: the order of loading
     *  follows). */
    void
    prepare_for_serialization();

    /** After a saved triangulation was loaded and setup_dofs(): the three
     *  states read back. */
    void
    deserialize();

    /** The time-stepping state (time, step sizes, steps done), exactly. */
    void
    save_state(std::ostream &out) const;
    void
    load_state(std::istream &in);

    /** @p solid_crosses_boundaries: whether the solid flux of @p fields
     * passes through open and inflow (velocity) faces, as a prescribed
     * flux does; grains meet inflow faces as walls and leave through open
     * ones whole, as a volume sink (mass_source), so none of theirs. */
    void
    set_mixture_fields(std::shared_ptr<const MixtureFields<dim>> fields,
                       bool solid_crosses_boundaries = true);

    /**
     * Grains' implicit drag (none by default): at each grain's centre
     * through the shape functions (@p cell_averaged false), or spread over
     * its cell against the cell-mean velocity (true), which removes most of
     * the velocity a point force induces at its own location.
     */
    void
    set_point_drag_source(std::shared_ptr<const PointDragSource<dim>> source,
                          bool cell_averaged = false);

    /** Fluid velocity, its gradient and the pressure gradient at a point of
     * a cell (for the interaction force on a grain). */
    struct PointValues
    {
      dealii::Tensor<1, dim> velocity;
      dealii::Tensor<1, dim> pressure_gradient;
    };
    /** With the cell-averaged drag the velocity is the cell mean. */
    std::vector<PointValues>
    point_values(
      const typename dealii::Triangulation<dim>::active_cell_iterator &cell,
      const std::vector<dealii::Point<dim>> &reference_locations) const;

    /** Replaces the forcing and boundary data (tests with exact solutions). */
    void
    set_forcing(std::shared_ptr<dealii::Function<dim>> forcing);
    void
    set_boundary_velocity(std::shared_ptr<dealii::Function<dim>> velocity);

    struct StepStatistics
    {
      unsigned int nonlinear_iterations = 0;
      unsigned int linear_iterations    = 0; // summed over nonlinear steps
      double       initial_residual     = 0;
      double       final_residual       = 0;
      // Cells whose drag was integrated with its cell means (the entry
      // "Drag coefficient averaging"); there the fluid feels the mean
      // drag coefficient against its own velocity, not the drag that a
      // filtered grain drag gives the grains.
      unsigned int drag_averaged_cells = 0;
      // Preconditioners built in this step (0: the kept one served).
      unsigned int preconditioner_builds = 0;

      /** The statistics columns of a fluid step (doc/output.md). */
      static std::vector<std::string>
      column_names();
      /** @p builds_so_far: preconditioners built since the start (the
       *  column is cumulative). */
      void
      set_statistics(Statistics &statistics, unsigned int builds_so_far) const;
    };

    /** Advances from the current time to @p new_time = time + dt. A step
     *  that fails throws FluidStepFailure and leaves the solver as it was
     *  before it. */
    StepStatistics
    solve_time_step(double new_time, double dt);

    /** L2 velocity, H1-semi velocity, L2 pressure (both mean-free) errors. */
    std::array<double, 3>
    compute_errors(const dealii::Function<dim> &exact_solution) const;

    /** Adds velocity, pressure, fluid fraction, beta to @p data_out. */
    void
    add_data_vectors(dealii::DataOut<dim> &data_out) const;

    /** The pressure at a point of the mesh (collective: every rank calls
     * it; the mean over the cells that contain the point). */
    double
    pressure_at(const dealii::Point<dim> &point) const;

    /** The fluid fraction phi at @p point (collective). */
    double
    fluid_fraction_at(const dealii::Point<dim> &point) const;

    /**
     * The force of the fluid on the boundary parts with each id of @p ids
     * (per unit depth in 2D), -integral of phi sigma n with sigma = -p I +
     * mu (grad u + grad u^T), p without its hydrostatic part and n the
     * fluid's outward normal. Where the id's faces meet no other boundary
     * with a given velocity (an obstacle), it is the reaction of the
     * discrete momentum equation: the residual of the current solution
     * tested with the velocity shape functions of the id's faces, summed
     * (one assembly pass over the cells that touch those faces), which
     * converges with the flow's own order; elsewhere the traction of the
     * discrete solution integrated over the faces, which converges like
     * its gradient. Collective.
     */
    std::vector<dealii::Tensor<1, dim>>
    boundary_forces(const std::vector<dealii::types::boundary_id> &ids);

    /**
     * The fluid's volume flux out through the boundary parts with id @p id
     * (m^3/s; m^2/s in 2D): the integral of phi u.n, n the outward normal,
     * so negative through an inflow. Collective.
     */
    double
    boundary_flux(dealii::types::boundary_id id) const;

    /** The largest velocity component at a node (collective). */
    double
    max_velocity() const;

    /**
     * The fastest flow the fluid's data can drive (collective), for the
     * divergence check of Simulation: the largest of the initial velocity,
     * the boundary velocities, a prescribed grain velocity where its drag
     * acts, and the speeds that the largest body force F and open-face
     * pressure P seen so far reach across the box's diagonal L, inertial
     * (sqrt(F L / rho), sqrt(2 P / rho)) or viscous (F L^2 / mu,
     * P L / mu), whichever is larger. Gravity is the caller's: its
     * hydrostatic part is in the pressure.
     */
    double
    driven_speed() const;

    /** The integral of the fluid fraction over the mesh, and where
     *  @p mesh_volume is given the mesh's volume under the mapping (a
     *  curved boundary's volume changes with refinement). Collective. */
    double
    integrate_fluid_fraction(double *mesh_volume = nullptr) const;

    dealii::types::global_dof_index
    n_dofs() const;

    const dealii::DoFHandler<dim> &
    get_dof_handler() const;

    const VectorType &
    get_solution() const;

    /** Reads a locally owned cell's values from the solution (and every
     * ghosted vector of its layout) without look-ups in Epetra's map. */
    const CellGather<dim> &
    get_cell_gather() const;

    double
    get_time() const;

  private:
    // Calls @p add_face for each face with boundary id @p id that this
    // rank owns, with the fluid fraction at its quadrature points; the
    // FEFaceValues have @p flags and the normals, JxW and points.
    void
    integrate_over_boundary(
      dealii::types::boundary_id                             id,
      dealii::UpdateFlags                                    flags,
      const std::function<void(const dealii::FEFaceValues<dim> &,
                               const MixtureValues<dim> &)> &add_face) const;

    // Fluid/Superficial inflow: the prescribed values on inflow faces in
    // @p constraints (not yet closed) become u = U/phi.
    void
    divide_inflow_by_fluid_fraction(
      dealii::AffineConstraints<double> &constraints) const;

    // solve_time_step() without the way back.
    StepStatistics
    advance(double new_time, double dt);

    void
    make_constraints();

    // The locally owned cells that hold @p point (more than one on their
    // faces), each with the point's reference coordinates.
    std::vector<
      std::pair<typename dealii::DoFHandler<dim>::active_cell_iterator,
                dealii::Point<dim>>>
    owned_cells_around(const dealii::Point<dim> &point) const;

    // -integral of phi sigma n over the faces with id @p id.
    dealii::Tensor<1, dim>
    traction_force(dealii::types::boundary_id id) const;

    // The residual's velocity rows summed over the DoFs of some boundary
    // ids: boundary_forces().
    struct BoundaryReactions
    {
      // The velocity DoFs on each id's faces.
      std::vector<dealii::IndexSet> dofs;
      // Per id, the sum of the residual's rows of each component.
      std::vector<dealii::Tensor<1, dim>> sums;
    };

    // The system of the current iterate, or with @p reactions only the
    // residual's sums over the boundary DoFs that it names (the system
    // untouched).
    void
    assemble_system(bool               assemble_preconditioner_matrices,
                    BoundaryReactions *reactions = nullptr);

    // The terms of the weak form that the scene needs (fluid_assembly.cc),
    // those integrated at quadrature points and those added per cell.
    struct AssemblyTermList
    {
      std::vector<std::unique_ptr<AssemblyTerm<dim>>> owned;
      std::vector<const AssemblyTerm<dim> *>          at_points, on_cells;
      bool                                            convects = false;
      bool linearises_convection                               = false;
      bool forcing                                             = false;
    };
    AssemblyTermList
    make_assembly_terms(const ScalarDofs<dim> &dofs,
                        double                 density,
                        double                 viscosity,
                        double                 inv_dt,
                        double                &max_beta) const;

    // Solves for newton_update; with @p fresh_preconditioner the
    // preconditioner is built first (its matrices must have been
    // assembled), else the kept one is used.
    unsigned int
    solve_linear_system(double absolute_tolerance, bool fresh_preconditioner);

    // Whether the next solve needs a new preconditioner (the entry
    // Preconditioner rebuild ratio).
    bool
    preconditioner_due() const;

    // rho-free mass coefficient a0/dt of the current step (0 if steady).
    double
    mass_coefficient() const;

    // |A x + r| over the unconstrained rows, with A and r = system_rhs as
    // assembled at the iterate x: the size of the right-hand side.
    double
    right_hand_side_norm(const VectorType &iterate) const;

    void
    build_preconditioner();

    // The refinement of the box's coarse mesh for the two-level correction,
    // or -1 where the mesh is too coarse for it (collective).
    int
    coarse_correction_level() const;

    // Whether the velocity block couples different components: only
    // through Newton's derivative of the advection term (the slip faces of
    // a box are normal to an axis and fix one component each).
    bool
    velocity_components_coupled() const;

    void
    normalize_pressure(VectorType &vector) const;

    bool
    pressure_has_null_space() const;

    const FluidParameters<dim>                        &parameters;
    const Geometry<dim>                               &geometry;
    dealii::parallel::distributed::Triangulation<dim> &triangulation;
    dealii::TimerOutput                               &timer;
    dealii::ConditionalOStream                        &pcout;
    MPI_Comm                                           mpi_communicator;

    dealii::FESystem<dim>   fe;
    dealii::DoFHandler<dim> dof_handler;
    // Geometry::mapping(): the Cartesian map on meshes of axis-parallel
    // cells (MappingQ1 rebuilt its support points for every FEValues
    // object, doc/performance.md), MappingQ1 on others.
    const dealii::Mapping<dim>   &mapping;
    std::vector<dealii::IndexSet> owned_partitioning;
    std::vector<dealii::IndexSet> relevant_partitioning;

    // Constraints of the solution (inhomogeneous Dirichlet data), of the
    // Newton/Picard update (homogeneous), and of the pressure mass matrix.
    dealii::AffineConstraints<double> solution_constraints;
    dealii::AffineConstraints<double> update_constraints;
    dealii::AffineConstraints<double> pressure_mass_constraints;

    MatrixType system_matrix;
    MatrixType pressure_mass_matrix; // block (1,1) used
    // Diagonal of the mass-and-drag part of the velocity block plus its
    // floor where that vanishes (schur_floor_factor, fluid_assembly.cc),
    // and the Schur complement approximation B diag^{-1} B^T built from it.
    VectorType reaction_diagonal; // block 0 used
    // The integral of each pressure shape function (block-local indices,
    // summed onto the owners) and of 1: the pressure's mean is a dot
    // product, not a pass over the cells (normalize_pressure()).
    dealii::TrilinosWrappers::MPI::Vector  pressure_shape_integrals;
    double                                 domain_measure = 0;
    dealii::TrilinosWrappers::SparseMatrix schur_diagonal_matrix;

    VectorType solution;         // ghosted, current iterate / new time
    VectorType old_solution;     // ghosted, t^n
    VectorType old_old_solution; // ghosted, t^{n-1}
    VectorType system_rhs;       // owned: minus the residual
    VectorType newton_update;    // owned
    // The time step's iterate (owned), and the copies between it and the
    // ghosted vectors above.
    VectorType    step_iterate;
    GhostExchange ghost_exchange;
    // FGMRES's basis vectors, kept between solves; and the vector in which
    // right_hand_side_norm() forms A x + r.
    OwnedVectorMemory  krylov_vectors;
    mutable VectorType residual_force;

    // Shape functions at grain positions (point_values); the Q2 ones also at
    // the Gauss points for cell means.
    mutable CellPointShapes<dim> velocity_shapes, pressure_shapes;
    // The cell mean of each scalar velocity shape function: the same on
    // every cell, all of them being axis-parallel boxes (the mapping).
    std::vector<double> cell_mean_weights;

    std::shared_ptr<const MixtureFields<dim>>   mixture_fields;
    std::shared_ptr<const PointDragSource<dim>> point_drag_source;
    bool                                        cell_averaged_drag = false;
    unsigned int drag_averaged_cells = 0; // in the last assembly
    std::shared_ptr<dealii::Function<dim>> forcing;
    // A forcing given as zeros: its term is left out of the assembly.
    bool                                   forcing_is_zero = false;
    std::shared_ptr<dealii::Function<dim>> boundary_velocity;

    // What the data drive (driven_speed()): maxima on this rank since the
    // start (of this process: a resumed run starts them afresh).
    double max_initial_speed          = 0;
    double max_boundary_speed         = 0;
    double max_forcing                = 0; // |f|, N/m^3
    double max_prescribed_grain_speed = 0; // where beta > 0, without grains
    double max_open_pressure          = 0; // |p| on open faces, Pa
    // Whether the mixture fields are the prescribed functions, not grains'.
    bool fields_prescribed = true;
    // Whether the mixture's solid flux passes through inflow faces
    // (set_mixture_fields()).
    bool solid_crosses_boundaries = true;

    // Samples the open-face pressure at the faces' vertices.
    void
    sample_open_pressure();

    double       time       = 0;
    double       dt         = 0;
    double       old_dt     = 0;
    unsigned int steps_done = 0;
    // BDF coefficients of u^{n+1}, u^n, u^{n-1} (divided by dt when used).
    std::array<double, 3> bdf = {{0, 0, 0}};

    // Direct insertion of the cell matrices where the constraints allow
    // it (cell_scatter.h), rebuilt with the matrix.
    std::unique_ptr<CellScatter<dim>> cell_scatter;
    // Each owned cell's DoFs in the ghosted vectors (cell_gather.h).
    std::unique_ptr<CellGather<dim>> cell_gather;

    // The velocity block stored once for its dim components, where it is
    // K (x) I_dim (component_block.h); null where it is not. Set up with
    // the matrix, its values copied after each assembly.
    std::unique_ptr<ComponentBlock> velocity_block;

    std::unique_ptr<BlockSchurPreconditioner> preconditioner;
    // Its second level (Linear solver/Coarse correction), once per mesh.
    std::unique_ptr<CoarseSchurCorrection> coarse_schur;
    // Whether any drag is present; without it and without inertia (steady
    // Stokes) the Laplacian term of the Schur approximation is left out,
    // except in elongated boxes (build_preconditioner()).
    bool schur_has_drag = false;
    // The velocity block's viscous number in the last assembly of the
    // preconditioner matrices (fluid_assembly.cc), and whether the last
    // build chose the ILU for it.
    double velocity_viscous_number = 0;
    bool   velocity_ilu            = false;
    // Preconditioner reuse: the iterations of the first solve after the
    // last rebuild, whether a slower solve asked for a new one, and the
    // mass coefficient it was built for.
    unsigned int iterations_after_rebuild = 0;
    // The velocity-error check (Linear solver/Velocity error tolerance):
    // the factor its last finding put on Tolerance, and the solves since
    // it last ran.
    double       velocity_tolerance_factor   = 1;
    unsigned int solves_since_velocity_check = 0;
    unsigned int builds                      = 0; // since the start
    bool         rebuild_requested           = false;
    double       built_mass_coefficient      = 0;

    // DataOut keeps a pointer to the postprocessor until patches are built.
    mutable std::unique_ptr<dealii::DataPostprocessor<dim>> output_fields;

    std::unique_ptr<
      dealii::parallel::distributed::SolutionTransfer<dim, VectorType>>
      transfer;
  };
} // namespace ImmersedGrains

#endif
