"""Where the documented step loop spends its time, phase by phase, for one or more trees (not a test).

The loop of README.md ("Scripts of particleShear 1.0.2 …") on the ``bench_step.build(150, seed=2)``
scene: ``setShearRate``, ``mechanical_simulation_step_calculate_forces``,
``record_total_particle_forces``, ``ev.evaluate_stress_tensors(ens.force_register,
ens.movableSphereList(), ens.shear_rate)`` (every tensor), acceleration, movement.  Each call is
timed on its own; the figure of a phase is the first quartile of its block means (30 blocks of 20
steps after 100 warm-up steps), so the steps that rebuild the neighbour lists are included.  Each
tree runs in its own process (the tree first on ``sys.path``, one thread, pinned to one CPU where
``taskset`` exists); compare trees within one run of the script.

For comparison it also times the engine's own step without the documented view around it:
``BatchEngine.step(cool, dt, sample=…)`` on a copy of the same scene (``state_from_ensembles``,
plates on), with no stresses, the two shear stresses and every tensor (``sample=False``, ``True``,
``"tensors"``), the same statistics; "n/a" (and the error) where the tree's engine cannot.

Usage: python benchmarks/bench_phases.py [TREE ...]   (default: this tree)
"""
import json
import os
import shutil
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
#: the NumPy engine's figures (docs/performance.md; the workers inherit it); PARTICLESHEAR_BACKEND=numba times
#: the compiled loop
os.environ.setdefault("PARTICLESHEAR_BACKEND", "numpy")
PHASES = ("rate", "forces", "totals", "tensors", "acceleration", "movement")
#: the engine's own step on a copy of the scene: (row label, ``sample``)
ENGINE = (("engine step alone, no stresses", False), ("engine step alone, shear stresses", True),
          ("engine step alone, every tensor", "tensors"))

WORKER = r'''
import json, math, sys, time
tree = sys.argv[1]
sys.path[:0] = [tree, sys.argv[2]]
import particleShear
assert particleShear.__file__.startswith(tree), particleShear.__file__
import bench_step
from particleShear import StressTensorEvaluation
ens = bench_step.build(150, seed=2)
ev = StressTensorEvaluation(ens.size_x, ens.size_y)
bench_step.documented_steps(ens, ev, 100)
w, cool, dt = 2 * math.pi * bench_step.F_EXC, 0.99969060716623, bench_step.DT
names, engine_rows = json.loads(sys.argv[3])
means = {n: [] for n in names}
for _ in range(30):
    acc = dict.fromkeys(names, 0.0)
    for _ in range(20):
        t = [time.perf_counter()]
        ens.setShearRate(bench_step.AMPLITUDE * w * math.cos(w * ens.t)); t.append(time.perf_counter())
        ens.mechanical_simulation_step_calculate_forces(); t.append(time.perf_counter())
        ens.record_total_particle_forces(); t.append(time.perf_counter())
        ev.evaluate_stress_tensors(ens.force_register, ens.movableSphereList(), ens.shear_rate); t.append(time.perf_counter())
        ens.mechanical_simulation_step_calculate_acceleration(cool, dt); t.append(time.perf_counter())
        ens.mechanical_simulation_step_calculate_movement(dt); t.append(time.perf_counter())
        for k, n in enumerate(names):
            acc[n] += t[k + 1] - t[k]
    for n in names:
        means[n].append(acc[n] / 20 * 1e6)
out = {n: sorted(v)[len(v) // 4] for n, v in means.items()}
try:
    import numpy as np
    from particleShear.engine.state import BatchState
    from particleShear.base.engine_adapter import state_from_ensembles
    from particleShear.engine.step import BatchEngine
    eng = BatchEngine(state_from_ensembles([bench_step.build(150, seed=2)]), guard=False)
    eng.s.applying_shear = True
    for label, sample in engine_rows:
        eng.step(cool, dt, sample=sample)           # (raises where the tree's engine lacks the mode)
    blocks = {label: [] for label, _ in engine_rows}
    for _ in range(30):
        for label, sample in engine_rows:
            t0 = time.perf_counter()
            for _ in range(20):
                eng.set_rate(np.array([bench_step.AMPLITUDE * w * math.cos(w * float(eng.s.t[0]))]))
                eng.step(cool, dt, sample=sample)
            blocks[label].append((time.perf_counter() - t0) / 20 * 1e6)
    out.update({label: sorted(v)[len(v) // 4] for label, v in blocks.items()})
except Exception as exc:      # a tree whose engine lacks a mode: its rows print n/a, with the reason
    out["engine"] = repr(exc)
print(json.dumps(out))
'''


def main():
    trees = [os.path.abspath(t) for t in sys.argv[1:]] or [os.path.dirname(HERE)]
    env = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1", MKL_NUM_THREADS="1")
    pin = ["taskset", "-c", "0"] if shutil.which("taskset") else []
    rows = {}
    for tree in trees:
        p = subprocess.run(pin + [sys.executable, "-c", WORKER, tree, HERE, json.dumps([PHASES, ENGINE])],
                           capture_output=True, text=True, env=env)
        if p.returncode:
            sys.exit(f"{tree}: {p.stderr[-2000:]}")
        rows[tree] = json.loads(p.stdout.strip().splitlines()[-1])
    print("documented step loop, N = 150, µs per step by phase (first quartile of 30 block means of 20 steps)")
    print("| phase | " + " | ".join(trees) + " |")
    print("|---|" + "---|" * len(trees))
    for n in PHASES + ("sum",):
        print(f"| {n} | " + " | ".join(f"{(sum(rows[t][p] for p in PHASES) if n == 'sum' else rows[t][n]):.1f}"
                                      for t in trees) + " |")
    for label, _ in ENGINE:
        print(f"| {label} | " + " | ".join(f"{rows[t][label]:.1f}" if label in rows[t] else "n/a" for t in trees) + " |")
    for t in trees:
        if "engine" in rows[t]:
            print(f"{t}: the engine's own step not timed: {rows[t]['engine']}")


if __name__ == "__main__":
    main()
