#include <deal.II/base/mpi.h>

#include <immersed_grains/grains/grains.h>
#include <immersed_grains/io/grain_file.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <vector>

namespace ImmersedGrains
{
  template <int dim>
  void
  write_grain_file(const Grains<dim> &grains,
                   const std::string &file_name,
                   const double       time,
                   MPI_Comm           comm)
  {
    // id, position, radius, velocity
    using Row               = std::array<double, 2 * dim + 2>;
    const auto      &layout = grains.layout();
    std::vector<Row> rows;
    for (const auto &particle : grains.particle_handler())
    {
      const auto props = particle.get_properties();
      Row        row;
      row[0] = static_cast<double>(particle.get_id());
      for (unsigned int d = 0; d < dim; ++d)
      {
        row[1 + d]       = particle.get_location()[d];
        row[2 + dim + d] = props[layout.velocity + d];
      }
      row[1 + dim] = props[layout.radius];
      rows.push_back(row);
    }
    const auto all = dealii::Utilities::MPI::gather(comm, rows, 0);
    if (dealii::Utilities::MPI::this_mpi_process(comm) != 0)
      return;
    rows.clear();
    for (const auto &part : all)
      rows.insert(rows.end(), part.begin(), part.end());
    std::sort(rows.begin(),
              rows.end(),
              [](const Row &a, const Row &b) { return a[0] < b[0]; });

    const std::string partial = file_name + ".partial";
    {
      std::ofstream out(partial);
      if (!out)
        throw std::runtime_error("cannot write " + partial);
      out << "# " << rows.size() << " grains at t = " << time << " s: x y"
          << (dim == 3 ? " z" : "") << " r vx vy" << (dim == 3 ? " vz" : "")
          << " (Grains/Placement/Shape = file reads it)\n";
      char number[32];
      for (const auto &row : rows)
      {
        for (unsigned int c = 1; c < row.size(); ++c)
        {
          std::snprintf(number, sizeof(number), "%.17g", row[c]);
          out << number << (c + 1 < row.size() ? ' ' : '\n');
        }
      }
      out.close();
      if (!out)
        throw std::runtime_error("cannot write " + partial);
    }
    std::filesystem::rename(partial, file_name);
  }


  template void
  write_grain_file(const Grains<2> &, const std::string &, double, MPI_Comm);
  template void
  write_grain_file(const Grains<3> &, const std::string &, double, MPI_Comm);
} // namespace ImmersedGrains
