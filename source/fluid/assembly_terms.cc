#include <deal.II/base/qprojector.h>

#include <immersed_grains/fluid/assembly_terms.h>

namespace ImmersedGrains
{
  namespace
  {
    // B_{c,ab} += -Np_b div_a + alpha_a dNp_b/dx_c for one component c:
    // n_s x n_p entries at every quadrature point, as many as K's in 3D.
    // Compiled also for AVX2 like the K kernel in fluid_assembly.cc, with
    // each entry computed the same way in both versions.
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
    __attribute__((target_clones("avx2", "default")))
#endif
    void
    add_to_divergence_block(const unsigned int n_s,
                            const unsigned int n_p,
                            const double *__restrict N,
                            const double *__restrict Gc,
                            const double *__restrict Np,
                            const double *__restrict Gpc,
                            const double phi,
                            const double grad_phi_c,
                            const double alpha,
                            const double JxW,
                            double *__restrict Bc)
    {
      for (unsigned int a = 0; a < n_s; ++a)
      {
        const double div_a     = (phi * Gc[a] + grad_phi_c * N[a]) * JxW;
        const double alpha_a   = alpha * N[a] * JxW;
        double *__restrict row = Bc + a * n_p;
        for (unsigned int b = 0; b < n_p; ++b)
          row[b] += -Np[b] * div_a + alpha_a * Gpc[b];
      }
    }
  } // namespace


  template <int dim>
  void
  ScalarShapes<dim>::resize(const unsigned int n_velocity,
                            const unsigned int n_pressure)
  {
    N.resize(n_velocity);
    Np.resize(n_pressure);
    for (unsigned int d = 0; d < dim; ++d)
    {
      G[d].resize(n_velocity);
      Gp[d].resize(n_pressure);
    }
  }


  template <int dim>
  ScalarDofs<dim>::ScalarDofs(const dealii::FESystem<dim> &fe)
      : velocity(fe.base_element(0).n_dofs_per_cell())
      , pressure(fe.base_element(1).n_dofs_per_cell())
  {
    for (unsigned int k = 0; k < fe.n_dofs_per_cell(); ++k)
    {
      const auto [component, index] = fe.system_to_component_index(k);
      if (component < dim)
        velocity[index][component] = k;
      else
        pressure[index] = k;
    }
  }


  void
  CellIntegrals::resize(const unsigned int dim,
                        const unsigned int n_velocity,
                        const unsigned int n_pressure,
                        const bool         newton)
  {
    n_s = n_velocity;
    n_p = n_pressure;
    K.resize(n_s * n_s);
    W.resize(newton ? dim * dim * n_s * n_s : 0);
    B.resize(dim * n_s * n_p);
    C.resize(n_p * n_p);
    rhs_u.resize(dim * n_s);
    rhs_p.resize(n_p);
    Mp.resize(n_p * n_p);
    R.resize(n_s);
  }


  void
  CellIntegrals::clear(const bool preconditioner_pieces)
  {
    for (auto *block : {&K, &W, &B, &C, &rhs_u, &rhs_p})
      std::fill(block->begin(), block->end(), 0.0);
    if (preconditioner_pieces)
      for (auto *block : {&Mp, &R})
        std::fill(block->begin(), block->end(), 0.0);
  }


  template <int dim>
  void
  AssemblyTerm<dim>::point(const PointState<dim> &,
                           const ScalarShapes<dim> &,
                           double,
                           MomentumCoefficients<dim> &,
                           CellIntegrals &) const
  {
  }


  template <int dim>
  void
  AssemblyTerm<dim>::cell(const CellContext<dim> &, CellIntegrals &) const
  {
  }


  template <int dim>
  bool
  AssemblyTerm<dim>::convects() const
  {
    return false;
  }


  template <int dim>
  bool
  AssemblyTerm<dim>::linearises_convection() const
  {
    return false;
  }


  template <int dim>
  TimeDerivativeTerm<dim>::TimeDerivativeTerm(const double density,
                                              const double a0,
                                              const double inv_dt)
      : density(density)
      , a0(a0)
      , inv_dt(inv_dt)
  {
  }


  template <int dim>
  void
  TimeDerivativeTerm<dim>::point(const PointState<dim> &s,
                                 const ScalarShapes<dim> &,
                                 double,
                                 MomentumCoefficients<dim> &m,
                                 CellIntegrals &) const
  {
    // Matrix: phi rho a0/dt N_a N_b; residual: phi rho (a0 u + history)/dt.
    m.reaction += s.phi * density * a0 * inv_dt;
    m.force += s.phi * density * inv_dt * (a0 * s.u + s.u_history);
  }


