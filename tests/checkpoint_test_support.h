// What the tests that run whole scenes from a parameter text share (the
// checkpoint tests, adaptive_band_outrun_2d, fluidized_bed_3d, the column
// collapse tests, which run the ready scenes reduced). The
// checkpoint tests' scene: 81 discs (r = 12.5 um, 2400 kg/m^3) in a ball
// of 0.25 mm in glycerine, a 2 mm box, an adaptive mesh (levels 2-4,
// adapted every 3 steps) and contacts: every kind of state a checkpoint
// holds. Each test adds End time, the output directory and its Checkpoint
// subsection.
#ifndef immersed_grains_tests_checkpoint_test_support_h
#define immersed_grains_tests_checkpoint_test_support_h

#include <deal.II/base/mpi.h>
#include <deal.II/base/parameter_handler.h>

#include <immersed_grains/parameters.h>
#include <immersed_grains/simulation.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

inline const char *adaptive_cloud_scene = R"(set Dimension = 2
set Time step = 0.05
subsection Mesh
  set Lower corner = 0, 0
  set Upper corner = 2e-3, 2e-3
  set Subdivisions = 1, 1
  set Initial refinement = 4
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
subsection Coupling
  set Smoothing length = 5e-5
end
subsection Gravity
  set Vector = 0, -9.81
end
subsection Adaptivity
  set Enabled     = true
  set Min level   = 2
  set Max level   = 4
  set Every steps = 3
end
subsection Output
  set Terminal output = quiet
end
)";

// Writes @p text to @p file (rank 0 of MPI_COMM_WORLD) and runs it as a
// scene of dimension @p dim on @p comm; the ranks outside @p comm
// (MPI_COMM_NULL) only wait for the file.
template <int dim>
inline void
run_scene(const std::string &file,
          const std::string &text,
          MPI_Comm           comm = MPI_COMM_WORLD)
{
  if (dealii::Utilities::MPI::this_mpi_process(MPI_COMM_WORLD) == 0)
    std::ofstream(file) << text;
  MPI_Barrier(MPI_COMM_WORLD);
  if (comm == MPI_COMM_NULL)
    return;
  dealii::ParameterHandler prm;
  ImmersedGrains::Simulation<dim>::declare_parameters(prm);
  ImmersedGrains::parse_parameter_file(prm, file);
  ImmersedGrains::Simulation<dim> simulation(prm, file, comm);
  simulation.run();
}

// The text of the ready scene prm/@p name.prm, its packings/ paths made
// absolute, for a test to append its reductions to: a later `set` of an
// entry overrides the scene's, so the test runs the scene as it stands in
// all it does not reduce.
inline std::string
ready_scene_text(const std::string &name)
{
  const std::string prm =
    std::string(IMMERSED_GRAINS_TEST_DIRECTORY) + "/../prm/";
  std::ifstream in(prm + name + ".prm");
  AssertThrow(in, dealii::ExcMessage("cannot read " + prm + name + ".prm"));
  std::ostringstream text;
  text << in.rdbuf();
  std::string       scene    = text.str();
  const std::string relative = "= packings/";
  for (std::size_t at = scene.find(relative); at != std::string::npos;
       at             = scene.find(relative, at + 1))
    scene.replace(at, relative.size(), "= " + prm + "packings/");
  return scene + "\n";
}

inline void
run_2d_scene(const std::string &file,
             const std::string &text,
             MPI_Comm           comm = MPI_COMM_WORLD)
{
  run_scene<2>(file, text, comm);
}

// The largest relative difference between two runs' statistics rows (as
// read_csv_rows() gives them, header first), over every column but
// wall_time and the rows both have.
inline double
largest_statistics_difference(
  const std::vector<std::vector<std::string>> &straight,
  const std::vector<std::vector<std::string>> &resumed)
{
  double       largest = 0;
  unsigned int wall    = 0;
  for (unsigned int c = 0; c < straight[0].size(); ++c)
    if (straight[0][c] == "wall_time")
      wall = c;
  for (unsigned int r = 1; r < std::min(straight.size(), resumed.size()); ++r)
    for (unsigned int c = 0; c < straight[r].size(); ++c)
      if (c != wall)
      {
        const double a = std::stod(straight[r][c]);
        const double b = std::stod(resumed[r][c]);
        if (a != b)
          largest =
            std::max(largest,
                     std::abs(a - b) / std::max(std::abs(a), std::abs(b)));
      }
  return largest;
}

// The fields of every line of a CSV file (statistics.csv), header first.
inline std::vector<std::vector<std::string>>
read_csv_rows(const std::string &file)
{
  std::vector<std::vector<std::string>> rows;
  std::ifstream                         in(file);
  std::string                           line;
  while (std::getline(in, line))
  {
    std::vector<std::string> fields;
    std::istringstream       split(line);
    std::string              field;
    while (std::getline(split, field, ','))
      fields.push_back(field);
    rows.push_back(fields);
  }
  return rows;
}

// The index of the column @p name in statistics rows (header first).
inline unsigned int
column_index(const std::vector<std::vector<std::string>> &rows,
             const std::string                           &name)
{
  const auto at = std::find(rows[0].begin(), rows[0].end(), name);
  AssertThrow(at != rows[0].end(), dealii::ExcMessage("no column " + name));
  return at - rows[0].begin();
}

// The mean of @p value(row) over the statistics rows after time @p from,
// each weighted by its step (`dt`): a time average that the adaptive
// step does not bias towards the moments of short steps.
inline double
time_average(
  const std::vector<std::vector<std::string>>                   &rows,
  const double                                                   from,
  const std::function<double(const std::vector<std::string> &)> &value)
{
  const unsigned int t  = column_index(rows, "time"),
                     dt = column_index(rows, "dt");
  double integral = 0, duration = 0;
  for (unsigned int r = 1; r < rows.size(); ++r)
    if (std::stod(rows[r][t]) > from)
    {
      const double step = std::stod(rows[r][dt]);
      integral += value(rows[r]) * step;
      duration += step;
    }
  return integral / duration;
}

// The same for the column @p name.
inline double
time_average(const std::vector<std::vector<std::string>> &rows,
             const double                                 from,
             const std::string                           &name)
{
  const unsigned int c = column_index(rows, name);
  return time_average(rows,
                      from,
                      [c](const std::vector<std::string> &row)
                      { return std::stod(row[c]); });
}

#endif
