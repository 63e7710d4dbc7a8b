#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include <deal.II/base/geometry_info.h>
#include <deal.II/base/quadrature_lib.h>

#include <immersed_grains/fluid/assembly_terms.h>
#include <immersed_grains/fluid/cell_gather.h>
#include <immersed_grains/fluid/cell_scatter.h>
#include <immersed_grains/fluid/fluid_solver.h>
#include <immersed_grains/linear_algebra/component_block.h>

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
    average_drag_over_cell(const std::vector<double> &JxW,
                           MixtureValues<dim>        &mixture)
    {
      double                 beta = 0, beta_last = 0, volume = 0;
      dealii::Tensor<1, dim> momentum;
      for (unsigned int q = 0; q < JxW.size(); ++q)
      {
        beta += mixture.drag_coefficient[q] * JxW[q];
        beta_last += mixture.last_velocity_drag[q] * JxW[q];
        momentum +=
          mixture.drag_coefficient[q] * mixture.grain_velocity[q] * JxW[q];
        volume += JxW[q];
      }
      beta /= volume;
      beta_last /= volume;
      momentum /= volume;
      for (unsigned int q = 0; q < JxW.size(); ++q)
      {
        mixture.drag_coefficient[q]   = beta;
        mixture.last_velocity_drag[q] = beta_last;
        mixture.grain_velocity[q] =
          beta > 0 ? momentum / beta : dealii::Tensor<1, dim>();
      }
    }

    // K_ab += N_a w_b + viscous grad N_a . grad N_b for all pairs: the
    // assembly's innermost loop, n_s^2 entries at every quadrature point
    // (729 in 3D). Compiled also for AVX2 and chosen when the processor
    // has it (GCC's function multiversioning), since deal.II's Debian
    // build targets generic x86-64 (two doubles per instruction). Without
    // FMA contraction, and with each entry's sum in the same order, both
    // versions give the same bits.
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
    __attribute__((target_clones("avx2", "default")))
