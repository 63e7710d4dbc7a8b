#ifndef immersed_grains_divergence_guard_h
#define immersed_grains_divergence_guard_h

#include <deal.II/base/conditional_ostream.h>
#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/tensor.h>

#include <mpi.h>

#include <string>

namespace ImmersedGrains
{
  template <int dim>
  class FluidSolver;
  template <int dim>
  class Grains;
  template <int dim>
  struct GrainStatistics;

  /**
   * Tells a run that is diverging from one that is not, after each step:
   * a fluid value or a grain that is not finite (NaN or Inf), or a speed
   * over Divergence speed factor times the fastest motion the scene drives
   * (free fall across the domain along gravity, the grains' initial speeds,
   * what the fluid's data drive). An exploding run reaches such speeds
   * before NaN, while its adaptive steps shrink towards zero. It names the
   * field and the place (collective), and leaves stopping to the caller.
   */
  template <int dim>
  class DivergenceGuard
  {
  public:
    /** Top-level entries: Divergence speed factor. */
    static void
    declare_parameters(dealii::ParameterHandler &prm);
    void
    parse_parameters(dealii::ParameterHandler &prm);

    /** @p fall_height: the domain's extent along gravity @p gravity. */
    void
    start(const dealii::Tensor<1, dim> &gravity,
          double                        fall_height,
          double                        initial_grain_speed,
          MPI_Comm                      comm);

    /** What is not finite and where, or empty: the message of a run that
     *  stops after writing step @p step. @p grain_statistics: the step's
     *  (null without grains). */
    std::string
    find_not_finite(const FluidSolver<dim>     *fluid,
                    const Grains<dim>          *grains,
                    const GrainStatistics<dim> *grain_statistics,
                    unsigned int                step) const;

    /** Which speed outran the bound and where, or empty, as above. */
    std::string
    find_speeding(const FluidSolver<dim>     *fluid,
                  const Grains<dim>          *grains,
                  const GrainStatistics<dim> *grain_statistics,
                  unsigned int                step);

    /** The fastest speed seen against the driven one (the log's last
     *  lines), if any was measured. */
    void
    print_summary(dealii::ConditionalOStream &out) const;

  private:
    double
    driven_speed(const FluidSolver<dim> *fluid) const;

    double                 speed_factor = 100;
    dealii::Tensor<1, dim> gravity;
    double                 fall_height         = 0;
    double                 initial_grain_speed = 0;
    MPI_Comm               comm                = MPI_COMM_WORLD;
    // The largest speed over the driven speed so far, and that speed then.
    double largest_speed_ratio = 0;
    double driven_at_largest   = 0;
  };

} // namespace ImmersedGrains

#endif
