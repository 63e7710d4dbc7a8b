"""Runs a scene with the built executable for the benchmark drivers."""
import csv
import os
import subprocess
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


class RunFailed(RuntimeError):
    """A run that stopped with an error (which it printed itself)."""


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
        code = subprocess.run(command, env=env).returncode
    finally:
        os.unlink(prm.name)
    if code != 0:
        # The executable has said why in one line above.
        raise RunFailed("the run into %s stopped with exit code %d"
                        % (directory, code))
    return read_csv(os.path.join(directory, "statistics.csv"))


def ready_scene_text(name):
    """The text of prm/<name>.prm with its packings' paths made absolute,
    so that it runs from any directory; a study appends its changes (a later
    'set' overrides an earlier one)."""
    path = os.path.join(ROOT, "prm", name + ".prm")
    try:
        with open(path) as f:
            text = f.read()
    except OSError:
        raise SystemExit("cannot read the scene %s" % path)
    return text.replace("= packings/",
                        "= %s/" % os.path.join(ROOT, "prm", "packings"))


def end_time(prm_text):
    """The last top-level 'set End time' of a parameter text."""
    value = None
    for line in prm_text.splitlines():
        words = line.split("#")[0].split("=")
        if len(words) == 2 and words[0].split() == ["set", "End", "time"]:
            value = float(words[1])
    return value


def finished(directory, prm_text):
    """Whether the run of @p prm_text in @p directory reached its end time
    (a study runs again only what did not)."""
    path = os.path.join(directory, "statistics.csv")
    if not os.path.exists(path):
        return False
    rows = read_csv(path)
    return bool(rows) and float(rows[-1]["time"]) >= end_time(prm_text) - 1e-9
