#include <algorithm>
#include <cmath>
#include <limits>

#include <deal.II/base/qprojector.h>
#include <deal.II/base/quadrature_lib.h>
#include <deal.II/fe/fe_values.h>

#include <immersed_grains/fluid/cell_scatter.h>
#include <immersed_grains/fluid/fluid_solver.h>

namespace ImmersedGrains
{
  namespace
  {
    // Replaces beta and beta u_p at the quadrature points by their cell
    // means. A beta that jumps inside a cell gives a drag matrix of low
    // rank there (sum over the few points inside of beta N_i N_j): the
    // other modes of the cell stay viscous next to rows dominated by beta,
    // which neither AMG nor the Schur approximation resolve
    // (doc/benchmarks.md). The cell mean acts on all modes and keeps the
    // cell's total drag coefficient and grain momentum.
    template <int dim>
    void
    average_drag_over_cell(const dealii::FEValues<dim> &fe_values,
                           MixtureValues<dim>          &mixture)
    {
      double                 beta = 0, volume = 0;
      dealii::Tensor<1, dim> momentum;
      for (const unsigned int q : fe_values.quadrature_point_indices())
      {
        const double JxW = fe_values.JxW(q);
        beta += mixture.drag_coefficient[q] * JxW;
        momentum +=
          mixture.drag_coefficient[q] * mixture.grain_velocity[q] * JxW;
        volume += JxW;
      }
      beta /= volume;
      momentum /= volume;
      for (const unsigned int q : fe_values.quadrature_point_indices())
      {
        mixture.drag_coefficient[q] = beta;
        mixture.grain_velocity[q] =
          beta > 0 ? momentum / beta : dealii::Tensor<1, dim>();
      }
    }

    // The floor on the mass-and-drag coefficient c of S_c where c vanishes
    // (block_preconditioner.h), as a fraction of the viscous diagonal, for
    // a cell of size h in a box whose shortest side is L. Measured on the
    // drag-jump benchmark (doc/benchmarks.md, fifth and sixth rounds):
    // with exact inner solves the best floor on fine meshes is a Darcy
    // coefficient of the order of mu/L^2, i.e. a fraction of mu/h^2 that
    // falls like (h/L)^2 (a fixed fraction over-counts the Darcy term of
    // the clear fluid more on every finer mesh: 2D level 7, 57 iterations
    // with 10^-2, 26 with 10^-4); with V-cycles on A a fraction below
    // 10^-3 leaves the cycle's error in the drag region uncorrected. On
    // coarse meshes, where the ball is a few cells across, much larger
    // floors are better (h = L/8, steady, largest drag: 2D 20 -> 12 and
    // 3D 33 -> 16 iterations with 0.3 instead of 10^-2; a packed bed on
    // such a mesh 46-51 -> 38-43). Hence 10^-2 at h = L/16, falling like
    // h^2 to 10^-3 below, rising like h^5 to 0.3 above.
    double
    schur_floor_factor(const double h, const double L)
    {
      const double x = 16 * h / L;
      return x <= 1 ? std::max(1e-3, 1e-2 * x * x) :
                      std::min(0.3, 1e-2 * std::pow(x, 5));
    }

    // The factor on the phi/mu weight of the pressure mass matrix M_w in a
    // cell whose drag-to-viscosity ratio is r = beta h^2 / (phi mu) (cell
    // means of the drag coefficient field). M_w^{-1} is the viscous term of the
    // Schur complement approximation; where drag dominates, the Darcy term
    // S_c^{-1} is the right one and M_w^{-1} is negligible, except at the
    // pressure nodes on a Stokes-Darcy interface, which the drag cells' mass
    // also weighs down. Lightening the drag cells leaves M_w^{-1} there to the
    // clear fluid's side: drag-jump benchmark, steady, beta h^2/mu = 1e4 / 1e8,
    // 3D level 4: 30 / 33 -> 22 / 22 iterations, 2D level 7: 33 / 33 -> 24 /
    // 23; dt = 1, 2D level 7: 22 -> 15 (doc/benchmarks.md, seventh round). The
    // factor falls smoothly from 1 below r = 100 to 0.03, where it stops so
    // that M_w keeps a bounded contrast for its ILU (0.01 and 0.1 as the
    // bound: 23 / 21 and 21 / 24 at 3D level 4).
    double
    drag_cell_mass_factor(const double r)
    {
      return std::max(0.03, 1.0 / (1.0 + r / 100.0));
    }

