#!/usr/bin/python3
"""Solves one step's frictionless contact problem far beyond the solver's
tolerance, to tell the solver's error from the grains' own motion.

The problem is written by a build with write_contact_problem.patch applied
(next to this script), at the first sweep of a run:

    git apply benchmarks/pile_at_rest/write_contact_problem.patch
    (cd build && make immersed-grains)
    IG_WRITE_CONTACT_PROBLEM=/tmp/pile build/immersed-grains SCENE.prm
    git apply -R benchmarks/pile_at_rest/write_contact_problem.patch
    benchmarks/pile_at_rest/reference_solve.py /tmp/pile [TOLERANCE] [MAX_ITERATIONS]

SCENE.prm is typically a resume of a long pile run (Checkpoint/Resume) with
an End time one step later, so that the problem is that of a settled bed.

The problem: impulses p >= 0 with contact velocities w = N p + q >= 0 and
p . w = 0, N = J M^-1 J^T (frictionless, walls of zero inverse mass). The
files hold each contact row (grains i, j, normal, target velocity,
1 / N_kk, warm-started impulse) and each grain's velocity after the warm
start and its inverse mass. It is solved by MPRGP (Dostal & Schoeberl,
Comput. Optim. Appl. 30, 2005: conjugate gradients on the free impulses,
projected expansion steps, proportioning steps) on the Jacobi-scaled
variables, to max_k |projected w_k| / N_kk <= TOLERANCE * max p (the
solver's own measure: the largest impulse change a Gauss-Seidel update
would make, relative to the largest impulse). It prints the residual
history and the grains' speeds for the warm start and the solution.

Needs python3-numpy. A 10,000-sphere bed takes about two minutes.
"""
import sys
import time

import numpy as np


def load(stem):
    rows = np.loadtxt(stem + ".rows", ndmin=2)
    grains = np.loadtxt(stem + ".grains", ndmin=2)
    return rows, grains


def main():
    stem = sys.argv[1]
    tolerance = float(sys.argv[2]) if len(sys.argv) > 2 else 1e-8
    max_iterations = int(sys.argv[3]) if len(sys.argv) > 3 else 20000
    rows, grains = load(stem)
    first = rows[:, 0].astype(int)
    second = rows[:, 1].astype(int)
    normal = rows[:, 2:5]
    target = rows[:, 5]
    inverse_w = rows[:, 6]
    p_start = rows[:, 7]
    u_start = grains[:, :3]
    inverse_mass = grains[:, 3]
    n_grains = int(np.count_nonzero(inverse_mass > 0))

    def velocity_change(p):
        dv = np.zeros_like(u_start)
        np.add.at(dv, second, (inverse_mass[second] * p)[:, None] * normal)
        np.add.at(dv, first, -(inverse_mass[first] * p)[:, None] * normal)
        return dv

    def contact_velocity(u):
        return np.einsum("kd,kd->k", u[second] - u[first], normal)

    def delassus(p):
        return contact_velocity(velocity_change(p))

    q = contact_velocity(u_start) - target - delassus(p_start)
    scale = np.sqrt(1.0 / inverse_w)  # x = sqrt(N_kk) p: unit diagonal

    def operator(x):
        return delassus(x / scale) / scale

    b = -q / scale

    def residual(x, g):
        p = x / scale
        w = g * scale
        projected = np.where(p > 0, w, np.minimum(w, 0.0))
        return np.max(np.abs(projected) * inverse_w) / max(p.max(), 1e-300)

    rng = np.random.default_rng(1)
    v = rng.random(len(b))
    for _ in range(30):
        v = operator(v)
        largest = np.linalg.norm(v)
        v /= largest
    step = 1.9 / largest

    def split(x, g):
        free = x > 0
        return (np.where(free, g, 0.0), np.where(free, 0.0, np.minimum(g, 0.0)),
                free)

    x = p_start * scale
    g = operator(x) - b
    phi, beta, free = split(x, g)
    direction = phi.copy()
    history = []
    start = time.time()
    iteration = 0
    while iteration < max_iterations:
        history.append(residual(x, g))
        if history[-1] <= tolerance:
            break
        reduced = np.where(free, np.minimum(x / step, phi), 0.0)
        if beta @ beta <= reduced @ phi:
            a_direction = operator(direction)
            curvature = direction @ a_direction
            cg_step = (g @ direction) / curvature
            with np.errstate(divide="ignore", invalid="ignore"):
                feasible = np.min(np.where(direction > 0, x / direction, np.inf))
            if cg_step <= feasible:
                x = x - cg_step * direction
                g = g - cg_step * a_direction
                phi, beta, free = split(x, g)
                direction = phi - (phi @ a_direction) / curvature * direction
            else:
                x = x - feasible * direction
                g = g - feasible * a_direction
                phi, beta, free = split(x, g)
                x = np.maximum(x - step * phi, 0.0)
                g = operator(x) - b
                phi, beta, free = split(x, g)
                direction = phi.copy()
        else:
            a_beta = operator(beta)
            x = x - (g @ beta) / (beta @ a_beta) * beta
            g = g - (g @ beta) / (beta @ a_beta) * a_beta
            phi, beta, free = split(x, g)
            direction = phi.copy()
        iteration += 1

    p = x / scale
    print("%d grains, %d contacts, %d with an impulse at the warm start, "
          "%d at the solution" % (n_grains, len(p), np.count_nonzero(p_start > 0),
                                  np.count_nonzero(p > 0)))
    print("MPRGP: %d iterations, residual %.3e -> %.3e, %.0f s"
          % (iteration, history[0], history[-1], time.time() - start))
    for k in (10, 100, 1000, 5000, 10000):
        if k < len(history):
            print("  after %5d iterations: residual %.3e" % (k, history[k]))
    u = u_start + velocity_change(p - p_start)
    for name, velocities in (("warm start", u_start), ("solution", u)):
        speed = np.linalg.norm(velocities[:n_grains], axis=1)
        print("%-10s: fastest grain %.3e m/s, %d grains above 1 mm/s, "
              "rms speed %.3e m/s"
              % (name, speed.max(), np.count_nonzero(speed > 1e-3),
                 np.sqrt(np.mean(speed ** 2))))
    print("largest change of a grain's velocity: %.3e m/s"
          % np.abs(u - u_start)[:n_grains].max())


if __name__ == "__main__":
    main()
