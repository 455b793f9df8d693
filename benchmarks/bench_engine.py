"""The engine's protocol step per replica-step at N = 150, for batches of B = 1, 8, 32 (and 128).

Prints, in one run, the µs per replica-step of ``BatchEngine.step(cool, dt, sample=True)`` (what
:func:`particleShear.engine.step.protocol` does every step: set γ̇, step, the two shear
stresses) on default-scene replicas, and the ratio of each batch size to B = 1.

How: 32 default scenes (seeds 1 … 32) are constituted and pre-equilibrated exactly as
``run_batch`` does; their state at the start of the protocol is copied, and batches of B = 1, 8,
32 are taken from it (B = 128: the 32 scenes four times, each copy with its own history arrays).
Each batch runs ``--steps`` protocol steps of the shear periods (γ̇ = A·2πf·cos(2πf t)),
after ``--warm`` untimed ones, in ``--blocks`` blocks; the median and the best block are printed.

``--without-speedups`` runs the engine with the step's optional shortcuts switched off
(``BatchEngine.fast = False``: the tangential kernel on scenes with no friction and no bonds,
the reuse of image period counts), for the before/after comparison.

Run it with ``OMP_NUM_THREADS=1``.  Usage: python benchmarks/bench_engine.py [--steps S]
[--blocks K] [--no-128] [--without-speedups]
"""
import argparse
import copy
import statistics
import time

import numpy as np

import particleShear.engine.step as engine_step
from particleShear.engine.state import BatchState, ReplicaPairs
from particleShear.engine.step import BatchEngine
from particleShear.run.batch import run_batch


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
    out.pairs = [ReplicaPairs(p.i.copy(), p.j.copy(), p.state.copy(), p.xi.copy(), p.d_eq.copy(), p.active.copy())
                 for p in (st.pairs[b] for b in rows)]
    out.rng = [copy.deepcopy(st.rng[b]) for b in rows]
    out.applying_shear = st.applying_shear
    return out


def time_batch(st, args, steps, warm, blocks, fast):
    """µs per replica-step of each block of ``steps`` protocol steps."""
    dt, f, A, cool = args
    engine = BatchEngine(st)
    engine.phase = "protocol"
    if not fast:
        engine.fast = False
    w = 2 * np.pi * f

    def run(n):
        for _ in range(n):
            t = float(st.t[0])
            engine.set_rate(A * np.cos(w * t) * w)
            engine.step(cool, dt, sample=True)

    run(warm)
    out = []
    for _ in range(blocks):
        t0 = time.perf_counter()
        run(steps)
        out.append(1e6 * (time.perf_counter() - t0) / (steps * st.B))
    return out, sum(len(p.i) for p in engine.s.pairs) / st.B


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=None, help="steps per block (default: about 1 s per block)")
    ap.add_argument("--warm", type=int, default=30)
    ap.add_argument("--blocks", type=int, default=3)
    ap.add_argument("--no-128", action="store_true", help="skip B = 128")
    ap.add_argument("--without-speedups", action="store_true", help="BatchEngine.fast = False")
    args = ap.parse_args()
    t0 = time.perf_counter()
    st, pargs = protocol_start(32)
    print(f"32 default scenes (N = {st.N}) constituted and pre-equilibrated in {time.perf_counter() - t0:.1f} s; "
          f"engine shortcuts {'off' if args.without_speedups else 'on'}")
    sizes = [1, 8, 32] + ([] if args.no_128 else [128])
    ref = None
    for B in sizes:
        rows = [b % 32 for b in range(B)]
        steps = args.steps or max(50, int(16000 / B))
        dt, f, A, cool = pargs
        us, per = time_batch(subset(st, rows), (dt, f, A[rows], cool), steps, args.warm, args.blocks, not args.without_speedups)
        med = statistics.median(us)
        ref = ref or med
        print(f"B = {B:4d}: {med:7.1f} us per replica-step (median of {len(us)} blocks of {steps} steps; "
              f"best {min(us):.1f}), {per:.0f} candidates per replica, ratio to B = 1: {med / ref:.3f}")


if __name__ == "__main__":
    main()
