// Output/Format = hdf5: a 2D cloud of 81 discs in a fluid on an adaptive
// mesh writes its fields and grains every 2 steps for 6 steps as one HDF5
// file per output time, listed in fields.xdmf and particles.xdmf. A second
// run stops after step 3 (checkpoints every 2 steps) and a third resumes
// it from step 2. Checked: each list has the 4 states (steps 0, 2, 4, 6)
// with their times; every file it names exists and is an HDF5 file (its
// signature); the grains' list has one vertex per grain; and the resumed
// run's lists are the straight run's, character for character (the XDMF
// grids written before the checkpoint travel with it): the reference for
// the restart is the code's own straight run.
#include <deal.II/base/mpi.h>
#include <deal.II/base/parameter_handler.h>

#include <immersed_grains/parameters.h>
#include <immersed_grains/simulation.h>

#include <filesystem>
#include <fstream>
#include <iostream>
#include <regex>
#include <sstream>
#include <string>

using namespace dealii;
using namespace ImmersedGrains;

namespace
{
  const char *scene = R"(set Dimension = 2
set Time step = 0.05
subsection Mesh
  set Lower corner = 0, 0
  set Upper corner = 2e-3, 2e-3
  set Subdivisions = 1, 1
  set Initial refinement = 3
end
subsection Fluid
  set Density   = 1200
  set Viscosity = 0.12
  set Advection = false
end
subsection Grains
  set Enabled = true
  set Radius  = 12.5e-6
  set Density = 2400
  subsection Placement
    set Shape          = ball
    set Center         = 1e-3, 1.3e-3
    set Size           = 2.5e-4
    set Solid fraction = 0.2
    set Random seed    = 7
  end
end
subsection Gravity
  set Vector = 0, -9.81
end
subsection Adaptivity
  set Enabled   = true
  set Min level = 2
  set Max level = 4
end
subsection Checkpoint
  set Every steps = 2
end
subsection Output
  set Terminal output    = quiet
  set Format             = hdf5
  set Write fields every = 2
end
)";

  void
  run(const std::string &directory, const double end_time, const bool resume)
  {
    const std::string file = directory + ".prm";
    if (Utilities::MPI::this_mpi_process(MPI_COMM_WORLD) == 0)
    {
      std::ofstream prm(file);
      prm << scene << "set End time = " << end_time
          << "\nset Output directory = " << directory
          << "\nsubsection Checkpoint\n  set Resume = "
          << (resume ? "true" : "false") << "\nend\n";
    }
    MPI_Barrier(MPI_COMM_WORLD);
    ParameterHandler prm;
    Simulation<2>::declare_parameters(prm);
    parse_parameter_file(prm, file);
    Simulation<2> simulation(prm, file, MPI_COMM_WORLD);
    simulation.run();
  }

  std::string
  text_of(const std::string &file)
  {
    std::ifstream in(file);
    return std::string((std::istreambuf_iterator<char>(in)),
                       std::istreambuf_iterator<char>());
  }

  // The states an XDMF list names, and whether all its files are HDF5.
  void
  check_list(const std::string &directory, const std::string &name)
  {
    const std::string  text = text_of(directory + "/" + name + ".xdmf");
    std::ostringstream times;
    unsigned int       grids = 0;
    const std::regex   time(R"(<Time Value="([^"]+)\"/>)");
    for (std::sregex_iterator m(text.begin(), text.end(), time), end; m != end;
         ++m, ++grids)
      times << (grids ? ", " : "") << (*m)[1];
    bool             all_hdf5 = true;
    unsigned int     files    = 0;
    const std::regex file(R"(([A-Za-z_0-9]+\.h5):/nodes)");
    for (std::sregex_iterator m(text.begin(), text.end(), file), end; m != end;
         ++m, ++files)
    {
      const std::string signature =
        text_of(directory + "/" + (*m)[1].str()).substr(0, 8);
      all_hdf5 = all_hdf5 && signature == "\x89HDF\r\n\x1a\n";
    }
    std::cout << name << ".xdmf: " << grids << " states at t = " << times.str()
              << "; " << files
              << " files, all HDF5: " << (all_hdf5 ? "yes" : "no") << '\n';
  }
} // namespace


int
main(int argc, char **argv)
{
  Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  const bool root = Utilities::MPI::this_mpi_process(MPI_COMM_WORLD) == 0;
  if (root)
  {
    std::filesystem::remove_all("straight");
    std::filesystem::remove_all("resumed");
  }
  MPI_Barrier(MPI_COMM_WORLD);

  run("straight", 0.3, false);
  run("resumed", 0.15, false);
  run("resumed", 0.3, true);
  if (!root)
    return 0;

  check_list("straight", "fields");
  check_list("straight", "particles");
  const std::string particles = text_of("straight/particles.xdmf");
  std::cout << "one vertex per grain: "
            << (particles.find(
                  "NumberOfElements=\"81\" NodesPerElement=\"1\"") !=
                    std::string::npos ?
                  "yes" :
                  "no")
            << '\n';
  for (const char *name : {"fields", "particles"})
    std::cout << "resumed " << name << ".xdmf equals the straight run's: "
              << (text_of(std::string("straight/") + name + ".xdmf") ==
                      text_of(std::string("resumed/") + name + ".xdmf") ?
                    "yes" :
                    "no")
              << '\n';
}
