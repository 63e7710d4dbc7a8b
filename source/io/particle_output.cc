#include <deal.II/base/utilities.h>
#include <deal.II/particles/data_out.h>

#include <immersed_grains/io/particle_output.h>

#include <fstream>

namespace ImmersedGrains
{
  template <int dim>
  ParticleOutput<dim>::ParticleOutput(const std::string &directory,
                                      const OutputFormat format,
                                      MPI_Comm           comm)
      : written(directory, "particles", format, comm)
  {
  }


  template <int dim>
  void
  ParticleOutput<dim>::write(
    const dealii::Particles::ParticleHandler<dim> &particles,
    const std::vector<std::string>                &names,
    const std::vector<
      dealii::DataComponentInterpretation::DataComponentInterpretation>
                      &interpretations,
    const double       time,
    const unsigned int step)
  {
    dealii::Particles::DataOut<dim> data_out;
    data_out.build_patches(particles, names, interpretations);

    dealii::DataOutBase::VtkFlags flags;
    flags.time              = time;
    flags.cycle             = step;
    flags.compression_level = dealii::DataOutBase::VtkFlags::best_speed;
    data_out.set_flags(flags);

    written.write(data_out, time, step);
  }


  template class ParticleOutput<2>;
  template class ParticleOutput<3>;
} // namespace ImmersedGrains