    // Whether beta varies inside the cell enough for the cut-cell modes
    // above to matter: the stiffest drag-and-viscous mode against the
    // weakest, (beta_max h^2 + phi mu)/(beta_min h^2 + phi mu), compared
    // with the contrast. A beta that is smooth on the mesh never reaches it
    // (its ratio tends to 1 as h shrinks), so the averaging leaves the
    // discretisation's order alone where beta is resolved.
    template <int dim>
    bool
    drag_jumps_in_cell(const MixtureValues<dim> &mixture,
                       const double              h,
                       const double              viscosity,
                       const double              contrast)
    {
      const auto [beta_min, beta_max] =
        std::minmax_element(mixture.drag_coefficient.begin(),
                            mixture.drag_coefficient.end());
      const double viscous = *std::min_element(mixture.fluid_fraction.begin(),
                                               mixture.fluid_fraction.end()) *
                             viscosity;
      return *beta_max * h * h + viscous >
             contrast * (*beta_min * h * h + viscous);
    }
  } // namespace


  /*
   * One loop over the cells builds the Jacobian (Picard: the Oseen
   * operator; Newton: plus the derivative of the advection term), minus
   * the residual of the current iterate, and, when asked, the two pressure
   * matrices of the Schur complement approximation. With test functions
   * (v, q), the residual is
   *
   *   R_u = (phi rho (a0 u + a1 u^n + a2 u^{n-1})/dt, v)
   *       + (phi rho (grad u) u, v) + (phi mu grad u, grad v)
   *       - (p, div(phi v)) + (beta (u - u_p), v) - (f, v)
   *       + <phi p_open, v.n>_open
   *   R_p = -(q, div(phi u) - g) + (grad q, s) - <q, s.n>_{open, velocity},
   *
   * s = (1 - phi) u_p the solid volume flux (integrated by parts: walls
   * let no grain through),
   * with div(phi v) = phi div v + grad phi . v, so that the pressure and the
   * continuity blocks are transposes of each other.
   *
   * Each Taylor-Hood velocity shape function has one non-zero component, a
   * scalar Q2 function N_a times a unit vector. Every term but Newton's
   * couples a component only with itself, with the same coefficients for
   * each, so the velocity block is integrated once as a scalar n_s x n_s
   * matrix K and copied onto the dim diagonal blocks; the pressure coupling
   * B (and its transpose) as dim n_s x n_p matrices. This does about a
   * tenth of the work of a loop over all pairs of vector-valued shape
   * functions (doc/performance.md).
   */
  template <int dim>
  void
  FluidSolver<dim>::assemble_system(const bool assemble_preconditioner_matrices)
  {
    dealii::TimerOutput::Scope scope(timer, "fluid: assembly");

    system_matrix = 0;
    system_rhs    = 0;
    if (assemble_preconditioner_matrices)
    {
      pressure_mass_matrix = 0;
      reaction_diagonal    = 0;
    }

    const dealii::QGauss<dim>     quadrature(fe.degree + 1);
    const dealii::QGauss<dim - 1> face_quadrature(fe.degree + 1);
    dealii::FEValues<dim>         fe_values(mapping,
                                    fe,
                                    quadrature,
                                    dealii::update_values |
                                      dealii::update_gradients |
                                      dealii::update_quadrature_points |
                                      dealii::update_JxW_values);
    dealii::FEFaceValues<dim>     fe_face_values(
      mapping,
      fe,
      face_quadrature,
      dealii::update_values | dealii::update_normal_vectors |
        dealii::update_quadrature_points | dealii::update_JxW_values);

    // Face quadrature points in reference-cell coordinates, per face.
    std::vector<std::vector<dealii::Point<dim>>> face_reference_points;
    for (const unsigned int f : dealii::GeometryInfo<dim>::face_indices())
      face_reference_points.push_back(
        dealii::QProjector<dim>::project_to_face(
          dealii::ReferenceCells::get_hypercube<dim>(), face_quadrature, f)
          .get_points());

    const unsigned int dofs_per_cell = fe.n_dofs_per_cell();
    const unsigned int n_q           = quadrature.size();
    const dealii::FEValuesExtractors::Vector velocities(0);
    const dealii::FEValuesExtractors::Scalar pressure(dim);

    // Local index of velocity component c of scalar Q2 function a, and of
    // pressure function b.
    const unsigned int n_s = fe.base_element(0).n_dofs_per_cell();
    const unsigned int n_p = fe.base_element(1).n_dofs_per_cell();
    std::vector<std::array<unsigned int, dim>> velocity_dof(n_s);
    std::vector<unsigned int>                  pressure_dof(n_p);
    for (unsigned int k = 0; k < dofs_per_cell; ++k)
    {
      const auto [component, index] = fe.system_to_component_index(k);
      if (component < dim)
        velocity_dof[index][component] = k;
      else
        pressure_dof[index] = k;
    }

    dealii::FullMatrix<double> cell_matrix(dofs_per_cell, dofs_per_cell);
    dealii::FullMatrix<double> cell_mass(dofs_per_cell, dofs_per_cell);
    dealii::Vector<double>     cell_rhs(dofs_per_cell);
    dealii::Vector<double>     cell_reaction(dofs_per_cell);
    const double               box_size = geometry.shortest_side();
    std::vector<dealii::types::global_dof_index> dof_indices(dofs_per_cell);
    std::vector<PointDrag<dim>>                  drags;
    std::vector<double>                          point_shape(dofs_per_cell);
    std::vector<double>                          local_solution(dofs_per_cell);
    std::vector<double> local_old(dofs_per_cell), local_older(dofs_per_cell);

    // Scalar shape data at one quadrature point: N_a, grad N_a by
    // coordinate (contiguous, so the pair loops vectorise), and the same
    // for the pressure functions.
    std::vector<double>                  N(n_s), Np(n_p);
    std::array<std::vector<double>, dim> G, Gp;
    for (unsigned int d = 0; d < dim; ++d)
    {
      G[d].resize(n_s);
      Gp[d].resize(n_p);
    }
    // Cell integrals: K (velocity block of one component), W (Newton's
    // cross terms, dim x dim blocks), B (velocity-pressure coupling per
    // component, also the continuity block's transpose), C (pressure
    // mobility), Mp (weighted pressure mass), R (mass-and-drag diagonal).
    std::vector<double> K(n_s * n_s), B(dim * n_s * n_p), C(n_p * n_p),
      Mp(n_p * n_p), R(n_s), advection_weight(n_s);
    std::vector<double> W(parameters.newton ? dim * dim * n_s * n_s : 0);
    std::vector<dealii::Tensor<1, dim>> rhs_u(n_s);
    std::vector<double>                 rhs_p(n_p);

    std::vector<dealii::Vector<double>> f(n_q, dealii::Vector<double>(dim));
    MixtureValues<dim>                  mixture;

    const double rho = parameters.density, mu = parameters.viscosity;
    const double inv_dt =
      (parameters.time_derivative && dt > 0) ? 1.0 / dt : 0.0;
    const bool advection = parameters.advection;
    const bool newton    = parameters.newton && advection;
    forcing->set_time(time);
    parameters.open_boundary_pressure->set_time(time);

    double       max_beta       = 0;
    unsigned int averaged_cells = 0;
    // The largest ratio of the viscous and advective parts of A to its
    // mass-and-drag part, at the spacing of the velocity nodes: where it
    // is small, A is nearly diagonal (the entry Velocity preconditioner).
    double max_viscous_number = 0;

    unsigned int owned_cell = 0; // the cell's number for cell_scatter
    for (const auto &cell : dof_handler.active_cell_iterators())
    {
      if (!cell->is_locally_owned())
        continue;
      const unsigned int cell_number = owned_cell++;
      fe_values.reinit(cell);
      cell->get_dof_indices(dof_indices);
      for (unsigned int k = 0; k < dofs_per_cell; ++k)
        local_solution[k] = solution(dof_indices[k]);
      if (inv_dt > 0)
        for (unsigned int k = 0; k < dofs_per_cell; ++k)
        {
          local_old[k]   = old_solution(dof_indices[k]);
          local_older[k] = old_old_solution(dof_indices[k]);
        }
      std::fill(K.begin(), K.end(), 0.0);
      std::fill(B.begin(), B.end(), 0.0);
      std::fill(C.begin(), C.end(), 0.0);
      std::fill(W.begin(), W.end(), 0.0);
      std::fill(rhs_u.begin(), rhs_u.end(), dealii::Tensor<1, dim>());
      std::fill(rhs_p.begin(), rhs_p.end(), 0.0);
      if (assemble_preconditioner_matrices)
      {
        std::fill(Mp.begin(), Mp.end(), 0.0);
        std::fill(R.begin(), R.end(), 0.0);
      }
      // Integrals of the drag coefficient field and of the viscosity phi mu
      // over the cell, for drag_cell_mass_factor. Not the grains' point or
      // cell drag: rank one per grain or cell, it leaves the cell's other
      // velocity modes viscous, and counting it cost a packed bed 2 more
      // iterations per step (tests/coupled_resting_column: 40-44 instead of
      // 38-42).
      double cell_drag = 0, cell_viscosity = 0;

      mixture_fields->evaluate(cell,
                               fe_values.get_quadrature_points(),
                               quadrature.get_points(),
                               time,
                               mixture);
      const double h            = std::pow(cell->measure(), 1.0 / dim);
      const double floor_factor = schur_floor_factor(h, box_size);
      using DragAveraging       = typename FluidParameters<dim>::DragAveraging;
      if (parameters.drag_averaging == DragAveraging::cell ||
          (parameters.drag_averaging == DragAveraging::jump &&
           drag_jumps_in_cell(mixture, h, mu, parameters.drag_jump_contrast)))
      {
        average_drag_over_cell(fe_values, mixture);
        ++averaged_cells;
      }
      forcing->vector_value_list(fe_values.get_quadrature_points(), f);

      for (unsigned int q = 0; q < n_q; ++q)
      {
        for (unsigned int a = 0; a < n_s; ++a)
        {
          const unsigned int k = velocity_dof[a][0];
          N[a]                 = fe_values.shape_value(k, q);
          const auto grad      = fe_values.shape_grad(k, q);
          for (unsigned int d = 0; d < dim; ++d)
            G[d][a] = grad[d];
        }
        for (unsigned int b = 0; b < n_p; ++b)
        {
          const unsigned int k = pressure_dof[b];
          Np[b]                = fe_values.shape_value(k, q);
          const auto grad      = fe_values.shape_grad(k, q);
          for (unsigned int d = 0; d < dim; ++d)
            Gp[d][b] = grad[d];
        }

        // The current iterate and the history at this point.
        dealii::Tensor<1, dim> u, u_history;
        dealii::Tensor<2, dim> grad_u;
        double                 p = 0;
        dealii::Tensor<1, dim> grad_p;
        for (unsigned int a = 0; a < n_s; ++a)
          for (unsigned int c = 0; c < dim; ++c)
          {
            const unsigned int k = velocity_dof[a][c];
            u[c] += local_solution[k] * N[a];
            for (unsigned int d = 0; d < dim; ++d)
              grad_u[c][d] += local_solution[k] * G[d][a];
            if (inv_dt > 0)
              u_history[c] +=
                (bdf[1] * local_old[k] + bdf[2] * local_older[k]) * N[a];
          }
        for (unsigned int b = 0; b < n_p; ++b)
        {
          const double value = local_solution[pressure_dof[b]];
          p += value * Np[b];
          for (unsigned int d = 0; d < dim; ++d)
            grad_p[d] += value * Gp[d][b];
        }

        const double phi      = mixture.fluid_fraction[q];
        const auto  &grad_phi = mixture.fluid_fraction_gradient[q];
        const double beta     = mixture.drag_coefficient[q];
        const double alpha    = mixture.pressure_gradient_weight[q];
        const double mobility = mixture.pressure_mobility[q];
        const double mass     = phi * rho * bdf[0] * inv_dt;
        const double JxW      = fe_values.JxW(q);

        // Strong-form pieces of the residual at this point.
        dealii::Tensor<1, dim> momentum =
          phi * rho * inv_dt * (bdf[0] * u + u_history) +
          beta * (u - mixture.grain_velocity[q]) + alpha * grad_p;
        if (advection)
          momentum += phi * rho * (grad_u * u);
        for (unsigned int d = 0; d < dim; ++d)
          momentum[d] -= f[q](d);
        const dealii::Tensor<2, dim> viscous = phi * mu * grad_u;
        // The solid flux enters integrated by parts, (grad q, s): its
        // normal component is then zero on walls, where grains cannot pass,
        // and the continuity equation stays compatible with a pressure
        // fixed only up to a constant.
        const double continuity =
          phi * dealii::trace(grad_u) + grad_phi * u - mixture.mass_source[q];
        const dealii::Tensor<1, dim> solid_flux =
          mixture.solid_flux[q] + alpha * u - mobility * grad_p;

        // Velocity rows: momentum and viscous stress against N_a, pressure
        // against div(phi N_a e_c) = phi dN_a/dx_c + dphi/dx_c N_a.
        for (unsigned int a = 0; a < n_s; ++a)
          for (unsigned int c = 0; c < dim; ++c)
          {
            double viscous_a = 0;
            for (unsigned int d = 0; d < dim; ++d)
              viscous_a += viscous[c][d] * G[d][a];
            rhs_u[a][c] -= (momentum[c] * N[a] + viscous_a -
                            p * (phi * G[c][a] + grad_phi[c] * N[a])) *
                           JxW;
          }
        for (unsigned int b = 0; b < n_p; ++b)
        {
          double flux_b = 0;
          for (unsigned int d = 0; d < dim; ++d)
            flux_b += Gp[d][b] * solid_flux[d];
          rhs_p[b] -= (-Np[b] * continuity + flux_b) * JxW;
        }

        // K_ab += (mass + beta) N_a N_b + phi mu grad N_a . grad N_b
        //       + phi rho (u . grad N_b) N_a.
        const double w_mass    = (mass + beta) * JxW;
        const double w_viscous = phi * mu * JxW;
        for (unsigned int b = 0; b < n_s; ++b)
        {
          double adv = 0;
          if (advection)
            for (unsigned int d = 0; d < dim; ++d)
              adv += u[d] * G[d][b];
          advection_weight[b] = w_mass * N[b] + phi * rho * adv * JxW;
        }
        for (unsigned int a = 0; a < n_s; ++a)
        {
          double *row = &K[a * n_s];
          for (unsigned int b = 0; b < n_s; ++b)
          {
            double g = 0;
            for (unsigned int d = 0; d < dim; ++d)
              g += G[d][a] * G[d][b];
            row[b] += N[a] * advection_weight[b] + w_viscous * g;
          }
        }
        if (newton)
          // phi rho (grad u)_cd N_b N_a couples component c of the row
          // with component d of the column.
          for (unsigned int c = 0; c < dim; ++c)
            for (unsigned int d = 0; d < dim; ++d)
            {
              const double w     = phi * rho * grad_u[c][d] * JxW;
              double      *block = &W[(c * dim + d) * n_s * n_s];
              for (unsigned int a = 0; a < n_s; ++a)
                for (unsigned int b = 0; b < n_s; ++b)
                  block[a * n_s + b] += w * N[a] * N[b];
            }

        // B_{c,ab} = -Np_b (phi dN_a/dx_c + dphi/dx_c N_a)
        //          + alpha dNp_b/dx_c N_a.
        for (unsigned int c = 0; c < dim; ++c)
          for (unsigned int a = 0; a < n_s; ++a)
          {
            const double div_a   = (phi * G[c][a] + grad_phi[c] * N[a]) * JxW;
            const double alpha_a = alpha * N[a] * JxW;
            double      *row     = &B[(c * n_s + a) * n_p];
            for (unsigned int b = 0; b < n_p; ++b)
              row[b] += -Np[b] * div_a + alpha_a * Gp[c][b];
          }
        if (mobility != 0)
          for (unsigned int b = 0; b < n_p; ++b)
            for (unsigned int e = 0; e < n_p; ++e)
            {
              double g = 0;
              for (unsigned int d = 0; d < dim; ++d)
                g += Gp[d][b] * Gp[d][e];
              C[b * n_p + e] -= mobility * g * JxW;
            }

        if (assemble_preconditioner_matrices)
        {
          // The Schur complement approximation (block_preconditioner.h)
          // needs the pressure mass matrix weighted by phi/mu and the
          // diagonal of the mass-and-drag part c M of A,
          // c = phi rho a0/dt + beta, plus its floor (schur_floor_factor).
          const double mass_weight    = phi / mu * JxW;
          const double c              = mass + beta;
          const double spacing        = h / fe.degree;
          double       viscous_number = c > 0 ?
                                          phi * mu / (c * spacing * spacing) :
                                          std::numeric_limits<double>::infinity();
          if (advection && c > 0)
            viscous_number =
              std::max(viscous_number, phi * rho * u.norm() / (c * spacing));
          max_viscous_number = std::max(max_viscous_number, viscous_number);
          cell_drag += beta * JxW;
          cell_viscosity += phi * mu * JxW;
          max_beta = std::max(max_beta, beta);
          for (unsigned int b = 0; b < n_p; ++b)
            for (unsigned int e = 0; e < n_p; ++e)
              Mp[b * n_p + e] += mass_weight * Np[b] * Np[e];
          for (unsigned int a = 0; a < n_s; ++a)
          {
            double g = 0;
            for (unsigned int d = 0; d < dim; ++d)
              g += G[d][a] * G[d][a];
            R[a] += w_mass * N[a] * N[a] + floor_factor * w_viscous * g;
          }
        }
      }

      // The scalar integrals onto the vector-valued cell matrix.
      cell_matrix = 0;
      for (unsigned int c = 0; c < dim; ++c)
        for (unsigned int a = 0; a < n_s; ++a)
        {
          const unsigned int i = velocity_dof[a][c];
          cell_rhs(i)          = rhs_u[a][c];
          for (unsigned int b = 0; b < n_s; ++b)
            cell_matrix(i, velocity_dof[b][c]) = K[a * n_s + b];
          if (newton)
            for (unsigned int d = 0; d < dim; ++d)
              for (unsigned int b = 0; b < n_s; ++b)
                cell_matrix(i, velocity_dof[b][d]) +=
                  W[(c * dim + d) * n_s * n_s + a * n_s + b];
          for (unsigned int b = 0; b < n_p; ++b)
          {
            const double value              = B[(c * n_s + a) * n_p + b];
            cell_matrix(i, pressure_dof[b]) = value;
            cell_matrix(pressure_dof[b], i) = value;
          }
        }
      for (unsigned int b = 0; b < n_p; ++b)
      {
        cell_rhs(pressure_dof[b]) = rhs_p[b];
        for (unsigned int e = 0; e < n_p; ++e)
          cell_matrix(pressure_dof[b], pressure_dof[e]) = C[b * n_p + e];
      }
      if (assemble_preconditioner_matrices)
      {
        cell_mass     = 0;
        cell_reaction = 0;
        for (unsigned int b = 0; b < n_p; ++b)
          for (unsigned int e = 0; e < n_p; ++e)
            cell_mass(pressure_dof[b], pressure_dof[e]) = Mp[b * n_p + e];
        for (unsigned int a = 0; a < n_s; ++a)
          for (unsigned int c = 0; c < dim; ++c)
            cell_reaction(velocity_dof[a][c]) = R[a];
      }

      // Grains in this cell: beta_i (u(x_i) - v_i) . N_k(x_i), implicit.
      if (point_drag_source)
      {
        drags.clear();
        point_drag_source->point_drags(cell, drags);
        if (cell_averaged_drag && !drags.empty())
        {
          // The cell averages of the velocity shape functions: the drag of
          // each grain spread evenly over its cell and felt against the
          // cell-mean velocity. Every grain of the cell has the same
          // shape, so their drags add up to one: sum beta_i against the
          // cell-mean velocity minus sum beta_i v_i.
          double volume = 0;
          std::fill(point_shape.begin(), point_shape.end(), 0.0);
          for (unsigned int q = 0; q < n_q; ++q)
          {
            volume += fe_values.JxW(q);
            for (unsigned int a = 0; a < n_s; ++a)
              point_shape[velocity_dof[a][0]] +=
                fe_values.shape_value(velocity_dof[a][0], q) * fe_values.JxW(q);
          }
          for (unsigned int a = 0; a < n_s; ++a)
          {
            const double mean = point_shape[velocity_dof[a][0]] / volume;
            for (unsigned int c = 0; c < dim; ++c)
              point_shape[velocity_dof[a][c]] = mean;
          }
          PointDrag<dim> total;
          total.beta = 0;
          for (const auto &drag : drags)
          {
            total.beta += drag.beta;
            total.velocity += drag.beta * drag.velocity;
            max_beta = std::max(max_beta, drag.beta);
          }
          // total.velocity holds sum beta_i v_i.
          drags.assign(1, total);
        }
        for (const auto &drag : drags)
        {
          if (!cell_averaged_drag)
            for (unsigned int k = 0; k < dofs_per_cell; ++k)
            {
              const unsigned int c = fe.system_to_component_index(k).first;
              point_shape[k] =
                c < dim ? fe.shape_value(k, drag.reference_location) : 0.0;
            }
          dealii::Tensor<1, dim> u_at_grain;
          for (unsigned int k = 0; k < dofs_per_cell; ++k)
            if (point_shape[k] != 0)
              u_at_grain[fe.system_to_component_index(k).first] +=
                local_solution[k] * point_shape[k];
          // The slip force beta (u - v); with the cell's grains summed,
          // sum beta_i u - sum beta_i v_i.
          const dealii::Tensor<1, dim> force =
            cell_averaged_drag ? drag.beta * u_at_grain - drag.velocity :
                                 drag.beta * (u_at_grain - drag.velocity);
          for (unsigned int i = 0; i < dofs_per_cell; ++i)
          {
            if (point_shape[i] == 0)
              continue;
            const unsigned int ci = fe.system_to_component_index(i).first;
            cell_rhs(i) -= force[ci] * point_shape[i];
            for (unsigned int j = 0; j < dofs_per_cell; ++j)
              if (point_shape[j] != 0 &&
                  fe.system_to_component_index(j).first == ci)
                cell_matrix(i, j) +=
                  drag.beta * point_shape[i] * point_shape[j];
            if (assemble_preconditioner_matrices)
            {
              cell_reaction(i) += drag.beta * point_shape[i] * point_shape[i];
              max_beta = std::max(max_beta, drag.beta);
            }
          }
        }
      }

      // Open faces: the weakly imposed pressure. Open and velocity faces:
      // the solid flux that crosses them, -<q, s.n> (walls let none pass).
      for (const unsigned int face_no : cell->face_indices())
      {
        const auto face = cell->face(face_no);
        if (!face->at_boundary())
          continue;
        const BoundaryType type = geometry.boundary_types[face->boundary_id()];
        if (type != BoundaryType::open && type != BoundaryType::velocity)
          continue;
        fe_face_values.reinit(cell, face_no);
        MixtureValues<dim> face_mixture;
        mixture_fields->evaluate(cell,
                                 fe_face_values.get_quadrature_points(),
                                 face_reference_points[face_no],
                                 time,
                                 face_mixture);
        for (unsigned int q = 0; q < face_quadrature.size(); ++q)
        {
          const auto  &n       = fe_face_values.normal_vector(q);
          const double JxW     = fe_face_values.JxW(q);
          const double outflux = face_mixture.solid_flux[q] * n;
          const double p_open  = type == BoundaryType::open ?
                                   parameters.open_boundary_pressure->value(
                                    fe_face_values.quadrature_point(q)) :
                                   0.0;
          for (unsigned int i = 0; i < dofs_per_cell; ++i)
            cell_rhs(i) -= (face_mixture.fluid_fraction[q] * p_open *
                              (fe_face_values[velocities].value(i, q) * n) -
                            fe_face_values[pressure].value(i, q) * outflux) *
                           JxW;
        }
      }

      if (cell_scatter->is_direct(cell_number))
        cell_scatter->add(cell_number, cell_matrix, cell_rhs);
      else
        update_constraints.distribute_local_to_global(
          cell_matrix, cell_rhs, dof_indices, system_matrix, system_rhs);
      if (assemble_preconditioner_matrices)
      {
        if (cell_drag > 0)
          cell_mass *=
            drag_cell_mass_factor(cell_drag * h * h / cell_viscosity);
        pressure_mass_constraints.distribute_local_to_global(
          cell_mass, dof_indices, pressure_mass_matrix);
        update_constraints.distribute_local_to_global(cell_reaction,
                                                      dof_indices,
                                                      reaction_diagonal);
      }
    }

    system_matrix.compress(dealii::VectorOperation::add);
    system_rhs.compress(dealii::VectorOperation::add);
    drag_averaged_cells =
      dealii::Utilities::MPI::sum(averaged_cells, mpi_communicator);
    if (assemble_preconditioner_matrices)
    {
      pressure_mass_matrix.compress(dealii::VectorOperation::add);
      reaction_diagonal.compress(dealii::VectorOperation::add);
      schur_has_drag =
        dealii::Utilities::MPI::max(max_beta, mpi_communicator) > 0;
      velocity_viscous_number =
        dealii::Utilities::MPI::max(max_viscous_number, mpi_communicator);
    }
  }


  template void
  FluidSolver<2>::assemble_system(bool);
  template void
  FluidSolver<3>::assemble_system(bool);
} // namespace ImmersedGrains
