"""Single-run cost of the engine at large N against the documented classes, same ensemble, same run (not a test).

Two scenes (``--scene``):

* ``relaxed`` (default): the frictional crosslinked ensemble of ``bench_step.build(N)`` (random
  bimodal spheres, radius ratio 1.4, packing fraction 1.5, a short damped relaxation, all links
  permanent, a few cut lines, μ = 0.01, plates on, the default sphere size and dt) — the scene of
  the issue's figures (a lively one: with the runs' skin, 0.2 r_max, the engine rebuilds its list
  every ~10 steps);
* ``default``: the scene a run measures, built as ``doParticleShearSimulation`` builds it
  (``bench_scenes.build``: the builder's crosslinked particles, 5 cut lines, μ = 0.01,
  pre-equilibrated with plates; the constitution grows faster than N: ~10 s at N = 10,000).

The ensemble is copied into a ``BatchState`` of one replica (``state_from_ensembles``), whose
engine has the Verlet skin of a run's engine (``run.batch.ENGINE_SKIN_FACTOR``, 0.2 r_max), and
both advance the same start under sinusoidal shear, in alternating blocks (so a slow moment of a
shared machine hits both):

* engine: ``BatchEngine.set_rate`` + ``BatchEngine.step(cool, dt, sample=True)`` — what a run's
  protocol does each step (the two shear stresses recorded; stability guard on, as in a run);
* classes: ``setShearRate`` + forces + register totals + ``EvaluationHandler.record`` (the two
  shear stresses, no tensor history) + acceleration + movement + reset, the documented step loop
  (with the schedule of the scene's experiment for ``default``).

Prints µs per step and ns per particle-step (median over blocks of the block mean, so the
engine's neighbour rebuilds are included in their share), the engine's rebuild count, and the
ratio engine / classes.  Targets (issue 11): ≤ 0.6 µs per particle-step at N = 10,000, ≤ 1 µs at
N = 100,000.

``--crossover`` also prints the cost of one near-pair search of the engine, all-pairs against
the cell list, from N = 100 to 2,000 on packings of the same density (the basis of
``CELL_LIST_MIN_N``), and of ``near_pairs`` (what the classes' ``candidate_pairs`` and the engine call) on the same positions.

Run it with ``OMP_NUM_THREADS=1`` (set here by default).
Usage: python benchmarks/bench_engine_large.py [--scene relaxed|default] [--sizes 10000 100000] [--steps 300]
[--block 50] [--crossover]
"""
import os

for _v in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_v, "1")

import argparse  # noqa: E402
import math  # noqa: E402
import statistics  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from bench_scenes import build as build_default_scene  # noqa: E402
from bench_step import AMPLITUDE, DT, F_EXC, PHI, R_MODEL, build  # noqa: E402

from particleShear import StressTensorEvaluation  # noqa: E402
from particleShear.engine.neighbours import near_pairs, near_pairs_all, near_pairs_cells  # noqa: E402
from particleShear.base.engine_adapter import state_from_ensembles  # noqa: E402
from particleShear.engine.step import BatchEngine  # noqa: E402
from particleShear.run.batch import ENGINE_SKIN_FACTOR  # noqa: E402
from particleShear.simulation.evaluation import EvaluationHandler  # noqa: E402

#: the NumPy engine's figures (docs/performance.md); PARTICLESHEAR_BACKEND=numba times the compiled loop
os.environ.setdefault("PARTICLESHEAR_BACKEND", "numpy")

COOL = 0.99969060716623
W = 2 * math.pi * F_EXC


def engine_block(eng, n, amplitude=AMPLITUDE, f=F_EXC, dt=DT, cool=COOL):
    """n protocol steps of the engine; wall time (s)."""
    s = eng.s
    w = 2 * math.pi * f
    t0 = time.perf_counter()
    for _ in range(n):
        eng.set_rate(np.array([amplitude * w * math.cos(w * float(s.t[0]))]))
        eng.step(cool, dt, sample=True)
    return time.perf_counter() - t0


def classes_block(ens, ev, handler, n, amplitude=AMPLITUDE, w=W, cool=COOL, dt=DT):
    """n protocol steps of the documented classes; wall time (s)."""
    t0 = time.perf_counter()
    for _ in range(n):
        ens.setShearRate(amplitude * w * math.cos(w * ens.t))
        ens.mechanical_simulation_step_calculate_forces()
        ens.record_total_particle_forces()
        handler.record(ens, ev)
        ens.mechanical_simulation_step_calculate_acceleration(cool, dt)
        ens.mechanical_simulation_step_calculate_movement(dt)
        ens.reset_force()
    return time.perf_counter() - t0


