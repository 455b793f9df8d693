"""Stress evaluation of the documented classes before/after a change of ``base/stress.py`` (not a test).

Loads ``particleShear/base/stress.py`` of a git revision (``--baseline``, default ``main``) next to
the working tree's and times, in one run and in alternating blocks on the same scenes:

* the evaluation alone on one force phase: ``ens.evaluate_stress_tensors(ev)`` (every tensor,
  what a step costs when tensors are saved) and ``ev.evaluate_shear_stresses`` (σ_xy only, what the
  experiment samples every other protocol step), on the N = 150 scene of ``bench_step.py``;
* the protocol step of ``bench_step.py`` (forces, totals, evaluation, acceleration, movement) with
  each evaluation;
* optionally (``--runs``) the default run on the classes' path, ``doParticleShearSimulation(
  doDrawing=True, renderer="none", plotStress=False)``, without and with the tensor table
  (``saveData=True, saveStressTensorData=True``), each revision once per repetition.

It also checks that both revisions give the same tensors to 1e-12 of the pressure scale and the
same shear stresses to 1e-12 relative on the measured phase.  The baseline's ``base/stress.py``
runs on this tree's engine, so it must use the engine's row-sum tensor registry
(``engine.stress.ROWS``); to compare whole trees use ``bench_phases.py``.

Usage: python benchmarks/bench_stress_facade.py [--baseline REV] [--blocks K] [--runs R]
"""
import os

for _v in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_v, "1")

import argparse  # noqa: E402
import importlib.util  # noqa: E402
import statistics  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

import particleShear.base.stress as new_stress  # noqa: E402
from bench_step import DT, build, protocol_steps  # noqa: E402

#: the NumPy engine's figures (docs/performance.md); PARTICLESHEAR_BACKEND=numba times the compiled loop
os.environ.setdefault("PARTICLESHEAR_BACKEND", "numpy")


