#include <deal.II/base/utilities.h>
#include <deal.II/grid/reference_cell.h>

#include <immersed_grains/io/output_series.h>

#include <fstream>
#include <iterator>

namespace ImmersedGrains
{
  OutputSeries::OutputSeries(const std::string &directory,
                             const std::string &name,
                             const OutputFormat format,
                             MPI_Comm           comm)
      : directory(directory)
      , name(name)
      , format(format)
      , comm(comm)
  {
  }


  template <int patch_dim, int spacedim>
  void
  OutputSeries::write(
    const dealii::DataOutInterface<patch_dim, spacedim> &data_out,
    const double                                         time,
    const unsigned int                                   step)
  {
    if (format == OutputFormat::vtu)
    {
      const std::string master = data_out.write_vtu_with_pvtu_record(
        directory + "/", name, step, comm, 5, 8);
      written.emplace_back(time, master);
    }
    else
    {
      // Duplicate vertices merged: XDMF readers take one mesh per file.
      dealii::DataOutBase::DataOutFilter filter(
        dealii::DataOutBase::DataOutFilterFlags(true, true));
      data_out.write_filtered_data(filter);
      const std::string file =
        name + "_" + dealii::Utilities::int_to_string(step, 5) + ".h5";
      data_out.write_hdf5_parallel(filter, directory + "/" + file, comm);
      const dealii::XDMFEntry entry =
        data_out.create_xdmf_entry(filter, file, time, comm);
      xdmf_grids.push_back(entry.get_xdmf_content(
        3, dealii::ReferenceCells::get_hypercube<patch_dim>()));
      written.emplace_back(time, file);
    }
    write_list();
  }


  void
  OutputSeries::write_list() const
  {
    if (dealii::Utilities::MPI::this_mpi_process(comm) != 0)
      return;
    if (format == OutputFormat::vtu)
    {
      std::ofstream pvd(directory + "/" + name + ".pvd");
      dealii::DataOutBase::write_pvd_record(pvd, written);
      return;
    }
    std::ofstream xdmf(directory + "/" + name + ".xdmf");
    xdmf << "<?xml version=\"1.0\" ?>\n"
         << "<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n"
         << "<Xdmf Version=\"2.0\">\n"
         << "  <Domain>\n"
         << "    <Grid Name=\"CellTime\" GridType=\"Collection\" "
            "CollectionType=\"Temporal\">\n";
    for (const auto &grid : xdmf_grids)
      xdmf << grid;
    xdmf << "    </Grid>\n  </Domain>\n</Xdmf>\n";
  }


  void
  OutputSeries::save(const std::string &file) const
  {
    if (format != OutputFormat::hdf5 ||
        dealii::Utilities::MPI::this_mpi_process(comm) != 0)
      return;
    // Each grid as its length in characters, a newline, and its text.
    std::ofstream out(file);
    out << xdmf_grids.size() << '\n';
    for (const auto &grid : xdmf_grids)
      out << grid.size() << '\n' << grid;
    AssertThrow(out, dealii::ExcMessage("Cannot write " + file));
  }


  void
  OutputSeries::load(const std::string &file)
  {
    xdmf_grids.clear();
    if (format != OutputFormat::hdf5)
      return;
    std::ifstream in(file);
    std::size_t   n = 0;
    in >> n;
    for (std::size_t k = 0; k < n && in; ++k)
    {
      std::size_t length = 0;
      in >> length;
      in.get(); // the newline
      std::string grid(length, ' ');
      in.read(grid.data(), length);
      xdmf_grids.push_back(grid);
    }
    AssertThrow(in && xdmf_grids.size() == written.size(),
                dealii::ExcMessage("Checkpoint: cannot read " + file));
  }


  template void
  OutputSeries::write(const dealii::DataOutInterface<2, 2> &,
                      double,
                      unsigned int);
  template void
  OutputSeries::write(const dealii::DataOutInterface<3, 3> &,
                      double,
                      unsigned int);
  template void
  OutputSeries::write(const dealii::DataOutInterface<0, 2> &,
                      double,
                      unsigned int);
  template void
  OutputSeries::write(const dealii::DataOutInterface<0, 3> &,
                      double,
                      unsigned int);
} // namespace ImmersedGrains
