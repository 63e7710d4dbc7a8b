#include <deal.II/base/utilities.h>

#include <immersed_grains/io/field_output.h>

#include <fstream>

namespace ImmersedGrains
{
  template <int dim>
  FieldOutput<dim>::FieldOutput(const std::string &directory,
                                const OutputFormat format,
                                MPI_Comm           comm)
      : written(directory, "fields", format, comm)
  {
  }


  template <int dim>
  void
  FieldOutput<dim>::write(
    const dealii::parallel::distributed::Triangulation<dim> &tria,
    const double                                             time,
    const unsigned int                                       step,
    const std::function<void(dealii::DataOut<dim> &)>       &add_fields)
  {
    dealii::DataOut<dim> data_out;
    data_out.attach_triangulation(tria);
    add_fields(data_out);

    dealii::Vector<float> rank(tria.n_active_cells());
    dealii::Vector<float> level(tria.n_active_cells());
    for (const auto &cell : tria.active_cell_iterators())
      if (cell->is_locally_owned())
      {
        rank(cell->active_cell_index())  = tria.locally_owned_subdomain();
        level(cell->active_cell_index()) = cell->level();
      }
    data_out.add_data_vector(rank, "mpi_rank");
    data_out.add_data_vector(level, "refinement_level");

    dealii::DataOutBase::VtkFlags flags;
    flags.time              = time;
    flags.cycle             = step;
    flags.compression_level = dealii::DataOutBase::VtkFlags::best_speed;
    data_out.set_flags(flags);
    // Quadratic cells drawn as 2^dim subcells; XDMF knows linear cells
    // only, where the subcells are cells of their own.
    data_out.build_patches(2);
    written.write(data_out, time, step);
  }


  template class FieldOutput<2>;
  template class FieldOutput<3>;
} // namespace ImmersedGrains