  template <int dim>
  void
  DragFieldTerm<dim>::point(const PointState<dim> &s,
                            const ScalarShapes<dim> &,
                            double,
                            MomentumCoefficients<dim> &m,
                            CellIntegrals &) const
  {
    m.reaction += s.beta;
    m.force += s.beta * (s.u - s.grain_velocity);
    m.force -= s.beta_last * s.u_last;
  }


  template <int dim>
  ViscousTerm<dim>::ViscousTerm(const double viscosity)
      : viscosity(viscosity)
  {
  }


  template <int dim>
  void
  ViscousTerm<dim>::point(const PointState<dim> &s,
                          const ScalarShapes<dim> &,
                          double,
                          MomentumCoefficients<dim> &m,
                          CellIntegrals &) const
  {
    m.diffusion += s.phi * viscosity;
    m.stress += s.phi * viscosity * s.grad_u;
  }


  template <int dim>
  AdvectionTerm<dim>::AdvectionTerm(const double density,
                                    const bool   newton,
                                    const bool   skew_symmetric)
      : density(density)
      , newton(newton)
      , skew_symmetric(skew_symmetric)
  {
  }


  template <int dim>
  void
  AdvectionTerm<dim>::point(const PointState<dim> &s,
                            const ScalarShapes<dim> &,
                            double,
                            MomentumCoefficients<dim> &m,
                            CellIntegrals &) const
  {
    // Picard: phi rho (u . grad du); Newton adds phi rho (grad u) du.
    m.convection_weight = s.phi * density;
    m.convection        = s.u;
    if (newton)
      m.convection_derivative = s.grad_u;
    m.force += s.phi * density * (s.grad_u * s.u);
    if (skew_symmetric)
    {
      // rho u R / 2 with R = d(phi)/dt + div(phi u), d(phi)/dt =
      // div(s) - mass_source from the grains' filtered flux s: tested with
      // u it cancels -rho |u|^2 R / 2, the energy the convective form
      // makes where the fluid's mass balance does not hold pointwise.
      const double residual = s.phi * dealii::trace(s.grad_u) +
                              s.grad_phi * s.u + s.solid_flux_divergence -
                              s.mass_source;
      m.reaction += 0.5 * density * residual;
      m.force += 0.5 * density * residual * s.u;
    }
  }


  template <int dim>
  bool
  AdvectionTerm<dim>::convects() const
  {
    return true;
  }


  template <int dim>
  bool
  AdvectionTerm<dim>::linearises_convection() const
  {
    return newton;
  }


  template <int dim>
  void
  ForcingTerm<dim>::point(const PointState<dim> &s,
                          const ScalarShapes<dim> &,
                          double,
                          MomentumCoefficients<dim> &m,
                          CellIntegrals &) const
  {
    m.force -= s.forcing;
  }


  template <int dim>
  void
  PressureContinuityTerm<dim>::point(const PointState<dim>     &s,
                                     const ScalarShapes<dim>   &shapes,
                                     const double               JxW,
                                     MomentumCoefficients<dim> &m,
                                     CellIntegrals             &integrals) const
  {
    const unsigned int n_s = integrals.n_s, n_p = integrals.n_p;
    m.force += s.alpha * s.grad_p;
    m.pressure = s.p;

    // Pressure rows: the continuity residual against Np_b, the total
    // solid flux against grad Np_b.
    const double continuity =
      s.phi * dealii::trace(s.grad_u) + s.grad_phi * s.u - s.mass_source;
    const dealii::Tensor<1, dim> solid_flux =
      s.solid_flux + s.alpha * s.u - s.mobility * s.grad_p;
    for (unsigned int b = 0; b < n_p; ++b)
    {
      double flux_b = 0;
      for (unsigned int d = 0; d < dim; ++d)
        flux_b += shapes.Gp[d][b] * solid_flux[d];
      integrals.rhs_p[b] -= (-shapes.Np[b] * continuity + flux_b) * JxW;
    }

    // B_{c,ab} = -Np_b (phi dN_a/dx_c + dphi/dx_c N_a)
    //          + alpha dNp_b/dx_c N_a.
    for (unsigned int c = 0; c < dim; ++c)
      add_to_divergence_block(n_s,
                              n_p,
                              shapes.N.data(),
                              shapes.G[c].data(),
                              shapes.Np.data(),
                              shapes.Gp[c].data(),
                              s.phi,
                              s.grad_phi[c],
                              s.alpha,
                              JxW,
                              &integrals.B[c * n_s * n_p]);
    if (s.mobility != 0)
      for (unsigned int b = 0; b < n_p; ++b)
        for (unsigned int e = 0; e < n_p; ++e)
        {
          double g = 0;
          for (unsigned int d = 0; d < dim; ++d)
            g += shapes.Gp[d][b] * shapes.Gp[d][e];
          integrals.C[b * n_p + e] -= s.mobility * g * JxW;
        }
  }


