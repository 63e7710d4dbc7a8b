// immersed-grains --check SCENE.prm: the scene is parsed, its grains placed
// and its size estimated, nothing is written, and the regime is printed with
// the choices that lie outside the validated range. The scene: 200 seed
// beads placed at random in a 3D box with cells of 2 grain diameters, in
// glycerine: the cell-spread drag without the self-disturbance correction
// (two warnings: grains feel their own disturbance there, and each cell's
// random share of grains drives a flow the closure holds already), the
// default coupling (Drag distribution = auto: the filtered drag over 8
// radii, none), a Stokes fluid and the filtered drag given (none), and the
// cell spread with the correction (a warning: the random share's flow;
// 2-10 % slow); the default coupling in a box walled all round (the cell
// spread with the correction, none: a layer between walls is not the
// suspension the filter was chosen on). In 2D with the
// default coupling (Drag distribution = auto): a ball of one disc (the
// cell spread, as for a cloud, and a warning: a lone disc settles several
// times too fast), a cloud of 160 discs (the cell spread, validated on 2D
// clouds: none), the same cloud given the filtered drag (a warning: the
// filter smooths the ball's collective flow) and 160 discs in a box (a
// suspension: the filtered drag with a filter half the box wide, none).
// Grains of two sizes (radii 1:2) under the default law (a warning: a law
// for one size), under Yin-Sundaresan (none), under van der
// Hoef-Beetstra (a warning: this dilute box lies below the solid fractions
// its correction was fitted at), and radii 1:5 under Yin-Sundaresan (a
// warning: fitted to diameter ratio 4). Packed beads read from a file, in
// the periodic box with the default coupling (a simple cubic stack of
// touching beads: the filtered drag over 8 radii, none).
//
// The report's figures in e-notation with a negative exponent (a grain's
// radius, terminal velocity, Reynolds number, ...; the stream writes
// two-digit exponents, the texts' own "1e-3" are left) are copied as
// "3.55 x 10^-06": numdiff compares with an absolute tolerance of 1e-6,
// which takes any two numbers closer than that as equal ("3.55e-06"
// against "4.18e-06" would pass); split, the digits are compared to 1e-8
// relative and the exponent exactly. Each check runs the executable's
// command line in a child process (command_line_in_child.h).
#include "command_line_in_child.h"

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <regex>
#include <string>

namespace fs = std::filesystem;

// The grains in a box 6e-4 m tall across a 3D domain periodic sideways
// (@p walled: a box of 6e-4 m in a domain walled all round), or in a ball
// of radius 3e-4 m in 2D (@p box_2d: a square of 6e-4 m); the domain a
// cube (square) of 8e-4 m in cells of 2 grain diameters.
void
check(const std::string &name,
      const std::string &coupling,
      const bool         stokes,
      const unsigned int count     = 200,
      const unsigned int dim       = 3,
      const bool         box_2d    = false,
      const std::string &grains    = "",
      const bool         walled    = false,
      const std::string &placement = "")
{
  fs::remove_all("out_" + name);
  {
    std::ofstream f(name + ".prm");
    f << "set Dimension = " << dim
      << "\n"
         "set Output directory = out_"
      << name
      << "\n"
         "set Time step = 1e-3\n"
         "subsection Mesh\n"
         "  set Upper corner = "
      << (dim == 3 ? "8e-4, 8e-4, 8e-4" : "8e-4, 8e-4")
      << "\n"
         "  set Subdivisions = 16\n"
         "  set Initial refinement = 0\n"
      << (dim == 3 && !walled ? "  set Boundary conditions = periodic, "
                                "periodic, periodic, periodic, wall, wall\n" :
                                "")
      << "end\n"
         "subsection Fluid\n"
         "  set Density = 1200\n"
         "  set Viscosity = 0.12\n"
      << (stokes ? "  set Advection = false\n" : "")
      << "end\n"
         "subsection Coupling\n"
      << coupling
      << "end\n"
         "subsection Grains\n"
         "  set Enabled = true\n"
         "  set Radius = 12.5e-6\n"
         "  set Density = 2400\n"
      << grains << "  subsection Placement\n"
      << (!placement.empty() ? placement :
          dim == 3           ? std::string("    set Shape = box\n"
                                           "    set Center = 4e-4, 4e-4, 4e-4\n") +
                       (walled ? "    set Size = 6e-4\n" :
                                 "    set Size = 8e-4, 8e-4, 6e-4\n") :
                     std::string(box_2d ? "    set Shape = box\n"
                                          "    set Center = 4e-4, 4e-4\n"
                                          "    set Size = 6e-4\n" :
                                          "    set Shape = ball\n"
                                          "    set Center = 4e-4, 4e-4\n"
                                          "    set Size = 3e-4\n"))
      << (placement.empty() ?
            "    set Count = " + std::to_string(count) + "\n" :
            "")
      << "  end\n"
         "end\n"
         "subsection Gravity\n"
         "  set Vector = "
      << (dim == 3 ? "0, 0, -9.81" : "0, -9.81")
      << "\n"
         "end\n";
  }
  const int status = run_command_line_in_child({"--check", name + ".prm"},
                                               "stdout_" + name,
                                               "stdout_" + name);
  std::cout << name << ": exit status " << (status == 0 ? "0" : "non-zero")
            << ", output directory "
            << (fs::exists("out_" + name) ? "written" : "absent") << '\n';
  std::ifstream    out("stdout_" + name);
  const std::regex small("([0-9.]+)e(-[0-9][0-9]+)");
  for (std::string line; std::getline(out, line);)
    std::cout << std::regex_replace(line, small, "$1 x 10^$2") << '\n';
}

