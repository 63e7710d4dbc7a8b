// A run that explodes without ever reaching NaN must stop too. A lid-driven
// cavity at a Reynolds number of 10^7 on 8 x 8 cells is far from resolved:
// its velocity grows without bound, and the adaptive step shrinks with it
// (to 1e-80 s by t = 2.27 s, where the run would sit for ever: time no
// longer advances, and the velocity, 1e78 m/s, is still finite). The
// divergence check (DivergenceGuard::find_speeding, source/divergence_guard.cc)
// stops it once a speed exceeds 100 times the fastest motion the scene drives,
// here free fall across the unit box, sqrt(2 g) = 4.43 m/s: one line on stderr
// naming the step and the speed, a non-zero exit status, a last output of that
// step. The same cavity with the lid at 1 mm/s and a viscosity that
// resolves it runs to its end with the check on.
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <regex>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace
{
  std::string
  cavity(const std::string &name, const double viscosity, const double lid)
  {
    fs::remove_all("out_" + name);
    std::ofstream f(name + ".prm");
    f << "set Dimension = 2\n"
         "set Output directory = out_"
      << name
      << "\n"
         "set End time = 5\n"
         "set Time step = 0.5\n"
         "set Adaptive time step = true\n"
         "subsection Mesh\n"
         "  set Lower corner = 0, 0\n"
         "  set Upper corner = 1, 1\n"
         "  set Subdivisions = 1, 1\n"
         "  set Initial refinement = 3\n"
         "  set Boundary conditions = velocity, velocity, wall, velocity\n"
         "end\n"
         "subsection Fluid\n"
         "  set Density = 1000\n"
         "  set Viscosity = "
      << viscosity
      << "\n"
         "  subsection Boundary velocity\n"
         "    set Function expression = "
      << lid
      << "; 0\n"
         "  end\n"
         "end\n"
         "subsection Output\n"
         "  set Terminal output = quiet\n"
         "end\n";
    return std::string(IMMERSED_GRAINS_EXECUTABLE) + " " + name +
           ".prm > stdout_" + name + " 2> stderr_" + name;
  }
} // namespace

int
main()
{
  const int     status = std::system(cavity("exploding", 1e-4, 1).c_str());
  std::ifstream err("stderr_exploding");
  std::vector<std::string> lines;
  for (std::string line; std::getline(err, line);)
    lines.push_back(line);
  const std::string message = lines.empty() ? "" : lines[0];

  std::smatch found;
  const bool  parsed = std::regex_search(
    message,
    found,
    std::regex("step ([0-9]+) .*speed reached ([0-9.e+]+) m/s.*over 100 "
                "times the fastest motion the scene drives \\(([0-9.e+]+) m/s"));
  const double speed  = parsed ? std::stod(found[2]) : 0;
  const double driven = parsed ? std::stod(found[3]) : 0;
  char         pvtu[64];
  std::snprintf(pvtu,
                sizeof(pvtu),
                "out_exploding/fields_%05d.pvtu",
                parsed ? std::stoi(found[1]) : -1);
  std::cout << "exit status non-zero: " << (status != 0 ? "yes" : "no") << '\n'
            << "lines on stderr: " << lines.size() << '\n'
            << "names the step and the speeds: " << (parsed ? "yes" : "no")
            << '\n'
            << "driven speed is free fall across the box: "
            << (std::abs(driven - 4.43) < 0.01 ? "yes" : "no") << '\n'
            << "stopped at 100 to 110 times it (3 digits printed): "
            << (speed > 99.5 * driven && speed < 110 * driven ? "yes" : "no")
            << '\n'
            << "last output written: " << (fs::exists(pvtu) ? "yes" : "no")
            << '\n';
  if (lines.size() != 1)
    for (const auto &line : lines)
      std::cout << "  stderr: " << line << '\n';

  // Resolved: Re = 1000 * 1e-3 * 1 / 1e-3 = 1.
  const int calm = std::system(cavity("calm", 1e-3, 1e-3).c_str());
  std::cout << "resolved cavity runs to its end: " << (calm == 0 ? "yes" : "no")
            << '\n';
  return 0;
}
