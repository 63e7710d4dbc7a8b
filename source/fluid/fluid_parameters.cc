#include <deal.II/base/exceptions.h>
#include <deal.II/base/utilities.h>

#include <immersed_grains/fluid/fluid_parameters.h>
#include <immersed_grains/parameters.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <sstream>
#include <string>

namespace ImmersedGrains
{
  namespace
  {
    // Whether a function expression is numbers only (components separated
    // by ';'): then it is a constant, which the cell loop evaluates without
    // muparser (6 % of a 3D assembly, doc/performance.md).
    bool
    is_number_list(const std::string &expression)
    {
      const auto components =
        dealii::Utilities::split_string_list(expression, ';');
      double value;
      return !components.empty() &&
             std::all_of(components.begin(),
                         components.end(),
                         [&](const std::string &component)
                         { return parse_number(component, value); });
    }

    // The prescribed fields, their components and defaults, in one table so
    // that declaration and parsing cannot drift apart.
    struct FieldEntry
    {
      const char *name;
      bool        vector_valued;
      const char *default_value;
      const char *documentation;
    };

    const FieldEntry field_entries[] = {
      {"Fluid fraction",
       false,
       "1",
       "Prescribed fluid fraction phi(x,t) in (0,1] when no grains are "
       "simulated."},
      {"Drag coefficient",
       false,
       "0",
       "Prescribed drag coefficient beta(x,t) [kg/(m^3 s)] of the term "
       "beta (u_f - u_p) when no grains are simulated."},
      {"Grain velocity",
       true,
       "0",
       "Prescribed grain velocity field u_p(x,t) [m/s] when no grains are "
       "simulated."},
      {"Forcing",
       true,
       "0",
       "Body force per unit volume f(x,t) [N/m^3] on the fluid (the "
       "hydrostatic part of gravity is already in the pressure)."},
      {"Boundary velocity",
       true,
       "0",
       "Fluid velocity on faces whose boundary condition is 'velocity'."},
      {"Open boundary pressure",
       false,
       "0",
       "Pressure (minus hydrostatic) imposed weakly on 'open' faces."},
      {"Initial velocity", true, "0", "Fluid velocity at t = 0."}};

    std::string
    vector_default(const char *component, const int dim)
    {
      std::string s = component;
      for (int d = 1; d < dim; ++d)
        s += std::string("; ") + component;
      return s;
    }
  } // namespace


