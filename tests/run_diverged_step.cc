// A step that diverges must stop the run with one line on stderr naming the
// step and what is not finite, a non-zero exit status, and a last output of
// the failed step to look at: no backtrace, no hang, no run that goes on
// with NaN. The scene's forcing turns to 0/0 from t = 4.5 ms on, so the
// fifth step's linear system holds NaN (the solver sees it first; the
// per-step finite check, source/divergence_guard.cc, backs it up for what no
// solver sees).
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

int
main()
{
  const std::string name = "diverged";
  fs::remove_all("out_" + name);
  {
    std::ofstream f(name + ".prm");
    f << "set Dimension = 2\n"
         "set Output directory = out_diverged\n"
         "set End time = 0.01\n"
         "set Time step = 0.001\n"
         "subsection Mesh\n"
         "  set Subdivisions = 4\n"
         "  set Initial refinement = 1\n"
         "end\n"
         "subsection Fluid\n"
         "  subsection Forcing\n"
         "    set Function expression = 0; if(t > 0.0045, 0/(x-x), 0)\n"
         "  end\n"
         "end\n"
         "subsection Output\n"
         "  set Terminal output = quiet\n"
         "end\n";
  }
  const std::string command = std::string(IMMERSED_GRAINS_EXECUTABLE) + " " +
                              name + ".prm > stdout_" + name + " 2> stderr_" +
                              name;
  const int status = std::system(command.c_str());

  std::ifstream            err("stderr_" + name);
  std::vector<std::string> lines;
  for (std::string line; std::getline(err, line);)
    lines.push_back(line);
  const std::string message = lines.empty() ? "" : lines[0];
  std::cout << "exit status non-zero: " << (status != 0 ? "yes" : "no") << '\n'
            << "lines on stderr: " << lines.size() << '\n'
            << "names the step: "
            << (message.find("step 5 ") != std::string::npos ? "yes" : "no")
            << '\n'
            << "says not finite: "
            << (message.find("not finite") != std::string::npos ? "yes" : "no")
            << '\n'
            << "last output written: "
            << (fs::exists("out_diverged/fields_00005.pvtu") ? "yes" : "no")
            << '\n';
  if (lines.size() != 1)
    for (const auto &line : lines)
      std::cout << "  stderr: " << line << '\n';
  return 0;
}
