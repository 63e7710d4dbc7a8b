#ifndef immersed_grains_io_particle_output_h
#define immersed_grains_io_particle_output_h

#include <deal.II/base/mpi.h>
#include <deal.II/numerics/data_component_interpretation.h>
#include <deal.II/particles/particle_handler.h>

#include <string>
#include <utility>
#include <vector>

namespace ImmersedGrains
{
  /**
   * Writes the grains of one output time as VTU pieces (one per rank, one
   * vertex per grain with its id and properties) with a PVTU master, and
   * keeps particles.pvd, the time series ParaView opens beside fields.pvd.
   * Show them as spheres with the Glyph filter scaled by "radius".
   */
  template <int dim>
  class ParticleOutput
  {
  public:
    ParticleOutput(const std::string &directory, MPI_Comm comm);

    void
    write(const dealii::Particles::ParticleHandler<dim> &particles,
          const std::vector<std::string>                &names,
          const std::vector<
            dealii::DataComponentInterpretation::DataComponentInterpretation>
                      &interpretations,
          double       time,
          unsigned int step);

    /** The (time, file) records of the PVD file, for a checkpoint. */
    std::vector<std::pair<double, std::string>> &
    pvd_records()
    {
      return records;
    }

  private:
    std::string                                 directory;
    MPI_Comm                                    comm;
    std::vector<std::pair<double, std::string>> records;
  };
} // namespace ImmersedGrains

#endif