  template <int dim>
  GrainDragTerm<dim>::GrainDragTerm(const PointDragSource<dim>  &source,
                                    const dealii::FESystem<dim> &fe,
                                    const ScalarDofs<dim>       &dofs,
                                    const bool                   cell_averaged,
                                    double                      &max_beta)
      : source(source)
      , element(fe.base_element(0))
      , dofs(dofs)
      , cell_averaged(cell_averaged)
      , max_beta(max_beta)
      , shape(element.n_dofs_per_cell())
  {
  }


  template <int dim>
  void
  GrainDragTerm<dim>::cell(const CellContext<dim> &context,
                           CellIntegrals          &integrals) const
  {
    drags.clear();
    source.point_drags(context.cell, drags);
    if (drags.empty())
      return;
    const unsigned int n_s = integrals.n_s;

    if (cell_averaged)
    {
      // The cell averages of the velocity shape functions: the drag of
      // each grain spread evenly over its cell and felt against the
      // cell-mean velocity. Every grain of the cell has the same shape, so
      // their drags add up to one: sum beta_i against the cell-mean
      // velocity minus sum beta_i v_i.
      const auto &JxW    = *context.JxW;
      double      volume = 0;
      std::fill(shape.begin(), shape.end(), 0.0);
      for (unsigned int q = 0; q < JxW.size(); ++q)
      {
        volume += JxW[q];
        for (unsigned int a = 0; a < n_s; ++a)
          shape[a] += (*context.shapes)[q].N[a] * JxW[q];
      }
      for (unsigned int a = 0; a < n_s; ++a)
        shape[a] /= volume;
      PointDrag<dim> total;
      total.beta = 0;
      for (const auto &drag : drags)
      {
        total.beta += drag.beta;
        total.velocity += drag.beta * drag.velocity;
      }
      // total.velocity holds sum beta_i v_i.
      drags.assign(1, total);
    }

    for (const auto &drag : drags)
    {
      if (!cell_averaged)
        for (unsigned int a = 0; a < n_s; ++a)
          shape[a] = element.shape_value(a, drag.reference_location);
      dealii::Tensor<1, dim> u_at_grain;
      for (unsigned int a = 0; a < n_s; ++a)
        if (shape[a] != 0)
          for (unsigned int c = 0; c < dim; ++c)
            u_at_grain[c] +=
              (*context.local_solution)[dofs.velocity[a][c]] * shape[a];
      // The slip force beta (u - v); with the cell's grains summed,
      // sum beta_i u - sum beta_i v_i.
      const dealii::Tensor<1, dim> force =
        cell_averaged ? drag.beta * u_at_grain - drag.velocity :
                        drag.beta * (u_at_grain - drag.velocity);
      max_beta = std::max(max_beta, drag.beta);
      for (unsigned int a = 0; a < n_s; ++a)
      {
        if (shape[a] == 0)
          continue;
        for (unsigned int c = 0; c < dim; ++c)
          integrals.rhs_u[a * dim + c] -= force[c] * shape[a];
        double *row = &integrals.K[a * n_s];
        for (unsigned int b = 0; b < n_s; ++b)
          if (shape[b] != 0)
            row[b] += drag.beta * shape[a] * shape[b];
        if (context.preconditioner_pieces)
          integrals.R[a] += drag.beta * shape[a] * shape[a];
      }
    }
  }


  template <int dim>
  BoundaryFluxTerm<dim>::BoundaryFluxTerm(
    const dealii::Mapping<dim>  &mapping,
    const dealii::FESystem<dim> &fe,
    const ScalarDofs<dim>       &dofs,
    const Geometry<dim>         &geometry,
    const MixtureFields<dim>    &mixture_fields,
    dealii::Function<dim>       &open_pressure,
    const double                 time,
    const bool                   solid_crosses_boundaries,
    const double                 backflow_weight)
      : geometry(geometry)
      , solid_crosses_boundaries(solid_crosses_boundaries)
      , backflow_weight(backflow_weight)
      , mixture_fields(mixture_fields)
      , open_pressure(open_pressure)
      , time(time)
      , quadrature(fe.degree + 1)
      , fe_face_values(mapping,
                       fe,
                       quadrature,
                       dealii::update_values | dealii::update_normal_vectors |
                         dealii::update_quadrature_points |
                         dealii::update_JxW_values)
      , dofs(dofs)
  {
    open_pressure.set_time(time);
    for (const unsigned int f : dealii::GeometryInfo<dim>::face_indices())
      reference_points.push_back(
        dealii::QProjector<dim>::project_to_face(
          dealii::ReferenceCells::get_hypercube<dim>(), quadrature, f)
          .get_points());
  }


