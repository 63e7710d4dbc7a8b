#!/usr/bin/python3
"""A mutation fuzzer for the two input readers: the parameter file and the
grain file (Grains/Placement/Shape = file).

Each case takes a seed scene (every .prm under prm/, tests/ and
benchmarks/) and mutates it a few times: a value swapped for an extreme or
malformed one, a line dropped, doubled or truncated, random bytes put in,
or a 'subsection' or 'end' lost. A third of the cases also place their
grains from a mutated grain file. Each case then runs

    build/immersed-grains --check CASE.prm

with a time limit (20 s) and an address-space limit (8 GiB). The input
readers are deal.II's ParameterHandler and the project's own parsers.
--check runs them all, placement and size estimate included, and writes
nothing. A case passes if the run exits 0 (a valid scene) or 1 or 2 with
exactly one line on stderr starting "immersed-grains: error:". It fails
if it is killed by a signal, times out, prints more than one line to
stderr, prints a backtrace, or exits with any other status. Failing cases
are kept in benchmarks/results/fuzz/ with their stderr. Fix them, and add
the input to tests/bad_input.cc.

    scripts/fuzz_input.py [SECONDS] [SEED]      (defaults: 300, 1)

Not libFuzzer or AFL++: those need the library built with coverage
instrumentation (clang), a second full build of deal.II-heavy sources
that does not fit the CI budget. This one is blind to coverage and relies
on the breadth of the seed scenes instead.
"""
import glob
import os
import random
import resource
import shutil
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
EXECUTABLE = os.path.join(ROOT, "build", "immersed-grains")
WORK = os.path.join(ROOT, "benchmarks", "results", "fuzz")

VALUES = ["0", "-1", "1e308", "-1e308", "1e-308", "nan", "inf", "-inf", "",
          "x", "1,", ",", "1,2,3,4,5", "2147483648", "4294967296",
          "99999999999", "0.5", "1e6", "1e9", "true", "false", "auto",
          "0; 0", "1 2", "0/0", "1e-300", "3", "12", "-0", "1e3, 1e3, 1e3",
          "1e-9, 1e-9, 1e-9", "\t", "#", "=", "0, 0; 1, 1", "sin(x)"]


def mutate_line(line, rng):
    if "=" in line and rng.random() < 0.8:
        head, _ = line.split("=", 1)
        return head + "= " + rng.choice(VALUES)
    choice = rng.randrange(4)
    if choice == 0:
        return ""
    if choice == 1:
        return line[: rng.randrange(len(line) + 1)]
    if choice == 2:
        return line + "\n" + line
    return "".join(chr(rng.randrange(1, 256)) if rng.random() < 0.1 else c
                   for c in line)


def mutate(text, rng):
    lines = text.split("\n")
    for _ in range(rng.randint(1, 3)):
        if not lines:
            break
        i = rng.randrange(len(lines))
        lines[i] = mutate_line(lines[i], rng)
    return "\n".join(lines)


def grain_file(rng, dim):
    rows = []
    for _ in range(rng.randint(0, 6)):
        row = [str(rng.uniform(0, 1)) for _ in range(dim)]
        if rng.random() < 0.5:
            row.append(str(rng.uniform(0.001, 0.05)))
        rows.append(" ".join(row))
    text = "\n".join(rows)
    return mutate(text, rng) if rng.random() < 0.7 else text


def limit_memory():
    resource.setrlimit(resource.RLIMIT_AS, (8 << 30, 8 << 30))


def classify(status, stderr, timed_out):
    # Lines end at '\n' only (str.splitlines would also split at control
    # characters, which a message must not carry either).
    lines = [l for l in stderr.split("\n") if l.strip()]
    if any(ord(c) < 32 and c not in "\t" for l in lines for c in l):
        return "control characters on stderr"
    if timed_out:
        return "timeout"
    if status < 0:
        return "signal %d" % -status
    if status not in (0, 1, 2):
        return "exit status %d" % status
    if status == 0:
        return None
    if len(lines) != 1 or not lines[0].startswith("immersed-grains: error:"):
        return "%d lines on stderr" % len(lines)
    return None


def main():
    seconds = float(sys.argv[1]) if len(sys.argv) > 1 else 300
    rng = random.Random(int(sys.argv[2]) if len(sys.argv) > 2 else 1)
    seeds = sorted(glob.glob(os.path.join(ROOT, "prm", "*.prm")) +
                   glob.glob(os.path.join(ROOT, "tests", "*.prm")) +
                   glob.glob(os.path.join(ROOT, "benchmarks", "**", "*.prm"),
                             recursive=True))
    seeds = [s for s in seeds if "/results/" not in s]
    shutil.rmtree(WORK, ignore_errors=True)
    os.makedirs(WORK)
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1",
               OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    start, cases, failures = time.time(), 0, 0
    outcomes = {}
    while time.time() - start < seconds:
        seed = rng.choice(seeds)
        text = open(seed, errors="replace").read()
        dim = 3 if "Dimension = 3" in text else 2
        name = "case_%05d" % cases
        scene = os.path.join(WORK, name + ".prm")
        if rng.random() < 0.33:
            grains = os.path.join(WORK, name + ".grains")
            with open(grains, "w") as f:
                f.write(grain_file(rng, dim))
            text += ("\nsubsection Grains\n  set Enabled = true\n"
                     "  subsection Placement\n    set Shape = file\n"
                     "    set File = %s\n  end\nend\n" % grains)
        text = mutate(text, rng)
        with open(scene, "w", errors="replace") as f:
            f.write(text)
        timed_out = False
        try:
            p = subprocess.run([EXECUTABLE, "--check", scene], cwd=WORK,
                               capture_output=True, text=True, errors="replace",
                               timeout=20, preexec_fn=limit_memory, env=env)
            status, stderr = p.returncode, p.stderr
        except subprocess.TimeoutExpired as e:
            timed_out, status = True, 0
            stderr = (e.stderr or b"").decode(errors="replace")
        problem = classify(status, stderr, timed_out)
        cases += 1
        key = "timeout" if timed_out else "exit %d" % status
        outcomes[key] = outcomes.get(key, 0) + 1
        if problem:
            failures += 1
            with open(os.path.join(WORK, name + ".failure"), "w") as f:
                f.write(problem + "\n" + stderr)
            print("%s (from %s): %s: %s" % (name, os.path.relpath(seed, ROOT),
                  problem, stderr.strip().splitlines()[-1][:200]
                  if stderr.strip() else ""), flush=True)
        else:
            for ext in (".prm", ".grains"):
                if os.path.exists(os.path.join(WORK, name + ext)):
                    os.remove(os.path.join(WORK, name + ext))
    print("%d cases in %.0f s (%s), %d failing (kept in %s)"
          % (cases, time.time() - start,
             ", ".join("%s: %d" % kv for kv in sorted(outcomes.items())),
             failures, WORK))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
