#ifndef immersed_grains_io_output_series_h
#define immersed_grains_io_output_series_h

#include <deal.II/base/data_out_base.h>
#include <deal.II/base/mpi.h>

#include <string>
#include <utility>
#include <vector>

namespace ImmersedGrains
{
  /** How a time series of fields or grains is written (Output/Format). */
  enum class OutputFormat
  {
    vtu, // one VTU piece per rank, a PVTU record per time, a PVD list
    hdf5 // one HDF5 file per time written by all ranks, an XDMF list
  };

  /**
   * One time series of outputs (the fluid's fields, or the grains):
   * writes each state in the chosen format and keeps the list ParaView
   * opens (NAME.pvd or NAME.xdmf) up to date after every write, so that a
   * running or killed run can be read. The list survives a checkpoint:
   * records() for the PVD, save()/load() for the XDMF grids.
   */
  class OutputSeries
  {
  public:
    OutputSeries(const std::string &directory,
                 const std::string &name,
                 OutputFormat       format,
                 MPI_Comm           comm);

    /** Writes @p data_out's patches as the state of @p step at @p time. */
    template <int patch_dim, int spacedim>
    void
    write(const dealii::DataOutInterface<patch_dim, spacedim> &data_out,
          double                                               time,
          unsigned int                                         step);

    /** (time, file) of every state written, for the checkpoint. */
    std::vector<std::pair<double, std::string>> &
    records()
    {
      return written;
    }

    /** With HDF5: the XDMF grids, to FILE (rank 0) and back. */
    void
    save(const std::string &file) const;
    void
    load(const std::string &file);

  private:
    void
    write_list() const;

    std::string                                 directory;
    std::string                                 name;
    OutputFormat                                format;
    MPI_Comm                                    comm;
    std::vector<std::pair<double, std::string>> written;
    std::vector<std::string>                    xdmf_grids;
  };
} // namespace ImmersedGrains

#endif
