"""The engine's protocol step per replica-step at N = 150, for batches of B = 1, 8, 32 (and 128).

Prints, in one run, the µs per replica-step of ``BatchEngine.step(cool, dt, sample=True)`` (what
:func:`particleShear.engine.step.protocol` does every step: set γ̇, step, the two shear
stresses) on default-scene replicas, and the ratio of each batch size to B = 1.

How: 32 default scenes (seeds 1 … 32) are constituted and pre-equilibrated exactly as
``run_batch`` does; their state at the start of the protocol is copied, and batches of B = 1, 8,
32 are taken from it (B = 128: the 32 scenes four times, each copy with its own history arrays).
Each batch runs ``--steps`` protocol steps of the shear periods (γ̇ = A·2πf·cos(2πf t)),
after ``--warm`` untimed ones, in ``--blocks`` blocks; the median and the best block are printed.

``--baseline REV`` (a git revision of this repository, e.g. ``HEAD~3``) is the before/after
switch: the ``particleShear/engine`` package of that revision is extracted to a temporary folder
and its ``BatchEngine`` runs on copies of the same batches, in blocks alternating with the
current engine (so both see the same load of the machine); printed are both figures, their
ratio, and whether the two engines' trajectories stayed bit-identical.

Run it with ``OMP_NUM_THREADS=1``.  Usage: python benchmarks/bench_engine.py [--steps S]
[--blocks K] [--no-128] [--baseline REV]
"""
import argparse
import copy
import importlib
import os
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

import particleShear.engine.step as engine_step
from particleShear.engine.state import BatchState
from particleShear.engine.step import BatchEngine
from particleShear.run.batch import run_batch

#: the NumPy engine's figures (docs/performance.md); PARTICLESHEAR_BACKEND=numba times the compiled loop
os.environ.setdefault("PARTICLESHEAR_BACKEND", "numpy")


class _Captured(Exception):
    pass


def protocol_start(n_scenes):
    """State of ``n_scenes`` default scenes at the start of the protocol, and the protocol's
    (dt, f, amplitudes, cool)."""
    box = {}
    real = engine_step.protocol

    def capture(engine, dt, f, amplitudes, cool, *args, **kwargs):
        box["state"] = copy.deepcopy(engine.s)
        box["args"] = (dt, f, np.asarray(amplitudes, float), cool)
        raise _Captured

    engine_step.protocol = capture
    try:
        run_batch([dict(seed=s, doDrawing=False, plotStress=False, verbose=False) for s in range(1, n_scenes + 1)])
    except _Captured:
        pass
    finally:
        engine_step.protocol = real
    return box["state"], box["args"]


def subset(st, rows):
    """A new state of the replicas ``rows`` of ``st`` (repeats allowed), every array copied."""
    out = BatchState(len(rows), st.N)
    N = st.N
    for name in ("x", "y", "vx", "vy", "omega", "phi", "r", "m", "inertia", "fx", "fy", "torque"):
        a = getattr(st, name)
        getattr(out, name)[...] = np.concatenate([a[b * N:(b + 1) * N] for b in rows])
    for name in ("Lx", "Ly", "gamma", "rate", "t", "k", "nu", "k_t", "nu_t", "mu", "c", "prc", "prt", "keep"):
        getattr(out, name)[...] = getattr(st, name)[list(rows)]
    out.pairs = [st.pairs[b].copy() for b in rows]
    out.rng = [copy.deepcopy(st.rng[b]) for b in rows]
    out.applying_shear = st.applying_shear
    return out


def baseline_engine(rev, folder):
    """``BatchEngine`` of ``particleShear/engine`` at git revision ``rev``, imported as a separate package."""
    root = subprocess.run(["git", "rev-parse", "--show-toplevel"], capture_output=True, text=True, check=True,
                          cwd=os.path.dirname(os.path.abspath(__file__))).stdout.strip()
    pkg = os.path.join(folder, "engine_baseline")
    os.makedirs(pkg)
    names = subprocess.run(["git", "ls-tree", "--name-only", rev, "particleShear/engine/"], capture_output=True,
                           text=True, check=True, cwd=root).stdout.split()
    for name in names:
        if name.endswith(".py"):
            src = subprocess.run(["git", "show", f"{rev}:{name}"], capture_output=True, check=True, cwd=root).stdout
            with open(os.path.join(pkg, os.path.basename(name)), "wb") as fh:
                fh.write(src)
    sys.path.insert(0, folder)
    return importlib.import_module("engine_baseline.step").BatchEngine


def time_batches(states, engines, args, steps, warm, blocks):
    """µs per replica-step of each block of ``steps`` protocol steps, for each (state, engine class),
    the blocks of the engines alternating."""
    dt, f, A, cool = args
    w = 2 * np.pi * f
    runs = []
    for st, cls in zip(states, engines):
        engine = cls(st)
        engine.phase = "protocol"
        runs.append((st, engine))

    def run(st, engine, n):
        for _ in range(n):
            t = float(st.t[0])
            engine.set_rate(A * np.cos(w * t) * w)
            engine.step(cool, dt, sample=True)

    for st, engine in runs:
        run(st, engine, warm)
    out = [[] for _ in runs]
    for _ in range(blocks):
        for k, (st, engine) in enumerate(runs):
            t0 = time.perf_counter()
            run(st, engine, steps)
            out[k].append(1e6 * (time.perf_counter() - t0) / (steps * st.B))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=None, help="steps per block (default: about 1 s per block)")
    ap.add_argument("--warm", type=int, default=30)
    ap.add_argument("--blocks", type=int, default=3)
    ap.add_argument("--no-128", action="store_true", help="skip B = 128")
    ap.add_argument("--baseline", default=None, help="git revision whose engine runs alternately, for comparison")
    args = ap.parse_args()
    t0 = time.perf_counter()
    st, pargs = protocol_start(32)
    print(f"32 default scenes (N = {st.N}) constituted and pre-equilibrated in {time.perf_counter() - t0:.1f} s")
    with tempfile.TemporaryDirectory() as folder:
        engines = [BatchEngine] + ([baseline_engine(args.baseline, folder)] if args.baseline else [])
        sizes = [1, 8, 32] + ([] if args.no_128 else [128])
        ref = None
        for B in sizes:
            rows = [b % 32 for b in range(B)]
            steps = args.steps or max(50, int(4000 / B))
            dt, f, A, cool = pargs
            states = [subset(st, rows) for _ in engines]
            times = time_batches(states, engines, (dt, f, A[rows], cool), steps, args.warm, args.blocks)
            med = [statistics.median(u) for u in times]
            ref = ref or med[0]
            per = sum(len(p.i) for p in states[0].pairs) / B
            line = (f"B = {B:4d}: {med[0]:7.1f} us per replica-step (median of {args.blocks} blocks of {steps} steps; "
                    f"best {min(times[0]):.1f}), ~{per:.0f} candidates per replica, ratio to B = 1: {med[0] / ref:.3f}")
            if args.baseline:
                same = all(np.array_equal(getattr(states[0], n), getattr(states[1], n))
                           for n in ("x", "y", "vx", "vy", "omega", "phi"))
                line += (f"\n          {args.baseline}: {med[1]:7.1f} us (best {min(times[1]):.1f}); now / then = "
                         f"{med[0] / med[1]:.3f}; trajectories bit-identical: {same}")
            print(line, flush=True)


if __name__ == "__main__":
    main()