  template <int dim>
  void
  FluidParameters<dim>::declare_parameters(dealii::ParameterHandler &prm)
  {
    using namespace dealii::Patterns;
    prm.enter_subsection("Fluid");
    {
      prm.declare_entry("Enabled",
                        "true",
                        Bool(),
                        "Solve the averaged fluid. Without it grains move in "
                        "vacuum (dry granular scenes).");
      prm.declare_entry(
        "Inflow velocity",
        "",
        Anything(),
        "The fluid velocity on 'inflow' (or 'velocity') boundaries: one "
        "expression per component separated by ';', each a function of x, "
        "y[, z] and t (deal.II FunctionParser), e.g. '0; 6*x*(1-x)'. Empty: "
        "the subsection Boundary velocity gives it (zero by default).");
      prm.declare_entry(
        "Superficial inflow",
        "false",
        Bool(),
        "false: the Inflow velocity is the fluid's own (interstitial) "
        "velocity u at the boundary; true: it is the superficial velocity "
        "phi u, the flow rate per unit area that a pump and a distributor "
        "plate fix, so the fluid enters at u = U/phi where grains on or "
        "near the boundary lower phi (a fluidized bed resting on its "
        "inflow).");
      prm.declare_entry("Density",
                        "1000",
                        Double(),
                        "Fluid density rho [kg/m^3].");
      prm.declare_entry("Viscosity",
                        "1e-3",
                        Double(),
                        "Dynamic viscosity mu [Pa s].");
      prm.declare_entry("Advection",
                        "true",
                        Bool(),
                        "Keep the advection term phi rho (u.grad)u "
                        "(Navier-Stokes); false gives Stokes.");
      prm.declare_entry(
        "Advection form",
        "convective",
        Selection("convective|skew-symmetric"),
        "convective: phi rho (u.grad)u. skew-symmetric: plus rho u R / 2, "
        "R = d(phi)/dt + div(phi u) the fluid's mass residual at each "
        "point (zero where the continuity holds pointwise; the discrete "
        "one holds only against the pressure's test functions), so that "
        "the advection neither makes nor takes kinetic energy inside the "
        "domain (Temam's form, for the fluid fraction). Keeps a coupled "
        "flow at high cell Reynolds number from diverging where the solid "
        "fraction changes fast (an immersed silo's orifice); costs the "
        "grains' flux projected once more per step under the implicit "
        "coupling. With prescribed fields d(phi)/dt is taken as 0.");
      prm.declare_entry(
        "Backflow stabilization",
        "1",
        Double(0, 1),
        "With Advection, on 'open' faces where the fluid flows in: the "
        "advection term carries kinetic energy in there that nothing "
        "bounds (the backflow divergence of outlets that eddies cross). "
        "The term -b rho phi min(u.n, 0) u.v / 2 on those faces takes it "
        "out again (Bazilevs et al. 2009; Moghadam et al. 2011): b = 1 all "
        "of it, 0 none. Where the fluid leaves, nothing changes.");
      prm.declare_entry("Time derivative",
                        "true",
                        Bool(),
                        "Keep phi rho du/dt; false solves a steady problem at "
                        "every step.");
      prm.declare_entry("Time scheme",
                        "BDF2",
                        Selection("BDF1|BDF2"),
                        "Implicit Euler (BDF1) or second-order BDF with "
                        "variable step (the first step is BDF1).");
      prm.declare_entry(
        "Drag coefficient averaging",
        "jump",
        Selection("jump|quadrature|cell"),
        "How the continuum drag beta (u - u_p) (prescribed, or filtered "
        "from the grains) is integrated: 'quadrature' with beta and u_p at "
        "each quadrature point; 'cell' with beta and beta u_p replaced by "
        "their means over each cell (same total drag coefficient and grain "
        "momentum per cell); 'jump' with the cell means only in the cells "
        "where beta jumps, (beta_max h^2 + phi mu)/(beta_min h^2 + phi mu) > "
        "10 over the cell's quadrature points, and at the quadrature points "
        "elsewhere. Where beta jumps by orders of magnitude inside cells, "
        "'quadrature' leaves velocity modes in the cut cells that the drag "
        "does not see, and the block preconditioner needs 5 to 30 times "
        "more iterations or does not converge; with 'cell' every mode of a "
        "cell feels its drag (doc/benchmarks.md, the drag-jump cells), but "
        "for a smooth beta the velocity converges at second instead of "
        "third order in L2. 'jump' converges like 'cell' on jumps and keeps "
        "the third order of 'quadrature' where beta is smooth on the mesh.");
      prm.declare_entry(
        "Linearization",
        "Extrapolated",
        Selection("Extrapolated|Picard|Newton"),
        "How the advection term is linearised. Extrapolated: one linear "
        "solve per time step, advected by the velocity extrapolated from "
        "the last two steps (u* = (1 + w) u^n - w u^{n-1}, w the step ratio; "
        "second order with BDF2, semi-implicit, so the step must resolve "
        "the flow: Adaptive time step keeps it within the Courant number). "
        "Picard (Oseen) and Newton iterate to Nonlinear tolerance, several "
        "assemblies and solves per step. A steady problem (Time derivative "
        "= false) is solved by Picard iterations under Extrapolated too.");
      prm.declare_entry("Nonlinear tolerance",
                        "1e-8",
                        Double(0),
                        "Relative reduction of the nonlinear residual.");
      prm.declare_entry("Max nonlinear iterations", "20", Integer(1));

      prm.enter_subsection("Linear solver");
      {
        prm.declare_entry("Type",
                          "iterative",
                          Selection("iterative|direct"),
                          "FGMRES with the block preconditioner, or a sparse "
                          "direct solver (Amesos KLU; small problems only).");
        prm.declare_entry(
          "Tolerance",
          "1e-6",
          Double(0),
          "Relative residual reduction of the outer solver; it stops "
          "earlier once the residual is a tenth of this times the norm of "
          "the whole right-hand side (the extrapolated start leaves a small "
          "residual to reduce). 1e-6 moved the "
          "2D cloud's centroid by 0.004% of its fall against 1e-8 for 40% "
          "fewer iterations (doc/performance.md).");
        prm.declare_entry("Max iterations", "500", Integer(1));
        prm.declare_entry(
          "Velocity error tolerance",
          "0.05",
          Double(0),
          "After FGMRES meets Tolerance, its velocity error is estimated as "
          "the velocity part of the preconditioner applied to the residual "
          "(one more application); while it exceeds this fraction of the "
          "largest velocity, FGMRES goes on with a tolerance up to 1000 "
          "times tighter, three times at most. A residual relative to the "
          "right-hand side says little about velocities far below the "
          "velocity that right-hand side drives: a packed suspension that "
          "settles at 1e-8 of its free-fall velocity over a step had "
          "velocity errors ten times its settling velocity at Tolerance = "
          "1e-6 (estimated ratio 0.7-23), other scenes 1e-6 to 0.04 "
          "(doc/stability.md). 0: no estimate.");
        prm.declare_entry(
          "Schur complement",
          "Cahouet-Chabard",
          Selection("Cahouet-Chabard|pressure mass|pressure Laplacian"),
          "Approximation of the inverse Schur complement: the sum of the "
          "phi/mu-weighted pressure mass matrix (viscous limit) and of "
          "(B diag(c M)^{-1} B^T)^{-1}, c = phi rho a0/dt + beta (mass- and "
          "drag-dominated limit; a Darcy-like pressure Laplacian), as "
          "Cahouet-Chabard do, or either limit alone.");
        prm.declare_entry(
          "Velocity preconditioner",
          "auto",
          Selection("auto|AMG|ILU"),
          "Approximate inverse of the velocity block A = c M + K_visc + "
          "K_adv (c = phi rho a0/dt + beta): AMG V-cycles (Velocity AMG "
          "cycles), one incomplete LU factorisation of A, or auto: the ILU "
          "where the block's viscous number, the largest over the mesh of "
          "phi mu/(c h^2) and phi rho |u|/(c h) with h the cell's velocity "
          "node spacing, is below Velocity ILU threshold, else AMG. Small "
          "viscous numbers are time steps far below the viscous time h^2/nu "
          "or strong drag: A is then nearly its diagonal and the ILU does in "
          "one sweep what a V-cycle does at several times its cost "
          "(doc/performance.md). Steady problems without drag everywhere "
          "always take AMG.");
        prm.declare_entry("Velocity ILU threshold",
                          "1",
                          Double(0),
                          "With Velocity preconditioner = auto, the viscous "
                          "number below which the ILU is used "
                          "(doc/performance.md measures the choice).");
        prm.declare_entry("Velocity ILU sweeps",
                          "1",
                          Integer(1, 10),
                          "ILU sweeps per application of the velocity "
                          "block's inverse where the ILU is chosen "
                          "(doc/performance.md).");
        prm.declare_entry(
          "Velocity AMG cycles",
          "auto",
          Selection("auto|1|2|3|4|5|6|7|8|9|10"),
          "AMG V-cycles per application of the velocity block's inverse. "
          "auto: one with a time derivative, whose mass term keeps the "
          "outer iterations bounded with one cycle (the 2D and 3D clouds' "
          "solves take 25-39 % less time than with two), two for steady "
          "flow, where one cycle lets them grow on fine meshes with strong "
          "drag (doc/performance.md, doc/benchmarks.md).");
        prm.declare_entry(
          "Velocity inner iterations",
          "0",
          Integer(0, 1000),
          "0: the velocity block's inverse is Velocity AMG cycles V-cycles "
          "(cheap; enough up to a drag contrast of about 1e4). N > 0: up to "
          "N GMRES iterations preconditioned by one V-cycle, for drag "
          "jumping by many orders of magnitude (doc/benchmarks.md).");
        prm.declare_entry("Velocity inner tolerance",
                          "1e-6",
                          Double(0, 1),
                          "Relative residual at which the inner iterations "
                          "stop before Velocity inner iterations.");
        prm.declare_entry(
          "Pressure mass iterations",
          "3",
          Integer(1, 100),
          "How the inverse of the phi/mu-weighted pressure mass matrix in the "
          "Schur complement approximation is applied: 1 is one ILU; N > 1 is "
          "at most N conjugate-gradient iterations preconditioned by that "
          "ILU, stopped at Pressure mass tolerance. On several ranks the "
          "ILU is block-Jacobi, and a single one cost up to 50% more outer "
          "iterations than on one rank (doc/benchmarks.md).");
        prm.declare_entry(
          "Pressure mass tolerance",
          "3e-4",
          Double(0, 1),
          "Relative residual at which the conjugate-gradient iterations of "
          "Pressure mass iterations stop. Below it the outer iterations no "
          "longer change; on one rank the ILU alone reaches it in most "
          "scenes, and one iteration is done. 0: always Pressure mass "
          "iterations (doc/performance.md).");
        prm.declare_entry(
          "Coarse correction",
          "auto",
          Selection("auto|true|false"),
          "A second level for the block preconditioner: the Stokes problem "
          "on a coarse Taylor-Hood space (the box's coarse mesh refined "
          "Coarse correction refinement times, its velocities split between "
          "the regions where viscosity and where mass or drag dominate), its "
          "operators the Galerkin products of the assembled blocks, solved "
          "exactly before each application. It catches the pressure modes "
          "that vary slowly along an elongated box, which the Schur "
          "complement approximation misses: steady flow in a 2D column "
          "1 x 8 with a region of drag takes 13-22 instead of 25-40 FGMRES "
          "iterations at a tolerance of 1e-8, in about the same time, and a "
          "packed 2D bed across a channel 23 instead of 57 over seven steps. "
          "auto: on for steady flow (Time derivative = false) in 2D boxes at "
          "least twice as long as their shortest side; in 3D and with a time "
          "derivative its set-up costs more than it saves "
          "(doc/adaptivity.md).");
        prm.declare_entry(
          "Coarse correction refinement",
          "2",
          Integer(0, 8),
          "How many times the box's coarse mesh (Mesh/Subdivisions) is "
          "refined for the coarse space of Coarse correction: at most one "
          "level below the mesh's coarsest cells, and fewer where the coarse "
          "mesh would exceed 4096 cells (2D) or 512 (3D).");
        prm.declare_entry(
          "Preconditioner rebuild ratio",
          "1.5",
          Double(0),
          "The preconditioner (AMG hierarchies, Schur complement pieces) is "
          "kept across nonlinear iterations and time steps and rebuilt when "
          "a solve takes more than this many times the iterations of the "
          "first solve after the last rebuild (plus 3), when the mass "
          "coefficient rho a0/dt changes by more than 25%, when a solve "
          "fails (with the kept preconditioner: once it needs three times "
          "the iterations that would ask for a rebuild, at least 30), or "
          "after a mesh change. 0: rebuilt before every solve "
          "(doc/performance.md).");
      }
      prm.leave_subsection();

      for (const FieldEntry &f : field_entries)
      {
        prm.enter_subsection(f.name);
        dealii::Functions::ParsedFunction<dim>::declare_parameters(
          prm, f.vector_valued ? dim : 1);
        prm.set("Function expression",
                f.vector_valued ? vector_default(f.default_value, dim) :
                                  std::string(f.default_value));
        prm.leave_subsection();
      }
    }
    prm.leave_subsection();
  }