int
main()
{
  // Each check runs the command line as a singleton MPI process; Open MPI
  // then starts a helper daemon unless told not to, which costs a fifth of a
  // check's time and nothing that the checks look at.
  setenv("OMPI_MCA_ess_singleton_isolated", "1", 0);
  check("cell_spread",
        "  set Drag distribution = cell\n"
        "  set Self-disturbance correction = false\n",
        false);
  check("default", "", false);
  check("filtered",
        "  set Drag distribution = filtered\n"
        "  set Smoothing length = 1e-4\n",
        true);
  check("cell_corrected", "  set Drag distribution = cell\n", false);
  check("walled", "", false, 200, 3, false, "", true);
  check("disc_2d", "", false, 1, 2);
  // A 2D cloud at area fraction 0.28: 160 of the discs' area over the
  // ball's.
  check("cloud_2d", "", false, 160, 2);
  check("cloud_2d_filtered",
        "  set Drag distribution = filtered\n"
        "  set Smoothing length = 1e-4\n",
        false,
        160,
        2);
  check("suspension_2d", "", false, 160, 2, true);
  const std::string two_sizes       = "  set Size distribution = classes\n"
                                      "  set Class fractions = 0.5, 0.5\n";
  const std::string stokes_filtered = "  set Drag distribution = filtered\n"
                                      "  set Smoothing length = 2e-4\n";
  check("two_sizes",
        stokes_filtered,
        true,
        200,
        3,
        false,
        two_sizes + "  set Class radii = 12.5e-6, 25e-6\n");
  check("two_sizes_yin_sundaresan",
        stokes_filtered + "  set Drag law = Yin-Sundaresan\n",
        true,
        200,
        3,
        false,
        two_sizes + "  set Class radii = 12.5e-6, 25e-6\n");
  check("two_sizes_van_der_hoef",
        stokes_filtered + "  set Drag law = van der Hoef-Beetstra\n",
        true,
        200,
        3,
        false,
        two_sizes + "  set Class radii = 12.5e-6, 25e-6\n");
  check("sizes_1_to_5_yin_sundaresan",
        stokes_filtered + "  set Drag law = Yin-Sundaresan\n",
        true,
        200,
        3,
        false,
        two_sizes + "  set Class radii = 12.5e-6, 62.5e-6\n");
  {
    // 8 x 8 x 4 beads, each touching its neighbours along the axes.
    std::ofstream f("packed_3d.txt");
    f.precision(17);
    for (unsigned int k = 0; k < 4; ++k)
      for (unsigned int j = 0; j < 8; ++j)
        for (unsigned int i = 0; i < 8; ++i)
          f << 3e-4 + 25e-6 * i << ' ' << 3e-4 + 25e-6 * j << ' '
            << 12.5e-6 + 25e-6 * k << " 12.5e-6\n";
  }
  check("packed_3d",
        "",
        false,
        0,
        3,
        false,
        "",
        false,
        "    set Shape = file\n"
        "    set File = packed_3d.txt\n");
}