  template <int dim>
  bool
  BoundaryFluxTerm<dim>::needed(const Geometry<dim> &geometry,
                                const bool           solid_crosses_boundaries)
  {
    for (const auto &[id, type] : geometry.boundary_types)
      if (type == BoundaryType::open ||
          (type == BoundaryType::velocity && solid_crosses_boundaries))
        return true;
    return false;
  }


  template <int dim>
  void
  BoundaryFluxTerm<dim>::cell(const CellContext<dim> &context,
                              CellIntegrals          &integrals) const
  {
    const auto &cell = context.cell;
    for (const unsigned int face_no : cell->face_indices())
    {
      const auto face = cell->face(face_no);
      if (!face->at_boundary())
        continue;
      const BoundaryType type = geometry.boundary_type(face->boundary_id());
      if (type != BoundaryType::open &&
          !(type == BoundaryType::velocity && solid_crosses_boundaries))
        continue;
      fe_face_values.reinit(cell, face_no);
      mixture_fields.evaluate(cell,
                              fe_face_values.get_quadrature_points(),
                              reference_points[face_no],
                              time,
                              mixture);
      for (unsigned int q = 0; q < quadrature.size(); ++q)
      {
        const auto  &n   = fe_face_values.normal_vector(q);
        const double JxW = fe_face_values.JxW(q);
        const double outflux =
          solid_crosses_boundaries ? mixture.solid_flux[q] * n : 0.0;
        const double p_open =
          type == BoundaryType::open ?
            open_pressure.value(fe_face_values.quadrature_point(q)) :
            0.0;
        const unsigned int n_s = dofs.velocity.size();
        for (unsigned int a = 0; a < n_s; ++a)
        {
          const double N = fe_face_values.shape_value(dofs.velocity[a][0], q);
          for (unsigned int c = 0; c < dim; ++c)
            integrals.rhs_u[a * dim + c] -=
              (mixture.fluid_fraction[q] * p_open * (N * n[c])) * JxW;
        }
        if (backflow_weight > 0 && type == BoundaryType::open)
        {
          // Where the fluid enters: -b rho phi (u.n)/2 N_a N_b on the
          // velocity block, (u.n) of the current iterate (Picard).
          const auto            &local = *context.local_solution;
          dealii::Tensor<1, dim> u;
          for (unsigned int a = 0; a < n_s; ++a)
          {
            const double N = fe_face_values.shape_value(dofs.velocity[a][0], q);
            for (unsigned int c = 0; c < dim; ++c)
              u[c] += local[dofs.velocity[a][c]] * N;
          }
          const double un = u * n;
          if (un < 0)
          {
            const double weight =
              -0.5 * backflow_weight * mixture.fluid_fraction[q] * un * JxW;
            for (unsigned int a = 0; a < n_s; ++a)
            {
              const double Na =
                fe_face_values.shape_value(dofs.velocity[a][0], q);
              for (unsigned int b = 0; b < n_s; ++b)
                integrals.K[a * n_s + b] +=
                  weight * Na *
                  fe_face_values.shape_value(dofs.velocity[b][0], q);
              for (unsigned int c = 0; c < dim; ++c)
                integrals.rhs_u[a * dim + c] -= weight * u[c] * Na;
            }
          }
        }
        if (outflux != 0)
          for (unsigned int b = 0; b < dofs.pressure.size(); ++b)
            integrals.rhs_p[b] -=
              (-fe_face_values.shape_value(dofs.pressure[b], q) * outflux) *
              JxW;
      }
    }
  }


  template struct ScalarDofs<2>;
  template struct ScalarDofs<3>;
  template struct ScalarShapes<2>;
  template struct ScalarShapes<3>;
  template class AssemblyTerm<2>;
  template class AssemblyTerm<3>;
  template class TimeDerivativeTerm<2>;
  template class TimeDerivativeTerm<3>;
  template class DragFieldTerm<2>;
  template class DragFieldTerm<3>;
  template class ViscousTerm<2>;
  template class ViscousTerm<3>;
  template class AdvectionTerm<2>;
  template class AdvectionTerm<3>;
  template class ForcingTerm<2>;
  template class ForcingTerm<3>;
  template class PressureContinuityTerm<2>;
  template class PressureContinuityTerm<3>;
  template class GrainDragTerm<2>;
  template class GrainDragTerm<3>;
  template class BoundaryFluxTerm<2>;
  template class BoundaryFluxTerm<3>;
} // namespace ImmersedGrains