  template <int dim>
  void
  FluidParameters<dim>::parse_parameters(dealii::ParameterHandler &prm,
                                         const std::string        &file,
                                         const Geometry<dim>      &geometry)
  {
    const InputLocation where{file, "Fluid"};
    prm.enter_subsection("Fluid");
    {
      enabled            = prm.get_bool("Enabled");
      superficial_inflow = prm.get_bool("Superficial inflow");
      density            = prm.get_double("Density");
      viscosity          = prm.get_double("Viscosity");
      where.require(density > 0,
                    "Density",
                    prm.get("Density"),
                    "must be positive");
      where.require(viscosity > 0,
                    "Viscosity",
                    prm.get("Viscosity"),
                    "must be positive");
      advection                = prm.get_bool("Advection");
      backflow_stabilization   = prm.get_double("Backflow stabilization");
      skew_symmetric_advection = prm.get("Advection form") == "skew-symmetric";
      time_derivative          = prm.get_bool("Time derivative");
      bdf_order                = prm.get("Time scheme") == "BDF2" ? 2 : 1;
      newton                   = prm.get("Linearization") == "Newton";
      extrapolated_advection   = prm.get("Linearization") == "Extrapolated";
      {
        const std::string averaging = prm.get("Drag coefficient averaging");
        drag_averaging = averaging == "cell" ? DragAveraging::cell :
                         averaging == "jump" ? DragAveraging::jump :
                                               DragAveraging::quadrature;
      }
      nonlinear_tolerance      = prm.get_double("Nonlinear tolerance");
      max_nonlinear_iterations = prm.get_integer("Max nonlinear iterations");

      prm.enter_subsection("Linear solver");
      {
        direct_solver              = prm.get("Type") == "direct";
        linear_tolerance           = prm.get_double("Tolerance");
        velocity_error_tolerance   = prm.get_double("Velocity error tolerance");
        max_linear_iterations      = prm.get_integer("Max iterations");
        const std::string schur    = prm.get("Schur complement");
        schur_approximation        = schur == "pressure mass" ?
                                       SchurApproximation::pressure_mass :
                                       (schur == "pressure Laplacian" ?
                                          SchurApproximation::pressure_laplace :
                                          SchurApproximation::cahouet_chabard);
        const std::string velocity = prm.get("Velocity preconditioner");
        velocity_preconditioner =
          velocity == "AMG" ?
            VelocityPreconditioner::amg :
            (velocity == "ILU" ? VelocityPreconditioner::ilu :
                                 VelocityPreconditioner::automatic);
        velocity_ilu_threshold   = prm.get_double("Velocity ILU threshold");
        velocity_ilu_sweeps      = prm.get_integer("Velocity ILU sweeps");
        const std::string cycles = prm.get("Velocity AMG cycles");
        velocity_amg_cycles =
          cycles == "auto" ? (time_derivative ? 1 : 2) : std::stoi(cycles);
        velocity_inner_iterations =
          prm.get_integer("Velocity inner iterations");
        velocity_inner_tolerance = prm.get_double("Velocity inner tolerance");
        pressure_mass_iterations = prm.get_integer("Pressure mass iterations");
        pressure_mass_tolerance  = prm.get_double("Pressure mass tolerance");
        preconditioner_rebuild_ratio =
          prm.get_double("Preconditioner rebuild ratio");
        const std::string coarse = prm.get("Coarse correction");
        coarse_correction =
          geometry.is_box() &&
          (coarse == "true" ||
           (coarse == "auto" && dim == 2 && !time_derivative &&
            geometry.longest_side() >= 2 * geometry.shortest_side()));
        coarse_correction_refinement =
          prm.get_integer("Coarse correction refinement");
        where.require(velocity_inner_tolerance < 1,
                      "Linear solver/Velocity inner tolerance",
                      prm.get("Velocity inner tolerance"),
                      "must be below 1");
      }
      prm.leave_subsection();
      const std::string        inflow_text = prm.get("Inflow velocity");
      dealii::ParameterHandler inflow_entry;

      // Read through a ParameterHandler of its own, so that its expression
      // is checked as the subsections' are, below.
      if (!inflow_text.empty())
      {
        inflow_entry.enter_subsection("Inflow velocity");
        dealii::Functions::ParsedFunction<dim>::declare_parameters(inflow_entry,
                                                                   dim);
        inflow_entry.set("Function expression", inflow_text);
        inflow_entry.leave_subsection();
      }

      std::shared_ptr<dealii::Functions::ParsedFunction<dim>> *targets[] = {
        &fluid_fraction,
        &drag_coefficient,
        &grain_velocity,
        &forcing,
        &boundary_velocity,
        &open_boundary_pressure,
        &initial_velocity};
      unsigned int              i     = 0;
      dealii::ParameterHandler &outer = prm;
      for (const FieldEntry &f : field_entries)
      {
        const bool inflow =
          targets[i] == &boundary_velocity && !inflow_text.empty();
        dealii::ParameterHandler &prm  = inflow ? inflow_entry : outer;
        const std::string         name = inflow ? "Inflow velocity" : f.name;
        prm.enter_subsection(name);
        auto function =
          std::make_shared<dealii::Functions::ParsedFunction<dim>>(
            f.vector_valued ? dim : 1);
        try
        {
          function->parse_parameters(prm);
          // muparser compiles an expression at its first evaluation
          // and reports errors on std::cerr itself: evaluate once now,
          // quietly, so that a bad expression is an input error.
          std::ostringstream muted;
          auto *const        cerr_buffer = std::cerr.rdbuf(muted.rdbuf());
          try
          {
            // Every component: vector_value() compiles them all.
            dealii::Vector<double> value(function->n_components);
            function->vector_value(dealii::Point<dim>(), value);
          }
          catch (...)
          {
            std::cerr.rdbuf(cerr_buffer);
            throw;
          }
          std::cerr.rdbuf(cerr_buffer);
        }
        catch (const std::exception &e)
        {
          std::string message = e.what();
          if (const auto *d = dynamic_cast<const dealii::ExceptionBase *>(&e))
          {
            std::ostringstream info;
            d->print_info(info);
            message = info.str();
          }
          where.fail(inflow ? name : name + "/Function expression",
                     prm.get("Function expression"),
                     message);
        }
        if (targets[i] == &forcing)
          forcing_is_constant = is_number_list(prm.get("Function expression"));
        *targets[i++] = function;
        prm.leave_subsection();
      }
    }
    prm.leave_subsection();

    if (!enabled)
      return;

    // A fluid fraction outside (0,1] is a modelling error that would only
    // show as a failing solver later: sample it on a grid over the box now,
    // before anything is written.
    const unsigned int n = 16;
    for (unsigned int k = 0; k < dealii::Utilities::fixed_power<dim>(n + 1);
         ++k)
    {
      dealii::Point<dim> p;
      unsigned int       index = k;
      for (unsigned int d = 0; d < dim; ++d)
      {
        const double s = (index % (n + 1)) / double(n);
        index /= (n + 1);
        p[d] = geometry.lower_corner[d] +
               s * (geometry.upper_corner[d] - geometry.lower_corner[d]);
      }
      const double phi = fluid_fraction->value(p);
      if (!(phi > 0 && phi <= 1))
      {
        std::ostringstream value;
        value << "phi(" << p << ") = " << phi;
        where.fail("Fluid fraction/Function expression",
                   value.str(),
                   "the fluid fraction must lie in (0,1]");
      }
      const double beta = drag_coefficient->value(p);
      if (!(beta >= 0))
      {
        std::ostringstream value;
        value << "beta(" << p << ") = " << beta;
        where.fail("Drag coefficient/Function expression",
                   value.str(),
                   "the drag coefficient must be non-negative");
      }
    }
  }


  template struct FluidParameters<2>;
  template struct FluidParameters<3>;
} // namespace ImmersedGrains
