// The executable's command line: reads the dimension, lets Simulation<dim>
// declare and parse the rest, runs. Input errors are one line on stderr and
// a non-zero exit, before anything is written.
#include <deal.II/base/exceptions.h>
#include <deal.II/base/mpi.h>
#include <deal.II/base/parameter_handler.h>

#include <immersed_grains/command_line.h>
#include <immersed_grains/parameters.h>
#include <immersed_grains/simulation.h>

#include <iostream>
#include <sstream>
#include <string>

namespace
{
  const char *usage =
    "usage: immersed-grains SCENE.prm          run a scene (mpirun -np N "
    "works)\n"
    "       immersed-grains --check SCENE.prm  validate it (placement, mesh,\n"
    "                                          memory) without writing, and\n"
    "                                          print its regime and warnings\n"
    "       immersed-grains --print-parameters [2|3]\n"
    "                                          every parameter, its default\n"
    "                                          and documentation\n"
    "       immersed-grains --help\n";

  // Runs the scene, or with @p check_only parses, places and estimates it
  // and prints its regime without writing anything.
  template <int dim>
  void
  run_scene(const std::string &file, const bool check_only)
  {
    dealii::ParameterHandler prm;
    ImmersedGrains::Simulation<dim>::declare_parameters(prm);
    ImmersedGrains::parse_parameter_file(prm, file);
    ImmersedGrains::Simulation<dim> simulation(prm, file, MPI_COMM_WORLD);
    if (check_only)
      simulation.print_check(std::cout);
    else
      simulation.run();
  }

  template <int dim>
  void
  print_parameters()
  {
    dealii::ParameterHandler prm;
    ImmersedGrains::Simulation<dim>::declare_parameters(prm);
    prm.print_parameters(std::cout, dealii::ParameterHandler::PRM);
  }
} // namespace


int
ImmersedGrains::run_command_line(int argc, char **argv)
{
  dealii::Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  const bool                               root =
    dealii::Utilities::MPI::this_mpi_process(MPI_COMM_WORLD) == 0;
  // deal.II would print a backtrace and abort on a failed AssertThrow in
  // some configurations; we want the message only.
  dealii::deal_II_exceptions::disable_abort_on_exception();
  dealii::deal_II_exceptions::suppress_stacktrace_in_exceptions();

  const std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty() || args[0] == "--help" || args[0] == "-h")
  {
    if (root)
      (args.empty() ? std::cerr : std::cout) << usage;
    return args.empty() ? 1 : 0;
  }

  try
  {
    if (args[0] == "--print-parameters")
    {
      const std::string dim = args.size() > 1 ? args[1] : "2";
      if (dim != "2" && dim != "3")
        throw std::runtime_error("--print-parameters takes 2 or 3, not '" +
                                 dim + "'");
      if (root)
        (dim == "2" ? print_parameters<2>() : print_parameters<3>());
      return 0;
    }
    const bool check_only = args[0] == "--check";
    if (check_only ? args.size() != 2 :
                     args.size() != 1 || args[0].rfind("-", 0) == 0)
    {
      if (root)
        std::cerr << usage;
      return 1;
    }

    const std::string  file = args.back();
    const unsigned int dim  = ImmersedGrains::read_dimension(file);
    if (dim == 2)
      run_scene<2>(file, check_only);
    else
      run_scene<3>(file, check_only);
  }
  catch (const ImmersedGrains::InputError &e)
  {
    if (root)
      std::cerr << "immersed-grains: error: " << e.what() << std::endl;
    return 1;
  }
  catch (const dealii::ExceptionBase &e)
  {
    std::ostringstream info;
    e.print_info(info);
    std::cerr << "immersed-grains: error: "
              << ImmersedGrains::one_line(info.str()) << std::endl;
    if (dealii::Utilities::MPI::n_mpi_processes(MPI_COMM_WORLD) > 1)
      MPI_Abort(MPI_COMM_WORLD, 2);
    return 2;
  }
  catch (const std::exception &e)
  {
    // Parse errors are raised on every rank alike: print once.
    if (root)
      std::cerr << "immersed-grains: error: "
                << ImmersedGrains::one_line(e.what()) << std::endl;
    return 1;
  }
  return 0;
}
