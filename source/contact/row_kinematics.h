#ifndef immersed_grains_source_contact_row_kinematics_h
#define immersed_grains_source_contact_row_kinematics_h

// How a contact row sees the grains' motion, on the raw arrays of the
// solver's work arrays: shared by the sweeps, APGD and the subspace
// correction. An angular velocity is a scalar in 2D.

#include <immersed_grains/contact/contact_solver.h>

namespace ImmersedGrains
{
  namespace Contact
  {
    namespace internal
    {
      // out = s x n: s an angular velocity, n in the plane.
      template <int dim>
      inline void
      spin_cross(const double *s, const double *n, double *out)
      {
        if constexpr (dim == 2)
        {
          out[0] = -s[0] * n[1];
          out[1] = s[0] * n[0];
        }
        else
        {
          out[0] = s[1] * n[2] - s[2] * n[1];
          out[1] = s[2] * n[0] - s[0] * n[2];
          out[2] = s[0] * n[1] - s[1] * n[0];
        }
      }

      // out = n x p for two vectors of the space (a scalar in 2D).
      template <int dim>
      inline void
      vector_cross(const double *n, const double *p, double *out)
      {
        if constexpr (dim == 2)
          out[0] = n[0] * p[1] - n[1] * p[0];
        else
        {
          out[0] = n[1] * p[2] - n[2] * p[1];
          out[1] = n[2] * p[0] - n[0] * p[2];
          out[2] = n[0] * p[1] - n[1] * p[0];
        }
      }
    } // namespace internal



    /// The relative velocity of the contact point, partner less grain:
    /// u_n alone without friction, the vector with the rotations with it.
    template <int dim>
    template <bool with_friction>
    void
    ContactSolver<dim>::contact_velocity(const unsigned int k,
                                         double            *out) const
    {
      const Row       &row = rows[k];
      const GrainSlot &a   = grains[row.i];
      const GrainSlot &b   = grains[row.j];
      if constexpr (!with_friction)
      {
        double u_n = 0;
        for (unsigned int d = 0; d < dim; ++d)
          u_n += (b.velocity[d] - a.velocity[d]) * row.normal[d];
        out[0] = u_n;
      }
      else
      {
        const FrictionRow &f = friction_rows[k];
        double             spin[spin_dim], lever[dim];
        for (unsigned int d = 0; d < spin_dim; ++d)
          spin[d] = f.radius_i * spins[row.i].angular_velocity[d] +
                    f.radius_j * spins[row.j].angular_velocity[d];
        internal::spin_cross<dim>(spin, row.normal, lever);
        for (unsigned int d = 0; d < dim; ++d)
          out[d] = b.velocity[d] - a.velocity[d] - lever[d];
      }
    }
  } // namespace Contact
} // namespace ImmersedGrains

#endif
