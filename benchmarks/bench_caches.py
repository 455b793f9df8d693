"""What each value kept in the canvas classes' memo buys per step, and the step against a baseline (not a test).

For every entry of the one cache mechanism (:class:`particleShear.base.memo.Memo`) the step is timed
with the entry disabled (its value recomputed at every ``get``) and enabled, in alternating blocks
in one process on the same scene; printed: the median µs per step of each state and the saving
(the median over block pairs of disabled − enabled, adjacent blocks seeing the same machine load)
in µs and as a fraction of the enabled step.  With ``--baseline REV`` the whole step of the working
tree is also timed against the step of git revision REV (its package loaded under another name)
on the same scene, alternating blocks: what the deleted caches cost together.

The memo holds the selection of the mobile spheres and the canvas's step engine
(docs/design.md, "The one cache"); only the selection is timed here: the engine also carries the
step's state from one phase to the next (the force phase's record that the acceleration and the
movement read, Verlet's half kick), so making it anew at every ``get`` would change the step, not
only its cost.

The step is what a run does: ``setShearRate``, the force phase, the register totals, the σ_xy-only
evaluation on every other step (what the experiment samples), the acceleration and the movement —
on the crosslinked, frictional, sheared scenes of ``bench_step.py`` at N = 150 and N = 10,000.

Usage: python benchmarks/bench_caches.py [--sizes 150,10000] [--blocks K] [--baseline REV]
"""
import os

for _v in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_v, "1")

import argparse  # noqa: E402
import importlib  # noqa: E402
import math  # noqa: E402
import statistics  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import tarfile  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

import bench_step  # noqa: E402
from bench_step import AMPLITUDE, DT, F_EXC, build  # noqa: E402

from particleShear import StressTensorEvaluation  # noqa: E402
from particleShear.base.memo import Memo  # noqa: E402

COOL = 0.99969060716623


def run_steps(ens, ev, n_steps):
    """Wall time (s) of each of n_steps run-like steps."""
    times = []
    w = 2 * math.pi * F_EXC
    for k in range(n_steps):
        t0 = time.perf_counter()
        ens.setShearRate(AMPLITUDE * w * math.cos(w * ens.t))
        ens.mechanical_simulation_step_calculate_forces()
        ens.record_total_particle_forces()
        if k % 2 == 0:
            ev.evaluate_shear_stresses(ens.force_register, ens._mobile_selection())
        ens.mechanical_simulation_step_calculate_acceleration(COOL, DT)
        ens.mechanical_simulation_step_calculate_movement(DT)
        times.append(time.perf_counter() - t0)
    return times


class BypassMemo(Memo):
    """A memo that recomputes the entries ``names`` (a ``+``-separated string) at every ``get``; an entry named
    ``NAME@phase`` is recomputed once per force phase instead (per geometry object ``canvas._g``)."""

    __slots__ = ("_bypass", "_per_phase", "_canvas", "_phase")

    def __init__(self, values, names, canvas=None):
        Memo.__init__(self)
        self._values.update(values)
        names = names.split("+")
        self._bypass = {n for n in names if not n.endswith("@phase")}
        self._per_phase = {n[:-len("@phase")] for n in names if n.endswith("@phase")}
        self._canvas = canvas
        self._phase = {}

    def get(self, name, key, compute):
        if name in self._bypass:
            return compute()
        if name in self._per_phase:
            g = self._canvas._g
            kept = self._phase.get(name)
            if kept is None or kept[0] is not g:
                kept = self._phase[name] = (g, compute())
            return kept[1]
        return Memo.get(self, name, key, compute)


ENTRIES = {
    "selection": "selection of the mobile spheres (the list)",
}