def compare(n, steps, block, scene):
    t0 = time.perf_counter()
    if scene == "default":
        exp, ens, cool = build_default_scene(n, 1, 0.01, True, 5)
        run_engine = (lambda eng, k: engine_block(eng, k, exp.amplitude, exp.f, exp.dt, cool))
        shear = dict(amplitude=exp.amplitude, w=2 * math.pi * exp.f, cool=cool, dt=exp.dt)
    else:
        ens = build(n)
        run_engine = engine_block
        shear = {}
    ev = StressTensorEvaluation(ens.size_x, ens.size_y)
    handler = EvaluationHandler()
    handler.allocate(steps + 2 * block + 5, keep_tensor_history=False)
    run_classes = (lambda k: classes_block(ens, ev, handler, k, **shear))
    t_build = time.perf_counter() - t0
    eng = BatchEngine(state_from_ensembles([ens]), skin_factor=ENGINE_SKIN_FACTOR)   # as a run's engine
    run_engine(eng, 5)                 # warm-up (the first list build is not timed)
    run_classes(5)
    rebuilds0 = int(eng.s.contacts.rebuilds[0])
    te, tc = [], []
    for _ in range(max(1, steps // block)):
        te.append(run_engine(eng, block) / block)
        tc.append(run_classes(block) / block)
    e_us, c_us = statistics.median(te) * 1e6, statistics.median(tc) * 1e6
    pairs = len(eng.s.contacts.C.ai)
    print(f"{scene} N = {n:7d}: engine {e_us:10.1f} µs/step = {1e3 * e_us / n:6.0f} ns/particle-step "
          f"({int(eng.s.contacts.rebuilds[0]) - rebuilds0} rebuilds in {len(te) * block} steps, {pairs} candidates); "
          f"classes {c_us:10.1f} µs/step = {1e3 * c_us / n:6.0f} ns/particle-step; "
          f"engine/classes = {e_us / c_us:.2f}  [L = {ens.size_x:.0f} µm, build {t_build:.1f} s]", flush=True)
    return e_us / n, c_us / n


def crossover(sizes=(100, 150, 200, 300, 400, 600, 1000, 2000), repeat=7):
    rng = np.random.default_rng(5)
    print("one near-pair search (median of %d), packing fraction %.1f, skin ½ r_max, γ = 0.3:" % (repeat, PHI))
    for n in sizes:
        L = math.sqrt(n * math.pi * R_MODEL ** 2 / PHI)
        x, y = rng.uniform(0, L, n), rng.uniform(0, L, n)
        r = np.where(rng.random(n) < 0.5, R_MODEL * math.sqrt(1.4), R_MODEL / math.sqrt(1.4))
        skin = 0.5 * float(r.max())
        row = []
        for f in (lambda: near_pairs_all(x, y, r, L, L, 0.3 * L, skin),
                  lambda: near_pairs_cells(x, y, r, L, L, 0.3 * L, skin),
                  lambda: near_pairs(x, y, r, L, L, 0.3 * L, skin)):
            f()
            ts = []
            for _ in range(repeat):
                t0 = time.perf_counter()
                f()
                ts.append(time.perf_counter() - t0)
            row.append(statistics.median(ts) * 1e6)
        print(f"  N = {n:5d}: engine all-pairs {row[0]:9.0f} µs, engine cell list {row[1]:7.0f} µs, "
              f"near_pairs (both layers) {row[2]:7.0f} µs")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[10000, 100000])
    ap.add_argument("--steps", type=int, default=300, help="timed steps of each side per size")
    ap.add_argument("--block", type=int, default=50, help="steps per alternating block")
    ap.add_argument("--crossover", action="store_true", help="also time one near-pair search by N")
    ap.add_argument("--scene", choices=("relaxed", "default"), default="relaxed")
    args = ap.parse_args()
    print(f"particleShear engine vs classes at large N; numpy {np.__version__}, threads pinned to 1")
    if args.crossover:
        crossover()
    res = {n: compare(n, args.steps, args.block, args.scene) for n in args.sizes}
    for n, target in ((10000, 0.6), (100000, 1.0)):
        if n in res:
            ok = res[n][0] <= target
            print(f"target N = {n}: engine ≤ {target} µs/particle-step: {'met' if ok else 'MISSED'} "
                  f"({res[n][0]:.3f})")


if __name__ == "__main__":
    main()
