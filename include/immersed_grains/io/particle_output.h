#ifndef immersed_grains_io_particle_output_h
#define immersed_grains_io_particle_output_h

#include <deal.II/base/mpi.h>
#include <deal.II/numerics/data_component_interpretation.h>
#include <deal.II/particles/particle_handler.h>

#include <string>
#include <utility>
#include <vector>

#include <immersed_grains/io/output_series.h>

namespace ImmersedGrains
{
  /**
   * Writes the grains of one output time (one vertex per grain with its id
   * and properties) as VTU pieces with a PVTU master listed in
   * particles.pvd, or as one HDF5 file listed in particles.xdmf
   * (Output/Format), the time series ParaView opens beside the fields'.
   * Show them as spheres with the Glyph filter scaled by "radius".
   */
  template <int dim>
  class ParticleOutput
  {
  public:
    ParticleOutput(const std::string &directory,
                   OutputFormat       format,
                   MPI_Comm           comm);

    void
    write(const dealii::Particles::ParticleHandler<dim> &particles,
          const std::vector<std::string>                &names,
          const std::vector<
            dealii::DataComponentInterpretation::DataComponentInterpretation>
                      &interpretations,
          double       time,
          unsigned int step);

    /** The states written, for a checkpoint. */
    OutputSeries &
    series()
    {
      return written;
    }

  private:
    OutputSeries written;
  };
} // namespace ImmersedGrains

#endif