def measure(ens, ev, name, blocks, steps):
    """(disabled, enabled, saved) s per step: the medians over all steps of each state, and the median
    over block pairs of the difference of their block medians (adjacent blocks see the same load)."""
    off, on, saved = [], [], []
    for b in range(blocks):
        med = {}
        for state in ((0, 1) if b % 2 == 0 else (1, 0)):
            kept = ens._memo
            if state == 0:
                ens._memo = BypassMemo(kept._values, name, ens)
            t = run_steps(ens, ev, steps)
            if state == 0:
                kept._values.update(ens._memo._values)
                ens._memo = kept
            (off if state == 0 else on).extend(t)
            med[state] = statistics.median(t)
        saved.append(med[0] - med[1])
    return statistics.median(off), statistics.median(on), statistics.median(saved)


def baseline_package(rev):
    """The package ``particleShear`` of git revision ``rev``, imported as ``particleShear_baseline``."""
    root = os.path.dirname(HERE)
    tmp = tempfile.mkdtemp()
    archive = os.path.join(tmp, "rev.tar")
    subprocess.run(["git", "-C", root, "archive", "-o", archive, rev, "particleShear"], check=True)
    with tarfile.open(archive) as tf:
        tf.extractall(tmp)
    os.rename(os.path.join(tmp, "particleShear"), os.path.join(tmp, "particleShear_baseline"))
    sys.path.insert(0, tmp)
    return importlib.import_module("particleShear_baseline")


def build_with(pkg, n):
    """``bench_step.build(n)`` with the classes of package ``pkg`` (same seed, same scene)."""
    saved = bench_step.EnsembleLinkable, bench_step.SphereLinkable
    bench_step.EnsembleLinkable, bench_step.SphereLinkable = pkg.EnsembleLinkable, pkg.SphereLinkable
    try:
        return build(n)
    finally:
        bench_step.EnsembleLinkable, bench_step.SphereLinkable = saved


def against_baseline(pkg, n, blocks, steps):
    """Median s per step of (baseline, working tree) on the same scene, alternating blocks."""
    import particleShear
    scenes = {}
    for key, p in (("baseline", pkg), ("tree", particleShear)):
        ens = build_with(p, n)
        ev = p.StressTensorEvaluation(ens.size_x, ens.size_y)
        run_steps(ens, ev, 10)
        scenes[key] = (ens, ev)
    times = {"baseline": [], "tree": []}
    for b in range(blocks):
        for key in (("baseline", "tree") if b % 2 == 0 else ("tree", "baseline")):
            times[key] += run_steps(*scenes[key], steps)
    return statistics.median(times["baseline"]), statistics.median(times["tree"])


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", default="150,10000")
    ap.add_argument("--blocks", type=int, default=20)
    ap.add_argument("--entries", default="", help="comma-separated rows of the entry table to run (default: all)")
    ap.add_argument("--baseline", default=None, help="git revision whose whole step is timed against this tree's")
    args = ap.parse_args()
    pkg = baseline_package(args.baseline) if args.baseline else None
    for n in [int(s) for s in args.sizes.split(",")]:
        steps = 40 if n <= 1000 else 6
        ens = build(n)
        ev = StressTensorEvaluation(ens.size_x, ens.size_y)
        run_steps(ens, ev, 20)
        print(f"\nN = {n}: {args.blocks} alternating blocks of {steps} steps per state; median µs per step")
        print(f"{'memo entry':44s} {'what':52s} {'disabled':>9s} {'enabled':>9s} {'saved':>8s} {'saved %':>8s}")
        for name, what in ENTRIES.items():
            if args.entries and name not in args.entries.split(","):
                continue
            t_off, t_on, dt = measure(ens, ev, name, args.blocks, steps)
            print(f"{name:44s} {what:52s} {t_off * 1e6:9.1f} {t_on * 1e6:9.1f} {dt * 1e6:8.1f} "
                  f"{100 * dt / t_on:7.1f}%", flush=True)
        if pkg is not None:
            t_base, t_tree = against_baseline(pkg, n, args.blocks, steps)
            print(f"whole step: {args.baseline} {t_base * 1e6:.1f} µs, this tree {t_tree * 1e6:.1f} µs "
                  f"({100 * (t_tree - t_base) / t_base:+.1f} %; {t_tree / n * 1e6:.3f} µs per particle-step)",
                  flush=True)


if __name__ == "__main__":
    main()
