"""backend="numba" against backend="numpy": µs per (replica-)step of the engine, and the default run (not a test).

Scenes: ``bench_step.build(N, seed)`` (frictional, crosslinked, plates on, sinusoidal shear; the
scene of docs/performance.md), stepped through ``BatchEngine.set_rate`` + ``step(cool, dt,
sample=True)`` on one ``BatchState`` of B replicas (seeds 1 … B), per backend.  Both engines are
built and warmed first (the compile, or the load from the cache, is not timed); then timed blocks
alternate NumPy / Numba / NumPy / … and the median of each backend's blocks is printed, with
their ratio.  One thread (``OMP_NUM_THREADS=1`` …).  The compiled backend runs each step in one
compiled call from the NumPy engine's own functions (engine/numba_step.py, docs/backends.md); the
candidate search and the Python of the loop around the step are the same on both.

"Numba, compiled blocks": the same steps through ``numba_step.run_block`` (many steps per compiled
call, the rate update, the records and the rebuilds of the candidate lists inside, as the
protocols' recording loop runs them).  ``--rebuilds-between`` adds, in the same alternation, the
compiled blocks with every rebuild between calls (``numba_step.REBUILD_IN_BLOCK = False``: the
rebuild of a replica's list by ``BatchEngine.neighbours``, a block call per list due; the same
bits) and its ratio to the rebuilds inside.  Rows of B = 32 and of N = 10,000 in compiled blocks
as long as the protocols' (``engine.rheometer.BLOCK`` steps, where the rows above take blocks of 40
and 10 so that NumPy's blocks stay short; the hand-back of a block's rebuilt lists is then shared
by more steps).  Then
the documented step loop of the README (what 1.0.2's scripts run, every tensor at every step) on
the N = 150 scene, its engine made on each backend, in alternating blocks.  Last rows: the default
run ``doParticleShearSimulation(seed=1)`` (no drawing), whole call with a warm
compile cache, per backend, without files and saving its files (``saveData=True`` into a temporary
folder: the per-step table of every stress tensor, so every step samples every tensor).

Then the protocol of the default run, the scene LAMMPS was matched on (:func:`matched_scene`): µs per
step of a single run and per replica-step of 32 runs in one batch.

Last: each target of issue 47 beside this run's figure, met or not (LAMMPS's figures and the
NumPy loop's factor over 1.0.2 are quoted from docs/performance.md and issue 47, not measured here).

Usage: python benchmarks/bench_compiled.py [--quick] [--rebuilds-between]
"""
import os

for _v in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ.setdefault(_v, "1")

import argparse  # noqa: E402
import contextlib  # noqa: E402
import io  # noqa: E402
import math  # noqa: E402
import statistics  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bench_step  # noqa: E402

from particleShear.base.engine_adapter import state_from_ensembles  # noqa: E402
from particleShear.engine import numba_step  # noqa: E402
from particleShear.engine.step import BatchEngine  # noqa: E402
from particleShear.run.batch import ENGINE_SKIN_FACTOR  # noqa: E402

BACKENDS = ("numpy", "numba", "numba blocks")
#: the compiled blocks with every rebuild between calls (``--rebuilds-between``)
BETWEEN = "numba blocks between"


def engine(ensembles, backend):
    """A BatchEngine of copies of ``ensembles`` on ``backend`` and its timed block function."""
    eng = BatchEngine(state_from_ensembles(ensembles, backend=backend.split()[0]), skin_factor=ENGINE_SKIN_FACTOR)
    s, B = eng.s, len(ensembles)
    w = 2 * math.pi * bench_step.F_EXC
    cool, dt, amp = 0.99969060716623, bench_step.DT, bench_step.AMPLITUDE

    def block(n):
        t0 = time.perf_counter()
        for _ in range(n):
            eng.set_rate(np.full(B, amp * w * math.cos(w * float(s.t[0]))))
            eng.step(cool, dt, sample=True)
        return time.perf_counter() - t0

    def compiled_block(n):
        # the same steps in compiled blocks (numba_step.run_block, as the protocols' recording loop runs them)
        t0 = time.perf_counter()
        start = float(s.t[0])
        rates = np.repeat((amp * w * np.cos(w * (start + dt * np.arange(n))))[:, None], B, axis=1)
        record = {name: np.empty((n, B)) for name in ("t", "strain", "strain_rate", "stress_internal",
                                                      "stress_surface")}
        inside = numba_step.REBUILD_IN_BLOCK
        numba_step.REBUILD_IN_BLOCK = backend != BETWEEN
        try:
            numba_step.run_block(eng, rates, cool, dt, record, 0)
        finally:
            numba_step.REBUILD_IN_BLOCK = inside
        return time.perf_counter() - t0
    return compiled_block if backend.startswith("numba blocks") else block


