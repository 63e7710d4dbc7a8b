"""Runs a scene with the built executable for the benchmark drivers."""
import csv
import os
import subprocess
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def read_csv(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def run_scene(prm_text, directory, ranks=1):
    """Runs the parameter text quietly into @p directory (one thread per
    rank, Open MPI allowed as root) and returns its statistics rows."""
    with tempfile.NamedTemporaryFile("w", suffix=".prm", delete=False) as prm:
        prm.write(prm_text)
        prm.write("\nset Output directory = %s\n" % directory)
        prm.write("subsection Output\n  set Terminal output = quiet\nend\n")
    # IMMERSED_GRAINS_BUILD: another build directory, to compare two builds.
    build = os.environ.get("IMMERSED_GRAINS_BUILD", os.path.join(ROOT, "build"))
    command = [os.path.join(build, "immersed-grains"), prm.name]
    if ranks > 1:
        command = ["mpirun", "-np", str(ranks)] + command
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1",
               OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               OMPI_MCA_rmaps_base_oversubscribe="1",
               DEAL_II_NUM_THREADS="1", OMP_NUM_THREADS="1")
    try:
        subprocess.run(command, check=True, env=env)
    finally:
        os.unlink(prm.name)
    return read_csv(os.path.join(directory, "statistics.csv"))
