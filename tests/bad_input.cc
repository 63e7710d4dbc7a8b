// Bad input must end with a non-zero exit status, exactly one line on stderr
// that names the file and the parameter (and the value where there is one),
// and no output directory. Each case below is a scene with one mistake, run
// by the executable's command line in a child process
// (command_line_in_child.h).
#include "command_line_in_child.h"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

struct Case
{
  std::string name;
  std::string body;      // the scene, without the output directory line
  std::string parameter; // what the message must name
  std::string value;     // and the offending value ("" if none)
};

int
main()
{
  const std::string good_mesh = R"(
subsection Mesh
  set Lower corner = 0, 0
  set Upper corner = 1, 1
  set Boundary conditions = wall, wall, wall, wall
end
)";
  // Meshes of tests/meshes, and a grain that makes a dry scene on them.
  const std::string meshes = std::string(IMMERSED_GRAINS_TEST_MESHES) + "/";
  const std::string dry_grain =
    "subsection Fluid\n set Enabled = false\nend\nsubsection Grains\n set "
    "Enabled = true\n set Radius = 0.05\n subsection Placement\n  set "
    "Shape = list\n  set Positions = 0.5, 0.1\n end\nend\n";
  // A dry fill of a box (r = 0.025 at solid fraction 0.3), its Grains
  // section left open for the size distribution.
  const std::string dry_fill =
    "subsection Fluid\n set Enabled = false\nend\nsubsection Grains\n set "
    "Enabled = true\n set Radius = 0.025\n subsection Placement\n  set "
    "Shape = box\n  set Center = 0.5, 0.5\n  set Size = 0.8, 0.8\n  set "
    "Solid fraction = 0.3\n end\n";
  const std::vector<Case> cases = {
    {"unknown_parameter",
     "set Dimension = 2\nset Viscosityy = 1\n",
     "Viscosityy",
     ""},
    {"unknown_subsection",
     "set Dimension = 2\nsubsection Fluidd\nend\n",
     "Fluidd",
     ""},
    {"malformed_number",
     "set Dimension = 2\nsubsection Fluid\n  set Viscosity = 1e-3x\nend\n",
     "Viscosity",
     "1e-3x"},
    {"negative_viscosity",
     "set Dimension = 2\nsubsection Fluid\n  set Viscosity = -1\nend\n",
     "Viscosity",
     "-1"},
    {"zero_density",
     "set Dimension = 2\nsubsection Fluid\n  set Density = 0\nend\n",
     "Density",
     "0"},
    {"fluid_fraction_above_one",
     "set Dimension = 2\nsubsection Fluid\n subsection Fluid fraction\n  set "
     "Function expression = 1.2\n end\nend\n",
     "Fluid fraction",
     "1.2"},
    {"fluid_fraction_zero",
     "set Dimension = 2\nsubsection Fluid\n subsection Fluid fraction\n  set "
     "Function expression = x - x\n end\nend\n",
     "Fluid fraction",
     "0"},
    {"inverted_corners",
     "set Dimension = 2\nsubsection Mesh\n  set Lower corner = 0, 1\n  set "
     "Upper corner = 1, 0\nend\n",
     "Upper corner",
     "1, 0"},
    {"wrong_corner_length",
     "set Dimension = 3\nsubsection Mesh\n  set Lower corner = 0, 0\nend\n",
     "Lower corner",
     "0, 0"},
    {"boundary_list_too_short",
     "set Dimension = 2\nsubsection Mesh\n  set Boundary conditions = wall, "
     "wall, wall\nend\n",
     "Boundary conditions",
     "wall, wall, wall"},
    {"unknown_boundary_type",
     "set Dimension = 2\nsubsection Mesh\n  set Boundary conditions = wall, "
     "wall, wall, sticky\nend\n",
     "Boundary conditions",
     "sticky"},
    {"unpaired_periodic",
     "set Dimension = 2\nsubsection Mesh\n  set Boundary conditions = "
     "periodic, wall, wall, wall\nend\n",
     "Boundary conditions",
     "periodic"},
    {"bad_dimension", "set Dimension = 4\n", "Dimension", "4"},
    {"negative_time_step",
     "set Dimension = 2\nset Time step = -0.1\n",
     "Time step",
     "-0.1"},
    {"bad_expression",
     "set Dimension = 2\nsubsection Fluid\n subsection Forcing\n  set Function "
     "expression = sin(; 0\n end\nend\n",
     "Forcing",
     ""},
    {"bad_selection",
     "set Dimension = 2\nsubsection Fluid\n  set Time scheme = BDF7\nend\n",
     "Time scheme",
     "BDF7"},
    {"grains_overlap",
     "set Dimension = 2\nsubsection Grains\n  set Enabled = true\n  set "
     "Radius = 0.1\n  subsection Placement\n    set Positions = 0.5, "
     "0.5; 0.6, 0.5\n  end\nend\n",
     "Positions",
     "0.5, 0.5; 0.6, 0.5"},
    // Beyond the overlap the contact solver leaves (Contacts/Overlap
    // tolerance, 1e-3 r): 2e-3 r.
    {"grains_overlap_beyond_tolerance",
     "set Dimension = 2\nsubsection Grains\n  set Enabled = true\n  set "
     "Radius = 0.1\n  subsection Placement\n    set Positions = 0.5, "
     "0.5; 0.6998, 0.5\n  end\nend\n",
     "Positions",
     "0.5, 0.5; 0.6998, 0.5"},
    {"grains_outside_domain",
     "set Dimension = 2\nsubsection Grains\n  set Enabled = true\n  set "
     "Radius = 0.1\n  subsection Placement\n    set Positions = 0.5, "
     "0.95\n  end\nend\n",
     "Positions",
     "0.5, 0.95"},
    {"grains_impossible_fraction",
     "set Dimension = 2\nsubsection Grains\n  set Enabled = true\n  set "
     "Radius = 0.02\n  subsection Placement\n    set Shape = box\n    "
     "set Size = 0.5\n    set Solid fraction = 0.95\n  end\nend\n",
     "Solid fraction",
     "0.95"},
    {"grains_unreachable_fraction",
     "set Dimension = 3\nsubsection Grains\n  set Enabled = true\n  set "
     "Radius = 0.05\n  subsection Placement\n    set Shape = box\n    "
     "set Size = 0.5\n    set Solid fraction = 0.6\n  end\nend\n",
     "Solid fraction",
     "0.6"},
    {"grains_fill_outside_domain",
     "set Dimension = 2\nsubsection Grains\n  set Enabled = true\n  set "
     "Radius = 0.02\n  subsection Placement\n    set Shape = box\n    "
     "set Size = 1.5, 0.5\n  end\nend\n",
     "Size",
     "1.5, 0.5"},
    {"grains_missing_file",
     "set Dimension = 2\nsubsection Grains\n  set Enabled = true\n  "
     "subsection Placement\n    set Shape = file\n    set File = "
     "no_such_grains.txt\n  end\nend\n",
     "File",
     "no_such_grains.txt"},
    {"grains_velocity_count",
     "set Dimension = 2\nsubsection Grains\n  set Enabled = true\n  set "
     "Radius = 0.1\n  subsection Placement\n    set Positions = 0.2, "
     "0.5; 0.5, 0.5; 0.8, 0.5\n    set Velocities = 1, 0; 2, 0\n  "
     "end\nend\n",
     "Velocities",
     "1, 0; 2, 0"},
    {"grains_lattice_too_many",
     "set Dimension = 2\nsubsection Grains\n  set Enabled = true\n  set "
     "Radius = 0.1\n  subsection Placement\n    set Shape = lattice\n  "
     "  set Size = 0.4\n    set Count = 5\n  end\nend\n",
     "Count",
     "5"},
    {"grains_negative_restitution",
     "set Dimension = 2\nsubsection Contacts\n  set Restitution = "
     "-0.5\nend\n",
     "Restitution",
     "-0.5"},
    {"rolling_friction_without_friction",
     "set Dimension = 2\nsubsection Contacts\n  set Rolling friction = "
     "0.1\nend\n",
     "Rolling friction",
     "0.1"},
    {"rolling_friction_with_apgd",
     "set Dimension = 2\nsubsection Contacts\n  set Friction = 0.5\n  set "
     "Solver = apgd\n  set Rolling friction = 0.2\nend\n",
     "Rolling friction",
     "0.2"},
    {"fixed_region_one_corner",
     "set Dimension = 2\nsubsection Grains\n  set Fixed region = 0, "
     "0\nend\n",
     "Fixed region",
     "0, 0"},
    {"fixed_region_not_a_number",
     "set Dimension = 2\nsubsection Grains\n  set Fixed region = 0, 0; "
     "1, 0.2y\nend\n",
     "Fixed region",
     "0, 0; 1, 0.2y"},
    {"fixed_region_wrong_dimension",
     "set Dimension = 2\nsubsection Grains\n  set Fixed region = 0, 0, "
     "0; 1, 1, 1\nend\n",
     "Fixed region",
     "0, 0, 0; 1, 1, 1"},
    {"fixed_region_inverted",
     "set Dimension = 2\nsubsection Grains\n  set Fixed region = 0, "
     "0.5; 1, 0.25\nend\n",
     "Fixed region",
     "0, 0.5; 1, 0.25"},
    {"fixed_region_with_fixed",
     "set Dimension = 2\nsubsection Grains\n  set Fixed = true\n  set "
     "Fixed region = 0, 0; 1, 0.25\nend\n",
     "Fixed region",
     "0, 0; 1, 0.25"},
    {"bad_test_check",
     "set Dimension = 2\nsubsection Output\n  set Test checks = "
     "kinetic_energy << 1\nend\n",
     "Test checks",
     "kinetic_energy << 1"},
    {"unknown_test_column",
     "set Dimension = 2\nsubsection Output\n  set Test columns = step, "
     "nonsense\nend\n",
     "Test columns",
     "nonsense"},
    {"pressure_drop_one_point",
     "set Dimension = 2\nsubsection Output\n  set Pressure drop points = "
     "0.5, 0.5\nend\n",
     "Pressure drop points",
     "0.5, 0.5"},
    {"pressure_drop_outside",
     "set Dimension = 2\nsubsection Output\n  set Pressure drop points = "
     "0.5, 0.5; 2, 0.5\nend\n",
     "Pressure drop points",
     "0.5, 0.5; 2, 0.5"},
    {"implicit_coupling_not_bool",
     "set Dimension = 2\nsubsection Coupling\n  set Implicit coupling = "
     "maybe\nend\n",
     "Implicit coupling",
     "maybe"},
    // 8^3 cells refined 3 times, Q2-Q1: 6.7 million DoFs, about 38
    // GiB; stopped by the memory estimate before anything is
    // allocated (any machine this suite runs on has less than 1 TiB:
    // refinement 5 asks for about 2.4 TiB).
    {"mesh_too_large",
     "set Dimension = 3\nsubsection Mesh\n  set Lower corner = 0, 0, 0\n  "
     "set Upper corner = 1, 1, 1\n  set Subdivisions = 8, 8, 8\n  set "
     "Initial refinement = 5\nend\n",
     "Initial refinement",
     "5"},
    // An adaptive mesh of 8^3 cells with grains all through it and
    // Max level 9: the band around them would hold some 3 million
    // cells of level 9 (about 500 GB), which the initial 512 cells do
    // not show; stopped by the adapted estimate, naming Max level.
    {"adaptive_mesh_too_large",
     "set Dimension = 3\nsubsection Mesh\n  set Lower corner = 0, 0, 0\n  "
     "set Upper corner = 1, 1, 1\n  set Subdivisions = 8, 8, 8\nend\n"
     "subsection Grains\n set Enabled = true\n set Radius = 1e-4\n"
     " subsection Placement\n  set Shape = box\n  set Center = 0.5, "
     "0.5, 0.5\n  set Size = 1\n  set Count = 20000\n end\nend\n"
     "subsection Adaptivity\n set Enabled = true\n set Min level = 0\n"
     " set Max level = 9\nend\n",
     "Max level",
     "9"},
    {"nonpositive_courant_number",
     "set Dimension = 2\nset Adaptive time step = true\nset Courant "
     "number = 0\n",
     "Courant number",
     "0"},
    {"adaptivity_levels_reversed",
     "set Dimension = 2\nsubsection Adaptivity\n set Enabled = true\n"
     " set Min level = 4\n set Max level = 3\nend\n",
     "Min level",
     "4"},
    {"adaptivity_every_steps_not_a_number",
     "set Dimension = 2\nsubsection Adaptivity\n set Every steps = "
     "often\nend\n",
     "Every steps",
     "often"},
    {"adaptivity_band_width_not_a_number",
     "set Dimension = 2\nsubsection Adaptivity\n set Band width = "
     "wide\nend\n",
     "Band width",
     "wide"},
    {"adaptivity_band_width_too_large",
     "set Dimension = 3\nsubsection Adaptivity\n set Band width = "
     "21\nend\n",
     "Band width",
     "21"},
    {"resume_without_checkpoint",
     "set Dimension = 2\nsubsection Checkpoint\n set Resume = true\nend\n",
     "Resume",
     "true"},
    {"adaptivity_without_fluid",
     "set Dimension = 2\nsubsection Fluid\n set Enabled = false\nend\n"
     "subsection Adaptivity\n set Enabled = true\nend\n",
     "Enabled",
     "true"},
    {"grain_weight_not_a_number",
     "set Dimension = 3\nsubsection Load balancing\n set Grain weight = "
     "heavy\nend\n",
     "Grain weight",
     "heavy"},
    {"cloud_analysis_without_grains",
     "set Dimension = 2\nsubsection Cloud analysis\n set Enabled = "
     "true\nend\n",
     "Enabled",
     "true"},
    {"several_centres_for_a_lattice",
     "set Dimension = 2\nsubsection Grains\n set Enabled = true\n set "
     "Radius = 0.01\n subsection Placement\n  set Shape = lattice\n"
     "  set Center = 0.3, 0.3; 0.7, 0.7\n  set Size = 0.2\n end\nend\n",
     "Center",
     "0.3, 0.3; 0.7, 0.7"},
    {"overlapping_clouds",
     "set Dimension = 2\nsubsection Grains\n set Enabled = true\n set "
     "Radius = 0.01\n subsection Placement\n  set Shape = ball\n"
     "  set Center = 0.4, 0.5; 0.5, 0.5\n  set Size = 0.2\n"
     "  set Solid fraction = 0.4\n end\nend\n",
     "Center",
     "0.4, 0.5; 0.5, 0.5"},
    // A placement for grains left off: an error, not a fluid-only run.
    {"grains_section_while_disabled",
     "set Dimension = 2\nsubsection Grains\n set Radius = 0.01\n"
     " subsection Placement\n  set Shape = ball\n  set Center = 0.5, "
     "0.5\n  set Size = 0.2\n end\nend\n",
     "Enabled",
     "Grains/Radius"},
    // Refused before a billion radii are drawn.
    {"count_beyond_memory",
     "set Dimension = 3\nsubsection Grains\n set Enabled = true\n set "
     "Radius = 1e-3\n subsection Placement\n  set Shape = box\n  set "
     "Center = 0.5, 0.5, 0.5\n  set Size = 1\n  set Count = "
     "1000000000\n end\nend\n",
     "Count",
     "1000000000"},
    // Found by scripts/fuzz_input.py: a damaged line quoted in the
    // message carried its control characters to the terminal.
    {"control_characters",
     "set Dimension = 2\n\x1e front\x1d garbled\n",
     "\\x1e",
     "\\x1d"},
    {"gmsh_without_file",
     "set Dimension = 2\nsubsection Mesh\n set Geometry = gmsh\nend\n",
     "File",
     ""},
    {"gmsh_missing_file",
     "set Dimension = 2\nsubsection Mesh\n set Geometry = gmsh\n set File "
     "= nowhere.msh\nend\n",
     "File",
     "nowhere.msh"},
    {"gmsh_not_a_mesh",
     "set Dimension = 2\nsubsection Mesh\n set Geometry = gmsh\n set File "
     "= " +
       meshes + "incline_2d.geo\nend\n",
     "File",
     "incline_2d.geo"},
    {"gmsh_triangles",
     "set Dimension = 2\nsubsection Mesh\n set Geometry = gmsh\n set File "
     "= " +
       meshes +
       "triangles_2d.msh\n set Boundary conditions = 1: "
       "wall\nend\n" +
       dry_grain,
     "File",
     "triangles_2d.msh"},
    {"gmsh_unnamed_boundary",
     "set Dimension = 2\nsubsection Mesh\n set Geometry = gmsh\n set File "
     "= " +
       meshes +
       "incline_2d.msh\n set Boundary conditions = 1: "
       "wall, 2: wall, 3: wall\nend\n" +
       dry_grain,
     "Boundary conditions",
     "boundary id 4"},
    {"gmsh_boundary_not_on_mesh",
     "set Dimension = 2\nsubsection Mesh\n set Geometry = gmsh\n set File "
     "= " +
       meshes +
       "incline_2d.msh\n set Boundary conditions = 1: "
       "wall, 2: wall, 3: wall, 4: wall, 9: open\nend\n" +
       dry_grain,
     "Boundary conditions",
     "boundary id 9"},
    {"gmsh_boundaries_by_face",
     "set Dimension = 2\nsubsection Mesh\n set Geometry = gmsh\n set File "
     "= " +
       meshes +
       "incline_2d.msh\n set Boundary conditions = wall, "
       "wall, wall, wall\nend\n" +
       dry_grain,
     "Boundary conditions",
     "wall, wall, wall, wall"},
    {"gmsh_periodic",
     "set Dimension = 2\nsubsection Mesh\n set Geometry = gmsh\n set File "
     "= " +
       meshes +
       "incline_2d.msh\n set Boundary conditions = 1: "
       "wall, 2: periodic, 3: wall, 4: periodic\nend\n" +
       dry_grain,
     "Boundary conditions",
     "periodic"},
    {"gmsh_periodic_without_partner",
     "set Dimension = 2\nsubsection Mesh\n set Geometry = gmsh\n set File "
     "= " +
       meshes +
       "periodic_square_2d.msh\n set Boundary conditions = 1: wall, 2: "
       "wall, 3: wall, 4: periodic\nend\n" +
       dry_grain,
     "Boundary conditions",
     "periodic boundary id 4"},
    {"gmsh_periodic_faces_not_matching",
     "set Dimension = 2\nsubsection Mesh\n set Geometry = gmsh\n set File "
     "= " +
       meshes +
       "periodic_mismatch_2d.msh\n set Boundary conditions = 1: periodic, "
       "2: periodic, 3: periodic, 4: periodic\nend\n" +
       dry_grain,
     "Boundary conditions",
     "do not match"},
    {"gmsh_manifold_off_its_curve",
     "set Dimension = 2\nsubsection Mesh\n set Geometry = gmsh\n set File = " +
       meshes +
       "incline_2d.msh\n set Boundary conditions = 1: wall, 2: wall, 3: "
       "wall, 4: wall\n set Manifolds = 1: cylinder 0, 0\nend\n" +
       dry_grain,
     "Manifolds",
     "not on one cylinder"},
    {"gmsh_manifold_unknown_shape",
     "set Dimension = 2\nsubsection Mesh\n set Geometry = gmsh\n set File = " +
       meshes +
       "incline_2d.msh\n set Boundary conditions = 1: wall, 2: wall, 3: "
       "wall, 4: wall\n set Manifolds = 1: cone 0, 0\nend\n" +
       dry_grain,
     "Manifolds",
     "cone"},
    {"box_with_manifolds",
     "set Dimension = 2\nsubsection Mesh\n set Manifolds = 0: sphere 0, "
     "0\nend\n",
     "Manifolds",
     "0: sphere 0, 0"},
    {"boundary_force_unknown_id",
     "set Dimension = 2\nsubsection Output\n set Boundary forces = 7\nend\n",
     "Boundary forces",
     "boundary id 7"},
    {"boundary_contact_force_open_id",
     "set Dimension = 2\nsubsection Mesh\n set Boundary conditions = wall, "
     "wall, wall, open\nend\nsubsection Output\n set Boundary contact "
     "forces = 2, 3\nend\n" +
       dry_grain,
     "Boundary contact forces",
     "grains do not meet it"},
    {"boundary_contact_force_without_grains",
     "set Dimension = 2\nsubsection Output\n set Boundary contact forces = "
     "2\nend\n",
     "Boundary contact forces",
     "needs grains with contacts"},
    {"boundary_flux_unknown_id",
     "set Dimension = 2\nsubsection Output\n set Boundary fluxes = 0, "
     "5\nend\n",
     "Boundary fluxes",
     "boundary id 5"},
    {"boundary_flux_without_fluid",
     "set Dimension = 2\nsubsection Output\n set Boundary fluxes = "
     "0\nend\n" +
       dry_grain,
     "Boundary fluxes",
     "needs the fluid"},
    {"size_classes_fractions_sum",
     "set Dimension = 2\n" + good_mesh + dry_fill +
       " set Size distribution = classes\n set Class radii = 0.02, "
       "0.04\n set Class fractions = 0.5, 0.4\nend\n",
     "Class fractions",
     "0.5, 0.4"},
    {"size_classes_without_fractions",
     "set Dimension = 2\n" + good_mesh + dry_fill +
       " set Size distribution = classes\n set Class radii = 0.02, "
       "0.04\nend\n",
     "Class fractions",
     "volume fractions"},
    {"size_classes_repeated_radius",
     "set Dimension = 2\n" + good_mesh + dry_fill +
       " set Size distribution = classes\n set Class radii = 0.02, "
       "0.02\n set Class fractions = 0.5, 0.5\nend\n",
     "Class radii",
     "0.02, 0.02"},
    {"size_uniform_spread_above_radius",
     "set Dimension = 2\n" + good_mesh + dry_fill +
       " set Size distribution = uniform\n set Radius spread = "
       "0.03\nend\n",
     "Radius spread",
     "0.03"},
    {"size_lognormal_spread_below_one",
     "set Dimension = 2\n" + good_mesh + dry_fill +
       " set Size distribution = lognormal\n set Radius spread = "
       "0.5\nend\n",
     "Radius spread",
     "0.5"},
    {"size_and_radius_distribution",
     "set Dimension = 2\n" + good_mesh + dry_fill +
       " set Size distribution = uniform\n set Radius spread = 0.01\n set "
       "Radius distribution = normal\nend\n",
     "Size distribution",
     "uniform"},
    {"probe_outside",
     "set Dimension = 2\nsubsection Output\n set Probes = far: 2, 2\nend\n",
     "Probes",
     "far"},
    {"probe_without_name",
     "set Dimension = 2\nsubsection Output\n set Probes = 0.5, 0.5\nend\n",
     "Probes",
     "0.5, 0.5"},
    {"probe_without_fluid",
     "set Dimension = 2\nsubsection Output\n set Probes = a: 0.5, "
     "0.5\nend\n" +
       dry_grain,
     "Probes",
     "needs the fluid"},
    {"inflow_bad_expression",
     "set Dimension = 2\nsubsection Fluid\n set Inflow velocity = 1; "
     "sin(\nend\n",
     "Inflow velocity",
     "sin("},
    {"gmsh_grain_outside",
     "set Dimension = 2\nsubsection Mesh\n set Geometry = gmsh\n set File "
     "= " +
       meshes +
       "incline_2d.msh\n set Boundary conditions = 1: "
       "wall, 2: wall, 3: wall, 4: wall\nend\nsubsection Fluid\n set "
       "Enabled = false\nend\nsubsection Grains\n set Enabled = true\n "
       "set Radius = 0.05\n subsection Placement\n  set Shape = list\n  "
       "set Positions = 1.5, 0.3\n end\nend\n",
     "Positions",
     "outside the mesh"},
    {"gmsh_grain_in_wall",
     "set Dimension = 2\nsubsection Mesh\n set Geometry = gmsh\n set File "
     "= " +
       meshes +
       "incline_2d.msh\n set Boundary conditions = 1: "
       "wall, 2: wall, 3: wall, 4: wall\nend\nsubsection Fluid\n set "
       "Enabled = false\nend\nsubsection Grains\n set Enabled = true\n "
       "set Radius = 0.05\n subsection Placement\n  set Shape = list\n  "
       "set Positions = 0.5, -0.27\n end\nend\n",
     "Positions",
     "overlaps a wall"},
    {"nothing_to_simulate",
     "set Dimension = 2\nsubsection Fluid\n set Enabled = false\nend\n",
     "Enabled",
     "nothing to simulate"},
  };

  // Each case runs the command line as a singleton MPI process; Open MPI
  // then starts a helper daemon unless told not to, which costs a fifth of a
  // case's time and nothing that the cases check.
  setenv("OMPI_MCA_ess_singleton_isolated", "1", 0);

  unsigned int failures = 0;
  for (const Case &c : cases)
  {
    const std::string prm    = c.name + ".prm";
    const std::string outdir = "out_" + c.name;
    fs::remove_all(outdir);
    {
      std::ofstream f(prm);
      f << c.body << "set Output directory = " << outdir << "\n";
      (void)good_mesh;
    }
    const int status =
      run_command_line_in_child({prm}, "stdout_" + c.name, "stderr_" + c.name);

    std::ifstream            err("stderr_" + c.name);
    std::vector<std::string> lines;
    for (std::string line; std::getline(err, line);)
      lines.push_back(line);
    const std::string message = lines.empty() ? "" : lines[0];

    std::vector<std::string> problems;
    if (status == 0)
      problems.push_back("exit status 0");
    if (lines.size() != 1)
      problems.push_back(std::to_string(lines.size()) + " lines on stderr");
    if (message.find(prm) == std::string::npos)
      problems.push_back("file not named");
    if (message.find(c.parameter) == std::string::npos)
      problems.push_back("parameter not named");
    if (!c.value.empty() && message.find(c.value) == std::string::npos)
      problems.push_back("value not named");
    if (fs::exists(outdir))
      problems.push_back("output directory written");

    std::cout << c.name << ": " << (problems.empty() ? "OK" : "FAILED");
    for (const auto &p : problems)
      std::cout << " [" << p << "]";
    std::cout << std::endl;
    if (!problems.empty())
    {
      std::cout << "    stderr: " << message << std::endl;
      ++failures;
    }
  }
  std::cout << failures << " of " << cases.size() << " cases failed"
            << std::endl;
  return failures == 0 ? 0 : 1;
}