def load_baseline(rev):
    """``particleShear.base.stress`` of git revision ``rev``, as module ``particleShear.base._stress_baseline``."""
    root = os.path.dirname(HERE)
    src = subprocess.run(["git", "-C", root, "show", f"{rev}:particleShear/base/stress.py"], check=True,
                         capture_output=True, text=True).stdout
    path = os.path.join(tempfile.mkdtemp(), "stress_baseline.py")
    with open(path, "w") as f:
        f.write(src)
    spec = importlib.util.spec_from_file_location("particleShear.base._stress_baseline", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def median_us(times):
    return statistics.median(times) * 1e6


def shear_only_steps(ens, ev, n_steps, cool=0.99969060716623):
    """``protocol_steps`` with the σ_xy-only evaluation the experiment samples."""
    import math
    from bench_step import AMPLITUDE, F_EXC
    times = []
    w = 2 * math.pi * F_EXC
    for _ in range(n_steps):
        t0 = time.perf_counter()
        ens.setShearRate(AMPLITUDE * w * math.cos(w * ens.t))
        ens.mechanical_simulation_step_calculate_forces()
        ens.record_total_particle_forces()
        ev.evaluate_shear_stresses(ens.force_register, ens._mobile_selection())
        ens.mechanical_simulation_step_calculate_acceleration(cool, DT)
        ens.mechanical_simulation_step_calculate_movement(DT)
        ens.reset_force()
        times.append(time.perf_counter() - t0)
    return times


def evaluation_alone(ens, evs, blocks, reps=200):
    """Median µs of each evaluation of each revision on one force phase, alternating blocks."""
    ens.mechanical_simulation_step_calculate_forces()
    ens.record_total_particle_forces()
    out = {}
    for _ in range(blocks):
        for name, ev in evs.items():
            for kind in ("full", "shear"):
                ts = []
                for _ in range(reps):
                    t0 = time.perf_counter()
                    if kind == "full":
                        ens.evaluate_stress_tensors(ev)
                    else:
                        ev.evaluate_shear_stresses(ens.force_register, ens._mobile_selection())
                    ts.append(time.perf_counter() - t0)
                out.setdefault((name, kind), []).extend(ts)
    return {k: median_us(v) for k, v in out.items()}


def agreement(ens, evs):
    ens.evaluate_stress_tensors(evs["baseline"])
    ens.evaluate_stress_tensors(evs["new"])
    a, b = evs["baseline"].tensors.copy(), evs["new"].tensors.copy()
    p = abs(a[0, 0, 0]) + abs(a[0, 1, 1])
    ta = evs["baseline"].evaluate_shear_stresses(ens.force_register, ens._mobile_selection())
    tb = evs["new"].evaluate_shear_stresses(ens.force_register, ens._mobile_selection())
    rel = max(abs(x - y) / abs(x) for x, y in zip(ta, tb))
    return float(np.max(np.abs(a - b)) / p), rel


def default_runs(classes, repeats):
    """Wall time (s) of the default run on the classes' path per revision, without and with the tensor table."""
    import particleShear.simulation.evaluation as evaluation
    import particleShear.simulation.experiment as experiment
    from particleShear import doParticleShearSimulation
    out = {}
    for r in range(repeats):
        for name, cls in classes.items():
            evaluation.StressTensorEvaluation = experiment.StressTensorEvaluation = cls
            for table in (False, True):
                with tempfile.TemporaryDirectory() as d:
                    t0 = time.perf_counter()
                    res = doParticleShearSimulation(d, doDrawing=True, renderer="none", plotStress=False,
                                                    saveData=table, saveStressTensorData=table, seed=1 + r,
                                                    verbose=False, return_result=True)
                    out.setdefault((name, table), []).append((time.perf_counter() - t0, res.G_internal[0]))
    evaluation.StressTensorEvaluation = experiment.StressTensorEvaluation = classes["new"]
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--baseline", default="main", help="git revision of the baseline base/stress.py")
    ap.add_argument("--blocks", type=int, default=6, help="alternating blocks per measurement")
    ap.add_argument("--runs", type=int, default=0, help="repetitions of the default run per revision (0: none)")
    args = ap.parse_args()
    old = load_baseline(args.baseline)
    classes = {"baseline": old.StressTensorEvaluation, "new": new_stress.StressTensorEvaluation}
    ens = build(150, seed=2)
    evs = {k: c(ens.size_x, ens.size_y) for k, c in classes.items()}
    for ev in evs.values():
        protocol_steps(ens, ev, 20)
    d_tensors, d_tau = agreement(ens, evs)
    print(f"N = 150 scene of bench_step.py; baseline = {args.baseline}; numpy {np.__version__}, threads pinned to 1")
    print(f"agreement on one force phase: tensors {d_tensors:.1e} of the pressure scale, shear stresses "
          f"{d_tau:.1e} relative")
    alone = evaluation_alone(ens, evs, args.blocks)
    for kind, label in (("full", "every tensor (ens.evaluate_stress_tensors)"),
                        ("shear", "σ_xy only (evaluate_shear_stresses)")):
        b, n = alone[("baseline", kind)], alone[("new", kind)]
        print(f"evaluation alone, {label:45s}: baseline {b:7.1f} µs, new {n:7.1f} µs ({n - b:+.1f} µs)")
    steps = {}
    for _ in range(args.blocks):
        for name, ev in evs.items():
            steps.setdefault((name, "shear"), []).extend(shear_only_steps(ens, ev, 100))
            steps.setdefault((name, "full"), []).extend(protocol_steps(ens, ev, 100))
    for kind, label in (("shear", "σ_xy only (the experiment's step)"), ("full", "every tensor (bench_step.py)")):
        b, n = median_us(steps[("baseline", kind)]), median_us(steps[("new", kind)])
        print(f"protocol step, N = 150, {label:36s}: baseline {b:7.1f} µs, new {n:7.1f} µs "
              f"({100 * (n / b - 1):+.1f} %)")
    if args.runs:
        runs = default_runs(classes, args.runs)
        for table in (False, True):
            b = [w for w, _ in runs[("baseline", table)]]
            n = [w for w, _ in runs[("new", table)]]
            g = [(gb, gn) for (_, gb), (_, gn) in zip(runs[("baseline", table)], runs[("new", table)])]
            print(f"default run, doDrawing=True, renderer='none', {'with' if table else 'without'} the tensor table: "
                  f"baseline {min(b):.2f} s, new {min(n):.2f} s (min of {len(b)}); G' baseline/new "
                  + ", ".join(f"{gb:.6f}/{gn:.6f}" for gb, gn in g))


if __name__ == "__main__":
    main()
