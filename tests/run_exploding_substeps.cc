// A coupled run whose grains would need more sub-steps in one fluid step
// than Coupling/Maximum grain sub-steps allows stops, or with an adaptive
// step takes the step again with half its length. A disc (r = 0.1 mm,
// 2500 kg/m^3) thrown at 1 m/s into a viscous liquid (0.1 Pa s) in a
// 1 cm box, in fluid steps of 0.1 s: its sub-steps of an eighth of its
// radius need 1 / (1.25e-5 / 0.1) = 8000 of them in the first step, over
// the default bound of 1000.
// With a fixed step: one line on stderr naming the step, the sub-steps
// and the bound, a non-zero exit status. With Maximum grain sub-steps =
// 10000 the same run goes on (the disc stops within its relaxation time,
// 65 us, and settles). With a fixed first step of 0.0125 s, which needs
// exactly 1000, it runs to its end too: the bound itself is allowed.
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <regex>
#include <string>

namespace fs = std::filesystem;

namespace
{
  std::string
  thrown_disc(const std::string &name,
              const double       time_step,
              const std::string &coupling)
  {
    fs::remove_all("out_" + name);
    std::ofstream f(name + ".prm");
    f << "set Dimension = 2\n"
         "set Output directory = out_"
      << name
      << "\n"
         "set End time = 0.2\n"
         "set Time step = "
      << time_step
      << "\n"
         "subsection Mesh\n"
         "  set Lower corner = 0, 0\n"
         "  set Upper corner = 1e-2, 1e-2\n"
         "  set Subdivisions = 4, 4\n"
         "  set Initial refinement = 0\n"
         "end\n"
         "subsection Fluid\n"
         "  set Density = 1000\n"
         "  set Viscosity = 0.1\n"
         "  set Advection = false\n"
         "end\n"
         "subsection Grains\n"
         "  set Enabled = true\n"
         "  set Radius = 1e-4\n"
         "  set Density = 2500\n"
         "  subsection Placement\n"
         "    set Shape = list\n"
         "    set Positions = 5e-3, 5e-3\n"
         "    set Velocities = 0, -1\n"
         "  end\n"
         "end\n"
         "subsection Coupling\n"
      << coupling
      << "end\n"
         "subsection Gravity\n"
         "  set Vector = 0, -9.81\n"
         "end\n"
         "subsection Output\n"
         "  set Terminal output = quiet\n"
         "end\n";
    return std::string(IMMERSED_GRAINS_EXECUTABLE) + " " + name +
           ".prm > stdout_" + name + " 2> stderr_" + name;
  }


  std::string
  contents(const std::string &path)
  {
    std::ifstream f(path);
    return {std::istreambuf_iterator<char>(f),
            std::istreambuf_iterator<char>()};
  }


  unsigned int
  lines(const std::string &text)
  {
    unsigned int n = 0;
    for (const char c : text)
      n += c == '\n';
    return n;
  }
} // namespace


int
main()
{
  const int stopped       = std::system(thrown_disc("fixed", 0.1, "").c_str());
  const std::string error = contents("stderr_fixed");
  std::cout << "exit status non-zero: " << (stopped != 0 ? "yes" : "no")
            << "\nlines on stderr: " << lines(error)
            << "\nnames the step, the sub-steps and the bound: "
            << (std::regex_search(error,
                                  std::regex("step 1 .*8000 grain "
                                             "sub-steps.*Maximum grain "
                                             "sub-steps = 1000")) ?
                  "yes" :
                  "no")
            << '\n';

  const int raised = std::system(
    thrown_disc("raised", 0.1, "  set Maximum grain sub-steps = 10000\n")
      .c_str());
  std::cout << "with the bound raised, runs to its end: "
            << (raised == 0 && contents("stderr_raised").empty() ? "yes" : "no")
            << '\n';

  const int at_bound = std::system(thrown_disc("at_bound", 0.0125, "").c_str());
  std::cout << "a step that needs exactly the bound runs: "
            << (at_bound == 0 ? "yes" : "no") << '\n';
  if (stopped == 0 || raised != 0 || at_bound != 0)
    std::cout << error << contents("stderr_raised")
              << contents("stderr_at_bound");
  return 0;
}