def row(N, B, steps, blocks, backends=BACKENDS):
    ensembles = [bench_step.build(N, seed=1 + b) for b in range(B)]
    run = {be: engine(ensembles, be) for be in backends}
    for be in backends:
        run[be](5)                       # warm-up: the compile (or the cache load) is not timed
    samples = {be: [] for be in backends}
    for _ in range(blocks):
        for be in backends:
            samples[be].append(run[be](steps) / (steps * B))
    return {be: statistics.median(v) for be, v in samples.items()}


def documented(backend):
    """The documented step loop of the README (``bench_step.documented_steps``: forces, totals, every
    tensor of ``StressTensorEvaluation`` over ``movableSphereList()``, acceleration, movement) on the
    N = 150 scene, its engine made on ``backend``; returns its timed block function."""
    from particleShear import StressTensorEvaluation
    before = os.environ.get("PARTICLESHEAR_BACKEND")
    os.environ["PARTICLESHEAR_BACKEND"] = backend      # (read when the ensemble's engine is made)
    try:
        ens = bench_step.build(150, seed=2)
        ev = StressTensorEvaluation(ens.size_x, ens.size_y)
        bench_step.documented_steps(ens, ev, 5)
    finally:
        if before is None:
            del os.environ["PARTICLESHEAR_BACKEND"]
        else:
            os.environ["PARTICLESHEAR_BACKEND"] = before
    return lambda n: sum(bench_step.documented_steps(ens, ev, n))


def default_run(backend, save=False):
    """Seconds of the whole default call; ``save``: with its files (every tensor sampled at every step)."""
    import tempfile

    from particleShear import doParticleShearSimulation
    with tempfile.TemporaryDirectory() as folder:
        t0 = time.perf_counter()
        with contextlib.redirect_stdout(io.StringIO()):
            doParticleShearSimulation(doDrawing=False, plotStress=False, saveData=save, seed=1, backend=backend,
                                      root_folder=folder + os.sep if save else "")
        return time.perf_counter() - t0