#endif
    void
    add_to_velocity_block(const unsigned int n_s,
                          const unsigned int dim,
                          const double *__restrict N,
                          const double *__restrict G0,
                          const double *__restrict G1,
                          const double *__restrict G2,
                          const double *__restrict w,
                          const double viscous,
                          double *__restrict K)
    {
      for (unsigned int a = 0; a < n_s; ++a)
      {
        double *__restrict row = K + a * n_s;
        const double Na = N[a], Ga0 = G0[a], Ga1 = G1[a];
        if (dim == 2)
          for (unsigned int b = 0; b < n_s; ++b)
          {
            double g = 0;
            g += Ga0 * G0[b];
            g += Ga1 * G1[b];
            row[b] += Na * w[b] + viscous * g;
          }
        else
        {
          const double Ga2 = G2[a];
          for (unsigned int b = 0; b < n_s; ++b)
          {
            double g = 0;
            g += Ga0 * G0[b];
            g += Ga1 * G1[b];
            g += Ga2 * G2[b];
            row[b] += Na * w[b] + viscous * g;
          }
        }
      }
    }


    // The floor on the mass-and-drag coefficient c of S_c where c vanishes
    // (block_preconditioner.h), as a fraction of the viscous diagonal, for
    // a cell of size h where the no-slip faces confine the flow to a gap
    // L (Geometry::wall_gap(): the box's shortest side when it is walled
    // all round, as on the benchmark; periodic and slip faces do not
    // confine: a column 1 x 8 with them sideways, 42 -> 33 and 36 -> 31
    // iterations at most, doc/adaptivity.md). Measured on the
    // drag-jump benchmark (doc/benchmarks.md):
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
    // 23; dt = 1, 2D level 7: 22 -> 15 (doc/benchmarks.md). The
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
    // The reference cell's scalar shape functions at the quadrature points.
    // On a mesh of axis-parallel boxes (MappingCartesian) the values on a
    // cell are these and its gradients these over the cell's extents
    // (scale_to_cell()); on other cells the gradients map through the
    // Jacobian (map_to_cell()). Computed once per assembly instead of
    // FEValues::reinit copying all of them for every cell (3 % of the 3D
    // cloud's run).
    template <int dim>
    std::vector<ScalarShapes<dim>>
    reference_shapes(const dealii::FESystem<dim>   &fe,
                     const ScalarDofs<dim>         &dofs,
                     const dealii::Quadrature<dim> &quadrature)
    {
      const unsigned int n_s = dofs.velocity.size(), n_p = dofs.pressure.size();
      std::vector<ScalarShapes<dim>> shapes(quadrature.size());
      for (unsigned int q = 0; q < quadrature.size(); ++q)
      {
        const auto &x = quadrature.point(q);
        shapes[q].resize(n_s, n_p);
        for (unsigned int a = 0; a < n_s; ++a)
        {
          shapes[q].N[a]  = fe.shape_value(dofs.velocity[a][0], x);
          const auto grad = fe.shape_grad(dofs.velocity[a][0], x);
          for (unsigned int d = 0; d < dim; ++d)
            shapes[q].G[d][a] = grad[d];
        }
        for (unsigned int b = 0; b < n_p; ++b)
        {
          shapes[q].Np[b] = fe.shape_value(dofs.pressure[b], x);
          const auto grad = fe.shape_grad(dofs.pressure[b], x);
          for (unsigned int d = 0; d < dim; ++d)
            shapes[q].Gp[d][b] = grad[d];
        }
      }
      return shapes;
    }

    // The gradients, weights and points of the box @p cell.
    template <int dim, typename CellIterator>
    void
    scale_to_cell(const CellIterator                   &cell,
                  const dealii::Quadrature<dim>        &quadrature,
                  const std::vector<ScalarShapes<dim>> &reference,
                  std::vector<ScalarShapes<dim>>       &shapes,
                  std::vector<double>                  &JxW,
                  std::vector<dealii::Point<dim>>      &points)
    {
      const dealii::Point<dim>     lower = cell->vertex(0);
      const dealii::Tensor<1, dim> extent =
        cell->vertex(dealii::GeometryInfo<dim>::vertices_per_cell - 1) - lower;
      double measure = 1;
      for (unsigned int d = 0; d < dim; ++d)
        measure *= extent[d];
      const unsigned int n_s = reference[0].N.size();
      const unsigned int n_p = reference[0].Np.size();
      for (unsigned int q = 0; q < quadrature.size(); ++q)
      {
        JxW[q] = quadrature.weight(q) * measure;
        for (unsigned int d = 0; d < dim; ++d)
        {
          points[q][d]         = lower[d] + extent[d] * quadrature.point(q)[d];
          const double inverse = 1.0 / extent[d];
          for (unsigned int a = 0; a < n_s; ++a)
            shapes[q].G[d][a] = reference[q].G[d][a] * inverse;
          for (unsigned int b = 0; b < n_p; ++b)
            shapes[q].Gp[d][b] = reference[q].Gp[d][b] * inverse;
        }
      }
    }

    // The bilinear (trilinear) vertex functions of the reference cell at
    // the quadrature points: a Q1 cell's map x(xi) = sum_v X_v N_v(xi).
    template <int dim>
    struct VertexFunctions
    {
      std::vector<std::vector<double>>                 value; // [q][v]
      std::vector<std::vector<dealii::Tensor<1, dim>>> gradient;
    };

    template <int dim>
    VertexFunctions<dim>
    vertex_functions(const dealii::Quadrature<dim> &quadrature)
    {
      constexpr unsigned int n_v = dealii::GeometryInfo<dim>::vertices_per_cell;
      VertexFunctions<dim>   f;
      f.value.assign(quadrature.size(), std::vector<double>(n_v));
      f.gradient.assign(quadrature.size(),
                        std::vector<dealii::Tensor<1, dim>>(n_v));
      for (unsigned int q = 0; q < quadrature.size(); ++q)
        for (unsigned int v = 0; v < n_v; ++v)
        {
          f.value[q][v] = dealii::GeometryInfo<dim>::d_linear_shape_function(
            quadrature.point(q), v);
          f.gradient[q][v] =
            dealii::GeometryInfo<dim>::d_linear_shape_function_gradient(
              quadrature.point(q), v);
        }
      return f;
    }

    // The reference gradients @p reference mapped through the inverse
    // Jacobian @p inverse (inverse[k][d] = dxi_k/dx_d): grad N = J^{-T}
    // grad_xi N.
    template <int dim, typename InverseJacobian>
    void
    map_gradients(const InverseJacobian   &inverse,
                  const ScalarShapes<dim> &reference,
                  ScalarShapes<dim>       &shapes)
    {
      const unsigned int n_s = reference.N.size();
      const unsigned int n_p = reference.Np.size();
      for (unsigned int d = 0; d < dim; ++d)
      {
        for (unsigned int a = 0; a < n_s; ++a)
        {
          double g = 0;
          for (unsigned int k = 0; k < dim; ++k)
            g += inverse[k][d] * reference.G[k][a];
          shapes.G[d][a] = g;
        }
        for (unsigned int b = 0; b < n_p; ++b)
        {
          double g = 0;
          for (unsigned int k = 0; k < dim; ++k)
            g += inverse[k][d] * reference.Gp[k][b];
          shapes.Gp[d][b] = g;
        }
      }
    }

    // The gradients, weights and points of a cell of any shape under the
    // Q1 map (MappingQ1's): grad N = J^{-T} grad_xi N, JxW = det J w, with
    // J = dx/dxi at each point. A Gmsh mesh's cells that are not
    // axis-parallel boxes take this path; boxes take scale_to_cell(), cells
    // on a curved boundary map_through_mapping().
    template <int dim, typename CellIterator>
    void
    map_to_cell(const CellIterator                   &cell,
                const dealii::Quadrature<dim>        &quadrature,
                const VertexFunctions<dim>           &vertex,
                const std::vector<ScalarShapes<dim>> &reference,
                std::vector<ScalarShapes<dim>>       &shapes,
                std::vector<double>                  &JxW,
                std::vector<dealii::Point<dim>>      &points)
    {
      constexpr unsigned int n_v = dealii::GeometryInfo<dim>::vertices_per_cell;
      std::array<dealii::Point<dim>, n_v> X;
      for (unsigned int v = 0; v < n_v; ++v)
        X[v] = cell->vertex(v);
      for (unsigned int q = 0; q < quadrature.size(); ++q)
      {
        dealii::Tensor<2, dim> J;
        points[q] = dealii::Point<dim>();
        for (unsigned int v = 0; v < n_v; ++v)
        {
          points[q] += vertex.value[q][v] * X[v];
          J += dealii::outer_product(X[v], vertex.gradient[q][v]);
        }
        const double determinant = dealii::determinant(J);
        Assert(determinant > 0, dealii::ExcMessage("a distorted cell"));
        JxW[q] = quadrature.weight(q) * determinant;
        map_gradients(dealii::invert(J), reference[q], shapes[q]);
      }
    }

    // The gradients, weights and points of a cell with an edge on a curved
    // boundary, under the geometry's quadratic mapping (@p mapped was
    // reinit'ed on the cell with its quadrature points, weights and inverse
    // Jacobians): the cell's edges on the boundary follow the curve.
    template <int dim>
    void
    map_through_mapping(const dealii::FEValues<dim>          &mapped,
                        const std::vector<ScalarShapes<dim>> &reference,
                        std::vector<ScalarShapes<dim>>       &shapes,
                        std::vector<double>                  &JxW,
                        std::vector<dealii::Point<dim>>      &points)
    {
      for (unsigned int q = 0; q < mapped.n_quadrature_points; ++q)
      {
        points[q] = mapped.quadrature_point(q);
        JxW[q]    = mapped.JxW(q);
        map_gradients(mapped.inverse_jacobian(q), reference[q], shapes[q]);
      }
    }

    // The cell's coefficients of the current iterate and of its history,
    // as gathered (current, old, older: by local DoF) and blocked by
    // velocity component for the point loop (velocity[c][a] for Q2
    // function a; history[c][a] the BDF combination a1 u^n + a2 u^{n-1};
    // last[c][a] u^n), so that evaluate_point_state() reads contiguous
    // arrays and computes the history once per cell, not once per point.
    template <int dim>
    struct LocalSolutions
    {
      void
      block_by_component(const ScalarDofs<dim>       &dofs,
                         const std::array<double, 3> &bdf)
      {
        const unsigned int n_s = dofs.velocity.size();
        for (unsigned int c = 0; c < dim; ++c)
        {
          velocity[c].resize(n_s);
          history[c].resize(n_s);
          last[c].resize(n_s);
          for (unsigned int a = 0; a < n_s; ++a)
          {
            const unsigned int k = dofs.velocity[a][c];
            velocity[c][a]       = current[k];
            if (with_history)
              history[c][a] = bdf[1] * old[k] + bdf[2] * older[k];
            if (drag_against_last)
              last[c][a] = old[k];
          }
        }
        pressure.resize(dofs.pressure.size());
        for (unsigned int b = 0; b < dofs.pressure.size(); ++b)
          pressure[b] = current[dofs.pressure[b]];
      }

      std::vector<double>                  current, old, older;
      std::array<std::vector<double>, dim> velocity, history, last;
      std::vector<double>                  pressure;
      bool                                 with_history      = false;
      bool                                 drag_against_last = false;
    };

    // The current iterate, its history and the mixture at point @p q.
    // Each sum runs over the shape functions in ascending order into a
    // local accumulator, which the compiler keeps in a register: summed
    // into @p state directly, every addition waited on the store of the
    // one before.
    template <int dim>
    void
    evaluate_point_state(const ScalarShapes<dim>      &shapes,
                         const LocalSolutions<dim>    &local,
                         const MixtureValues<dim>     &mixture,
                         const unsigned int            q,
                         const dealii::Vector<double> *forcing,
                         PointState<dim>              &state)
    {
      const double                   *N   = shapes.N.data();
      const unsigned int              n_s = shapes.N.size();
      std::array<const double *, dim> G, u;
      for (unsigned int d = 0; d < dim; ++d)
      {
        G[d] = shapes.G[d].data();
        u[d] = local.velocity[d].data();
      }
      double value[dim]         = {};
      double gradient[dim][dim] = {};
      for (unsigned int a = 0; a < n_s; ++a)
        for (unsigned int c = 0; c < dim; ++c)
        {
          value[c] += u[c][a] * N[a];
          for (unsigned int d = 0; d < dim; ++d)
            gradient[c][d] += u[c][a] * G[d][a];
        }
      for (unsigned int c = 0; c < dim; ++c)
      {
        state.u[c] = value[c];
        for (unsigned int d = 0; d < dim; ++d)
          state.grad_u[c][d] = gradient[c][d];
      }

      double history[dim] = {}, last[dim] = {};
      if (local.with_history)
        for (unsigned int c = 0; c < dim; ++c)
        {
          const double *h = local.history[c].data();
          for (unsigned int a = 0; a < n_s; ++a)
            history[c] += h[a] * N[a];
        }
      if (local.drag_against_last)
        for (unsigned int c = 0; c < dim; ++c)
        {
          const double *l = local.last[c].data();
          for (unsigned int a = 0; a < n_s; ++a)
            last[c] += l[a] * N[a];
        }
      for (unsigned int c = 0; c < dim; ++c)
      {
        state.u_history[c] = history[c];
        state.u_last[c]    = last[c];
      }

      const double      *Np  = shapes.Np.data();
      const unsigned int n_p = shapes.Np.size();
      double             p = 0, grad_p[dim] = {};
      for (unsigned int b = 0; b < n_p; ++b)
      {
        const double value_b = local.pressure[b];
        p += value_b * Np[b];
        for (unsigned int d = 0; d < dim; ++d)
          grad_p[d] += value_b * shapes.Gp[d][b];
      }
      state.p = p;
      for (unsigned int d = 0; d < dim; ++d)
        state.grad_p[d] = grad_p[d];
      state.phi                   = mixture.fluid_fraction[q];
      state.grad_phi              = mixture.fluid_fraction_gradient[q];
      state.beta                  = mixture.drag_coefficient[q];
      state.grain_velocity        = mixture.grain_velocity[q];
      state.beta_last             = mixture.last_velocity_drag[q];
      state.solid_flux            = mixture.solid_flux[q];
      state.mass_source           = mixture.mass_source[q];
      state.solid_flux_divergence = mixture.solid_flux_divergence[q];
      state.alpha                 = mixture.pressure_gradient_weight[q];
      state.mobility              = mixture.pressure_mobility[q];
      if (forcing)
        for (unsigned int d = 0; d < dim; ++d)
          state.forcing[d] = (*forcing)(d);
    }

    // The momentum terms' coefficients @p m at one point, integrated: the
    // velocity rows of the residual (force and stress against N_a and
    // grad N_a, the pressure against div(phi N_a e_c) = phi dN_a/dx_c +
    // dphi/dx_c N_a) and the scalar velocity block
    //   K_ab += reaction N_a N_b + diffusion grad N_a . grad N_b
    //         + convection_weight (convection . grad N_b) N_a,
    // with Newton's convection_weight (grad u)_cd N_b N_a in W.
    template <int dim>
    void
    integrate_momentum(const MomentumCoefficients<dim> &m,
                       const PointState<dim>           &state,
                       const ScalarShapes<dim>         &shapes,
                       const double                     JxW,
                       const bool                       convection,
                       const bool                       convection_derivative,
                       std::vector<double>             &advection_weight,
                       CellIntegrals                   &integrals)
    {
      const auto        &N   = shapes.N;
      const auto        &G   = shapes.G;
      const unsigned int n_s = N.size();
      {
        // The coefficients copied out, so that the writes into rhs_u do
        // not make the compiler read them again for every a.
        const dealii::Tensor<1, dim>    force    = m.force;
        const dealii::Tensor<2, dim>    stress   = m.stress;
        const dealii::Tensor<1, dim>    grad_phi = state.grad_phi;
        const double                    pressure = m.pressure;
        const double                    phi      = state.phi;
        const double                   *Na       = N.data();
        std::array<const double *, dim> Ga;
        for (unsigned int d = 0; d < dim; ++d)
          Ga[d] = G[d].data();
        double *rhs = integrals.rhs_u.data();
        for (unsigned int a = 0; a < n_s; ++a)
          for (unsigned int c = 0; c < dim; ++c)
          {
            double stress_a = 0;
            for (unsigned int d = 0; d < dim; ++d)
              stress_a += stress[c][d] * Ga[d][a];
            rhs[a * dim + c] -=
              (force[c] * Na[a] + stress_a -
               pressure * (phi * Ga[c][a] + grad_phi[c] * Na[a])) *
              JxW;
          }
      }

      const double w_mass    = m.reaction * JxW;
      const double w_viscous = m.diffusion * JxW;
      for (unsigned int b = 0; b < n_s; ++b)
      {
        advection_weight[b] = w_mass * N[b];
        if (convection)
        {
          double adv = 0;
          for (unsigned int d = 0; d < dim; ++d)
            adv += m.convection[d] * G[d][b];
          advection_weight[b] += m.convection_weight * adv * JxW;
        }
      }
      add_to_velocity_block(n_s,
                            dim,
                            N.data(),
                            G[0].data(),
                            G[1].data(),
                            dim == 3 ? G[dim - 1].data() : nullptr,
                            advection_weight.data(),
                            w_viscous,
                            integrals.K.data());
      if (convection_derivative)
        // convection_weight (grad u)_cd N_b N_a couples component c of
        // the row with component d of the column.
        for (unsigned int c = 0; c < dim; ++c)
          for (unsigned int d = 0; d < dim; ++d)
          {
            const double w =
              m.convection_weight * m.convection_derivative[c][d] * JxW;
            double *block = &integrals.W[(c * dim + d) * n_s * n_s];
            for (unsigned int a = 0; a < n_s; ++a)
              for (unsigned int b = 0; b < n_s; ++b)
                block[a * n_s + b] += w * N[a] * N[b];
          }
    }

    // What the preconditioner's pieces gather over a cell and the mesh.
    struct SchurSums
    {
      // Integrals of the drag coefficient field and of the viscosity phi mu
      // over the cell, for drag_cell_mass_factor. Not the grains' point or
      // cell drag: rank one per grain or cell, it leaves the cell's other
      // velocity modes viscous, and counting it cost a packed bed 2 more
      // iterations per step (tests/coupled_resting_column: 40-44 instead
      // of 38-42).
      double cell_drag      = 0;
      double cell_viscosity = 0;
      // The largest ratio of the viscous and advective parts of A to its
      // mass-and-drag part, at the spacing of the velocity nodes: where it
      // is small, A is nearly diagonal (the entry Velocity
      // preconditioner).
      double max_viscous_number = 0;
    };

    // The Schur complement approximation (block_preconditioner.h) at one
    // point: the pressure mass matrix weighted by phi/mu and the diagonal
    // of the mass-and-drag part c M of A, c = phi rho a0/dt + beta, plus
    // its floor (@p floor_factor, schur_floor_factor()).
    template <int dim>
    void
    integrate_schur_pieces(const MomentumCoefficients<dim> &m,
                           const PointState<dim>           &state,
                           const ScalarShapes<dim>         &shapes,
                           const double                     JxW,
                           const double                     viscosity,
                           const double                     spacing,
                           const double                     floor_factor,
                           const bool                       convection,
                           CellIntegrals                   &integrals,
                           SchurSums                       &sums,
                           double                          &max_beta)
    {
      const auto  &N           = shapes.N;
      const auto  &G           = shapes.G;
      const double w_mass      = m.reaction * JxW;
      const double w_viscous   = m.diffusion * JxW;
      const double mass_weight = state.phi / viscosity * JxW;
      const double c           = m.reaction;
      double viscous_number    = c > 0 ? m.diffusion / (c * spacing * spacing) :
                                         std::numeric_limits<double>::infinity();
      if (convection && c > 0)
        viscous_number =
          std::max(viscous_number,
                   m.convection_weight * state.u.norm() / (c * spacing));
      sums.max_viscous_number =
        std::max(sums.max_viscous_number, viscous_number);
      sums.cell_drag += state.beta * JxW;
      sums.cell_viscosity += m.diffusion * JxW;
      max_beta               = std::max(max_beta, state.beta);
      const unsigned int n_p = shapes.Np.size();
      for (unsigned int b = 0; b < n_p; ++b)
        for (unsigned int e = 0; e < n_p; ++e)
          integrals.Mp[b * n_p + e] +=
            mass_weight * shapes.Np[b] * shapes.Np[e];
      for (unsigned int a = 0; a < N.size(); ++a)
      {
        double g = 0;
        for (unsigned int d = 0; d < dim; ++d)
          g += G[d][a] * G[d][a];
        integrals.R[a] += w_mass * N[a] * N[a] + floor_factor * w_viscous * g;
      }
    }

    // The scalar integrals onto the vector-valued cell matrix and
    // right-hand side.
    template <int dim>
    void
    fill_cell_system(const CellIntegrals        &integrals,
                     const ScalarDofs<dim>      &dofs,
                     const bool                  convection_derivative,
                     dealii::FullMatrix<double> &cell_matrix,
                     dealii::Vector<double>     &cell_rhs)
    {
      const unsigned int n_s = integrals.n_s, n_p = integrals.n_p;
      // Without Newton's derivative the loops below overwrite every entry
      // that is not zero on every cell (a velocity couples only with its
      // own component), so the rest keeps the zeros it was made with.
      if (convection_derivative)
        cell_matrix = 0;
      for (unsigned int c = 0; c < dim; ++c)
        for (unsigned int a = 0; a < n_s; ++a)
        {
          const unsigned int i = dofs.velocity[a][c];
          cell_rhs(i)          = integrals.rhs_u[a * dim + c];
          for (unsigned int b = 0; b < n_s; ++b)
            cell_matrix(i, dofs.velocity[b][c]) = integrals.K[a * n_s + b];
          if (convection_derivative)
            for (unsigned int d = 0; d < dim; ++d)
              for (unsigned int b = 0; b < n_s; ++b)
                cell_matrix(i, dofs.velocity[b][d]) +=
                  integrals.W[(c * dim + d) * n_s * n_s + a * n_s + b];
          for (unsigned int b = 0; b < n_p; ++b)
          {
            const double value = integrals.B[(c * n_s + a) * n_p + b];
            cell_matrix(i, dofs.pressure[b]) = value;
            cell_matrix(dofs.pressure[b], i) = value;
          }
        }
      for (unsigned int b = 0; b < n_p; ++b)
      {
        cell_rhs(dofs.pressure[b]) = integrals.rhs_p[b];
        for (unsigned int e = 0; e < n_p; ++e)
          cell_matrix(dofs.pressure[b], dofs.pressure[e]) =
            integrals.C[b * n_p + e];
      }
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
   *   R_p = -(q, div(phi u) - g) + (grad q, s) - <q, s.n>_out,
   *
   * "out" the open faces, and the velocity faces where the solid crosses
   * them (prescribed fields; grains meet them as walls),
   *
   * one AssemblyTerm per term (assembly_terms.h), listed for the scene by
   * make_assembly_terms(): a term the scene switches off is not visited.
   *
   * Each Taylor-Hood velocity shape function has one non-zero component, a
   * scalar Q2 function N_a times a unit vector. Every term but Newton's
   * couples a component only with itself, with the same coefficients for
   * each, so the velocity block is integrated once as a scalar n_s x n_s
   * matrix K and copied onto the dim diagonal blocks; the pressure coupling
   * B (and its transpose) as dim n_s x n_p matrices. This does about a
   * tenth of the work of a loop over all pairs of vector-valued shape
   * functions (doc/performance.md). The momentum terms only state their
   * coefficients at each point (MomentumCoefficients); the kernel below
   * integrates them in one pass over K, whichever terms contributed.
   */
  template <int dim>
  void
  FluidSolver<dim>::assemble_system(const bool assemble_preconditioner_matrices,
                                    BoundaryReactions *reactions)
  {
    dealii::TimerOutput::Scope scope(timer,
                                     reactions ? "fluid: boundary forces" :
                                                 "fluid: assembly");
    Assert(!(reactions && assemble_preconditioner_matrices),
           dealii::ExcInternalError());

    if (!reactions)
      cell_scatter->zero_system(system_matrix, system_rhs);
    if (assemble_preconditioner_matrices)
    {
      pressure_mass_matrix = 0;
      reaction_diagonal    = 0;
    }

    const dealii::QGauss<dim> quadrature(fe.degree + 1);
    const unsigned int        dofs_per_cell = fe.n_dofs_per_cell();
    const unsigned int        n_q           = quadrature.size();
    const unsigned int        n_s = fe.base_element(0).n_dofs_per_cell();
    const unsigned int        n_p = fe.base_element(1).n_dofs_per_cell();
    const ScalarDofs<dim>     dofs(fe);

    const double rho = parameters.density, mu = parameters.viscosity;
    const double inv_dt =
      (parameters.time_derivative && dt > 0) ? 1.0 / dt : 0.0;
    forcing->set_time(time);

    double                 max_beta = 0;
    const AssemblyTermList terms =
      make_assembly_terms(dofs, rho, mu, inv_dt, max_beta);
    const bool convection            = terms.convects;
    const bool convection_derivative = terms.linearises_convection;

    dealii::FullMatrix<double> cell_matrix(dofs_per_cell, dofs_per_cell);
    // The pressure mass matrix's cell part over the pressure DoFs alone:
    // given the whole cell's matrix, distribute_local_to_global sorted and
    // resolved all its rows, zeros included, at every preconditioner build
    // (4 % of the 3D cloud's first steps).
    dealii::FullMatrix<double>                   cell_mass(n_p, n_p);
    std::vector<dealii::types::global_dof_index> pressure_indices(n_p);
    dealii::Vector<double>                       cell_rhs(dofs_per_cell);
    dealii::Vector<double>                       cell_reaction(dofs_per_cell);
    const double                                 wall_gap = geometry.wall_gap();
    std::vector<dealii::types::global_dof_index> dof_indices(dofs_per_cell);
    LocalSolutions<dim>                          local;
    local.current.resize(dofs_per_cell);
    local.old.resize(dofs_per_cell);
    local.older.resize(dofs_per_cell);
    local.with_history = inv_dt > 0;

    const std::vector<ScalarShapes<dim>> reference =
      reference_shapes(fe, dofs, quadrature);
    std::vector<ScalarShapes<dim>>       cell_shapes = reference;
    const bool                           cartesian   = geometry.is_cartesian();
    const VertexFunctions<dim>           vertex = vertex_functions(quadrature);
    std::optional<dealii::FEValues<dim>> curved_cell_values;
    if (geometry.has_curved_boundary())
      curved_cell_values.emplace(mapping,
                                 fe,
                                 quadrature,
                                 dealii::update_quadrature_points |
                                   dealii::update_JxW_values |
                                   dealii::update_inverse_jacobians);
    std::vector<double>             JxW_values(n_q);
    std::vector<dealii::Point<dim>> points(n_q);
    CellIntegrals                   integrals;
    integrals.resize(dim, n_s, n_p, convection_derivative);
    std::vector<double> advection_weight(n_s);
    CellContext<dim>    context;
    context.shapes                = &cell_shapes;
    context.JxW                   = &JxW_values;
    context.local_solution        = &local.current;
    context.preconditioner_pieces = assemble_preconditioner_matrices;

    std::vector<dealii::Vector<double>> f(n_q, dealii::Vector<double>(dim));
    MixtureValues<dim>                  mixture;
    PointState<dim>                     state;

    AssertThrow(cell_gather->matches(solution) &&
                  cell_gather->matches(old_solution) &&
                  cell_gather->matches(old_old_solution),
                dealii::ExcInternalError());

    unsigned int averaged_cells     = 0;
    double       max_viscous_number = 0;
    unsigned int owned_cell         = 0; // the cell's number for cell_scatter
    for (const auto &cell : dof_handler.active_cell_iterators())
    {
      if (!cell->is_locally_owned())
        continue;
      const unsigned int cell_number = owned_cell++;
      if (reactions)
      {
        // Only the cells with a velocity DoF on one of the faces.
        cell->get_dof_indices(dof_indices);
        if (std::none_of(dof_indices.begin(),
                         dof_indices.end(),
                         [&](const dealii::types::global_dof_index i)
                         {
                           return std::any_of(reactions->dofs.begin(),
                                              reactions->dofs.end(),
                                              [i](const dealii::IndexSet &set)
                                              { return set.is_element(i); });
                         }))
          continue;
      }
      if (cartesian)
        scale_to_cell(
          cell, quadrature, reference, cell_shapes, JxW_values, points);
      else if (geometry.is_curved(cell))
      {
        curved_cell_values->reinit(cell);
        map_through_mapping(
          *curved_cell_values, reference, cell_shapes, JxW_values, points);
      }
      else
        map_to_cell(
          cell, quadrature, vertex, reference, cell_shapes, JxW_values, points);
      cell_gather->gather(cell_number, solution, local.current);
      if (local.with_history)
      {
        cell_gather->gather(cell_number, old_solution, local.old);
        cell_gather->gather(cell_number, old_old_solution, local.older);
      }
      integrals.clear(assemble_preconditioner_matrices);
      SchurSums schur;

      mixture_fields->evaluate(
        cell, points, quadrature.get_points(), time, mixture);
      // u^n, also where a drag field is taken against it.
      local.drag_against_last =
        std::any_of(mixture.last_velocity_drag.begin(),
                    mixture.last_velocity_drag.end(),
                    [](const double b) { return b != 0; });
      if (local.drag_against_last && !local.with_history)
        cell_gather->gather(cell_number, old_solution, local.old);
      local.block_by_component(dofs, bdf);
      const double h            = std::pow(cell->measure(), 1.0 / dim);
      const double floor_factor = schur_floor_factor(h, wall_gap);
      using DragAveraging       = typename FluidParameters<dim>::DragAveraging;
      if (parameters.drag_averaging == DragAveraging::cell ||
          (parameters.drag_averaging == DragAveraging::jump &&
           drag_jumps_in_cell(mixture, h, mu, parameters.drag_jump_contrast)))
      {
        average_drag_over_cell(JxW_values, mixture);
        ++averaged_cells;
      }
      if (terms.forcing)
      {
        forcing->vector_value_list(points, f);
        for (unsigned int q = 0; q < n_q; ++q)
          max_forcing = std::max(max_forcing, f[q].l2_norm());
      }
      if (fields_prescribed)
        for (unsigned int q = 0; q < n_q; ++q)
          if (mixture.drag_coefficient[q] > 0)
            max_prescribed_grain_speed =
              std::max(max_prescribed_grain_speed,
                       mixture.grain_velocity[q].norm());

      for (unsigned int q = 0; q < n_q; ++q)
      {
        const ScalarShapes<dim> &shapes = cell_shapes[q];
        evaluate_point_state(
          shapes, local, mixture, q, terms.forcing ? &f[q] : nullptr, state);
        MomentumCoefficients<dim> m;
        for (const auto *term : terms.at_points)
          term->point(state, shapes, JxW_values[q], m, integrals);
        integrate_momentum(m,
                           state,
                           shapes,
                           JxW_values[q],
                           convection,
                           convection_derivative,
                           advection_weight,
                           integrals);
        if (assemble_preconditioner_matrices)
          integrate_schur_pieces(m,
                                 state,
                                 shapes,
                                 JxW_values[q],
                                 mu,
                                 h / fe.degree,
                                 floor_factor,
                                 convection,
                                 integrals,
                                 schur,
                                 max_beta);
      }
      max_viscous_number =
        std::max(max_viscous_number, schur.max_viscous_number);

      // Grains at points and boundary faces.
      if (!terms.on_cells.empty())
      {
        context.cell = cell;
        for (const auto *term : terms.on_cells)
          term->cell(context, integrals);
      }

      if (reactions)
      {
        // The residual tested with the sum of the faces' shape functions
        // of component c: -rhs_u summed over the cell's DoFs on them.
        for (unsigned int k = 0; k < reactions->dofs.size(); ++k)
          for (unsigned int a = 0; a < n_s; ++a)
            for (unsigned int c = 0; c < dim; ++c)
              if (reactions->dofs[k].is_element(
                    dof_indices[dofs.velocity[a][c]]))
                reactions->sums[k][c] += integrals.rhs_u[a * dim + c];
        continue;
      }
      fill_cell_system(
        integrals, dofs, convection_derivative, cell_matrix, cell_rhs);
      const bool direct = cell_scatter->is_direct(cell_number);
      if (!direct || assemble_preconditioner_matrices)
        cell->get_dof_indices(dof_indices);
      if (direct)
        cell_scatter->add(cell_number, cell_matrix, cell_rhs);
      else
        update_constraints.distribute_local_to_global(
          cell_matrix, cell_rhs, dof_indices, system_matrix, system_rhs);
      if (assemble_preconditioner_matrices)
      {
        cell_reaction = 0;
        for (unsigned int b = 0; b < n_p; ++b)
        {
          pressure_indices[b] = dof_indices[dofs.pressure[b]];
          for (unsigned int e = 0; e < n_p; ++e)
            cell_mass(b, e) = integrals.Mp[b * n_p + e];
        }
        for (unsigned int a = 0; a < n_s; ++a)
          for (unsigned int c = 0; c < dim; ++c)
            cell_reaction(dofs.velocity[a][c]) = integrals.R[a];
        if (schur.cell_drag > 0)
          cell_mass *= drag_cell_mass_factor(schur.cell_drag * h * h /
                                             schur.cell_viscosity);
        pressure_mass_constraints.distribute_local_to_global(
          cell_mass, pressure_indices, pressure_mass_matrix);
        update_constraints.distribute_local_to_global(cell_reaction,
                                                      dof_indices,
                                                      reaction_diagonal);
      }
    }

    if (reactions)
    {
      for (auto &sum : reactions->sums)
        sum = dealii::Utilities::MPI::sum(sum, mpi_communicator);
      return;
    }
    cell_scatter->compress_system(system_matrix, system_rhs);
    // The first assembly on a mesh also checks that every component's free
    // rows hold the same values.
    if (velocity_block && !velocity_block->update(system_matrix.block(0, 0)))
      velocity_block.reset();
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


  template <int dim>
  typename FluidSolver<dim>::AssemblyTermList
  FluidSolver<dim>::make_assembly_terms(const ScalarDofs<dim> &dofs,
                                        const double           rho,
                                        const double           mu,
                                        const double           inv_dt,
                                        double                &max_beta) const
  {
    AssemblyTermList list;
    const auto       add =
      [&](std::unique_ptr<AssemblyTerm<dim>> term, const bool at_points)
    {
      (at_points ? list.at_points : list.on_cells).push_back(term.get());
      list.convects |= term->convects();
      list.linearises_convection |= term->linearises_convection();
      list.owned.push_back(std::move(term));
    };
    // The order is the order in which the terms add to the residual.
    if (inv_dt > 0)
      add(std::make_unique<TimeDerivativeTerm<dim>>(rho, bdf[0], inv_dt), true);
    add(std::make_unique<DragFieldTerm<dim>>(), true);
    add(std::make_unique<PressureContinuityTerm<dim>>(), true);
    if (parameters.advection)
      add(std::make_unique<AdvectionTerm<dim>>(
            rho, parameters.newton, parameters.skew_symmetric_advection),
          true);
    if (!forcing_is_zero)
    {
      add(std::make_unique<ForcingTerm<dim>>(), true);
      list.forcing = true;
    }
    add(std::make_unique<ViscousTerm<dim>>(mu), true);
    if (point_drag_source)
      add(std::make_unique<GrainDragTerm<dim>>(
            *point_drag_source, fe, dofs, cell_averaged_drag, max_beta),
          false);
    if (BoundaryFluxTerm<dim>::needed(geometry, solid_crosses_boundaries))
      add(std::make_unique<BoundaryFluxTerm<dim>>(
            mapping,
            fe,
            dofs,
            geometry,
            *mixture_fields,
            *parameters.open_boundary_pressure,
            time,
            solid_crosses_boundaries,
            parameters.advection ? parameters.backflow_stabilization * rho :
                                   0.0),
          false);
    return list;
  }


  template void
  FluidSolver<2>::assemble_system(bool, BoundaryReactions *);
  template void
  FluidSolver<3>::assemble_system(bool, BoundaryReactions *);
  template FluidSolver<2>::AssemblyTermList
  FluidSolver<2>::make_assembly_terms(const ScalarDofs<2> &,
                                      double,
                                      double,
                                      double,
                                      double &) const;
  template FluidSolver<3>::AssemblyTermList
  FluidSolver<3>::make_assembly_terms(const ScalarDofs<3> &,
                                      double,
                                      double,
                                      double,
                                      double &) const;
} // namespace ImmersedGrains
