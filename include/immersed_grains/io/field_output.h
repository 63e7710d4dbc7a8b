#ifndef immersed_grains_io_field_output_h
#define immersed_grains_io_field_output_h

#include <deal.II/base/parameter_handler.h>
#include <deal.II/distributed/tria.h>
#include <deal.II/numerics/data_out.h>

#include <immersed_grains/io/output_series.h>

#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace ImmersedGrains
{
  /**
   * Writes the fields of one output time, as VTU pieces (one per rank)
   * with a PVTU master listed in fields.pvd, or as one HDF5 file listed in
   * fields.xdmf (Output/Format). Each carries the MPI rank and refinement
   * level as cell data.
   */
  template <int dim>
  class FieldOutput
  {
  public:
    FieldOutput(const std::string &directory,
                OutputFormat       format,
                MPI_Comm           comm);

    /**
     * @p add_fields attaches the solver's vectors to the DataOut object.
     */
    void
    write(const dealii::parallel::distributed::Triangulation<dim> &tria,
          double                                                   time,
          unsigned int                                             step,
          const std::function<void(dealii::DataOut<dim> &)>       &add_fields);

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