def matched_scene(batch=32):
    """The protocol of the default run on the compiled backend: the scene LAMMPS ``pair_style
    granular`` was matched on (docs/performance.md, 46–51 µs per step, one core).

    Returns µs per protocol step of a single run (the fastest of seeds 1–3, whole runs, their
    protocol's wall time) and µs per replica-step of ``batch`` default runs stepped as one batch
    (``doParticleShearSimulationSeries(batch_size=batch)``, one worker), as ``bench_batch.py``
    times them.  This scene rebuilds its lists about once per hundred steps; the bench scene of the
    rows above, sheared harder, about once per 17 (N = 150) and once per 5 (N = 10,000).
    """
    from particleShear import doParticleShearSimulation, doParticleShearSimulationSeries
    kw = dict(doDrawing=False, plotStress=False, backend="numba")
    with contextlib.redirect_stdout(io.StringIO()):
        single = [doParticleShearSimulation(seed=seed, verbose=False, return_result=True, **kw) for seed in (1, 2, 3)]
        series = doParticleShearSimulationSeries(N_repetitions=batch, batch_size=batch, executor=None, max_workers=1,
                                                 seed=1, **kw)
    one = min(r.timings["protocol"] / r.N_steps for r in single)
    many = sum(r.timings["protocol"] for r in series) / sum(r.N_steps for r in series)
    return 1e6 * one, 1e6 * many


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="fewer steps and blocks")
    ap.add_argument("--rebuilds-between", action="store_true",
                    help="also the compiled blocks with every list rebuild between calls (REBUILD_IN_BLOCK = False)")
    args = ap.parse_args()
    q, between = args.quick, args.rebuilds_between
    rows = [(150, 1, 100 if q else 400, 3 if q else 7, "µs/step"),
            (150, 32, 10 if q else 40, 3 if q else 5, "µs/replica-step"),
            (10_000, 1, 3 if q else 10, 3 if q else 5, "ns/particle-step")]
    extra = (" | Numba, blocks, rebuilds between calls | between / inside", "---|---|") if between else ("", "")
    print("| N | B | NumPy | Numba, a call per step | Numba, compiled blocks | NumPy / Numba per step | "
          f"NumPy / Numba blocks{extra[0]} | unit |\n|---|---|---|---|---|---|---|{extra[1]}---|", flush=True)
    got = {}          # the figures the targets of issue 47 are about
    for N, B, steps, blocks, unit in rows:
        m = row(N, B, steps, blocks, BACKENDS + ((BETWEEN,) if between else ()))
        scale = 1e9 / N if unit.startswith("ns") else 1e6
        got[N, B] = m["numba blocks"] * scale
        got["steps", N, B] = steps
        more = f" | {m[BETWEEN] * scale:.1f} | {m[BETWEEN] / m['numba blocks']:.2f}×" if between else ""
        print(f"| {N:,} | {B} | {m['numpy'] * scale:.1f} | {m['numba'] * scale:.1f} | {m['numba blocks'] * scale:.1f} | "
              f"{m['numpy'] / m['numba']:.2f}× | {m['numpy'] / m['numba blocks']:.2f}×{more} | {unit} |", flush=True)
    # B = 32 and N = 10,000 in blocks as long as the protocols' (engine.rheometer.BLOCK steps): the
    # hand-back of a block's rebuilt lists is shared by 6 and 25 times more steps than in the rows above
    from particleShear.engine.rheometer import BLOCK
    for N, B, unit in ((150, 32, "µs/replica-step"), (10_000, 1, "ns/particle-step")):
        m = row(N, B, 3 if q else BLOCK, 2 if q else 3, ("numba blocks",))
        got[N, B, "protocol"] = m["numba blocks"] * (1e9 / N if unit.startswith("ns") else 1e6)
        print(f"| {N:,} | {B} | | | {got[N, B, 'protocol']:.1f} (blocks of {3 if q else BLOCK} steps, as the "
              f"protocols run them) | | | {unit} |", flush=True)
    loops = {be: documented(be) for be in ("numpy", "numba")}
    samples = {be: [] for be in loops}
    for _ in range(3 if q else 7):
        for be, run in loops.items():
            samples[be].append(run(50 if q else 200) / (50 if q else 200))
    t = {be: statistics.median(v) for be, v in samples.items()}
    print(f"| documented step loop with every tensor (README), N = 150 | 1 | {t['numpy'] * 1e6:.1f} | | "
          f"{t['numba'] * 1e6:.1f} | | {t['numpy'] / t['numba']:.2f}× | µs/step |", flush=True)
    got["documented"] = t['numpy'] / t['numba']
    default_run("numba")                 # the cache warm (a first compile is not timed)
    t = {be: statistics.median(default_run(be) for _ in range(1 if q else 3)) for be in ("numpy", "numba")}
    print(f"| default run (seed 1), whole call | | {t['numpy']:.2f} | | {t['numba']:.2f} | | "
          f"{t['numpy'] / t['numba']:.2f}× | s |", flush=True)
    got["default run"] = t["numba"]
    got["matched", 1], got["matched", 32] = matched_scene()
    print(f"| the default run's protocol (the scene matched with LAMMPS), N = 150 | 1 | | | {got['matched', 1]:.1f} | "
          f"| | µs/step |\n| the default run's protocol, 32 runs as one batch | 32 | | | {got['matched', 32]:.1f} | | | "
          "µs/replica-step |")
    t = {be: statistics.median(default_run(be, save=True) for _ in range(1 if q else 3)) for be in ("numpy", "numba")}
    print(f"| default run saving its files (every tensor at every step), whole call | | {t['numpy']:.2f} | | "
          f"{t['numba']:.2f} | | {t['numpy'] / t['numba']:.2f}× | s |")
    targets(got)


#: LAMMPS ``pair_style granular`` on the matched scene, one core, µs per step at N = 150 and ns per
#: particle-step at N = 10,000 (docs/performance.md; issue 47 for N = 10,000): measured elsewhere, quoted here
LAMMPS = {150: (46.0, 76.0), 10_000: (750.0, 970.0)}
#: LAMMPS on the default run's protocol (the scene matched side by side, docs/performance.md), µs per step
LAMMPS_MATCHED = (46.0, 51.0)
#: the NumPy documented step loop against 1.0.2, measured with 1.0.2 (issue 47): the compiled loop's
#: factor is this times the NumPy / Numba ratio of this run
NUMPY_LOOP_OVER_REFERENCE = 196.0


def targets(got):
    """Print each target of issue 47 beside this run's figure and whether it is met."""
    lam = LAMMPS[150]
    rows = [("N = 150, B = 1, compiled blocks <= 25 µs per step", got[150, 1], got[150, 1] <= 25,
             f"{got[150, 1] / lam[1]:.2f}–{got[150, 1] / lam[0]:.2f}× LAMMPS (<= 0.5×)"),
            (f"N = 150, B = 32 <= 20 µs per replica-step (blocks of {got['steps', 150, 32]} steps)", got[150, 32],
             got[150, 32] <= 20, ""),
            ("N = 150, B = 32 <= 20 µs per replica-step (the protocols' blocks)", got[150, 32, "protocol"],
             got[150, 32, "protocol"] <= 20, ""),
            (f"N = 10,000 <= 200 ns per particle-step (blocks of {got['steps', 10_000, 1]} steps)", got[10_000, 1],
             got[10_000, 1] <= 200,
             f"{got[10_000, 1] / LAMMPS[10_000][1]:.2f}–{got[10_000, 1] / LAMMPS[10_000][0]:.2f}× LAMMPS (<= 0.3×)"),
            ("N = 10,000 <= 200 ns per particle-step (the protocols' blocks)", got[10_000, 1, "protocol"],
             got[10_000, 1, "protocol"] <= 200,
             f"{got[10_000, 1, 'protocol'] / LAMMPS[10_000][1]:.2f}–{got[10_000, 1, 'protocol'] / LAMMPS[10_000][0]:.2f}× "
             "LAMMPS (<= 0.3×)"),
            ("the matched scene (the default run's protocol), B = 1 <= 25 µs per step", got["matched", 1],
             got["matched", 1] <= 25, f"{got['matched', 1] / LAMMPS_MATCHED[1]:.2f}–"
             f"{got['matched', 1] / LAMMPS_MATCHED[0]:.2f}× LAMMPS on this scene (<= 0.5×)"),
            ("the matched scene, B = 32 <= 20 µs per replica-step", got["matched", 32], got["matched", 32] <= 20,
             f"{got['matched', 32] / LAMMPS_MATCHED[1]:.2f}–{got['matched', 32] / LAMMPS_MATCHED[0]:.2f}× LAMMPS"),
            ("default run <= 0.8 s, whole call", got["default run"], got["default run"] <= 0.8, ""),
            ("documented loop >= 300× 1.0.2", NUMPY_LOOP_OVER_REFERENCE * got["documented"],
             NUMPY_LOOP_OVER_REFERENCE * got["documented"] >= 300,
             f"{NUMPY_LOOP_OVER_REFERENCE:.0f}× (NumPy loop) × {got['documented']:.2f} (this run)")]
    print("\n| target | this run | met | note |\n|---|---|---|---|")
    for name, value, met, note in rows:
        print(f"| {name} | {value:.3g} | {'yes' if met else 'no'} | {note} |")


if __name__ == "__main__":
    main()
