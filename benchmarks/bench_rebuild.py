"""The cost of a neighbour-list rebuild event in a batch of 32 default-scene replicas (N = 150).

Prints µs per batch-step of ``BatchEngine.step(cool, dt, sample=True)`` with one replica's list
rebuilt every step (the replica chosen round robin; an early rebuild keeps the list valid) and
without forced rebuilds, and their difference, the cost of one rebuild event (the candidate
search, the constants of the rebuilt replica, the splice, and the next step's fresh image counts
and mobility flags).  ``--baseline REV`` runs the engine of that git revision in alternating
blocks on a copy of the same batch and checks that the two trajectories stay bit-identical.
Process time, the smallest of ``--blocks`` blocks of 40 steps (the host's scatter is large).

Run it with ``OMP_NUM_THREADS=1``.  Usage: python benchmarks/bench_rebuild.py [--blocks K] [--baseline REV]
"""
import argparse
import os
import tempfile
import time

import numpy as np

from bench_engine import baseline_engine, protocol_start, subset
from particleShear.engine.step import BatchEngine

#: the NumPy engine's figures (docs/performance.md); PARTICLESHEAR_BACKEND=numba times the compiled loop
os.environ.setdefault("PARTICLESHEAR_BACKEND", "numpy")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--blocks", type=int, default=12)
    ap.add_argument("--baseline", default=None, help="git revision whose engine runs alternately, for comparison")
    args = ap.parse_args()
    st, (dt, f, A, cool) = protocol_start(32)
    w = 2 * np.pi * f
    with tempfile.TemporaryDirectory() as folder:
        classes = [BatchEngine] + ([baseline_engine(args.baseline, folder)] if args.baseline else [])
        runs = []
        for cls in classes:
            s = subset(st, list(range(32)))
            e = cls(s)
            e.phase = "protocol"
            runs.append((s, e))
        K = 40
        best = {}
        for blk in range(args.blocks):
            for forced in (True, False):
                for k, (s, e) in enumerate(runs):
                    t0 = time.process_time()
                    for q in range(K):
                        if forced:
                            e.s.contacts.need[(blk * K + q) * 7 % 32] = True
                        e.set_rate(A * np.cos(w * float(s.t[0])) * w)
                        e.step(cool, dt, sample=True)
                    us = 1e6 * (time.process_time() - t0) / K
                    best[k, forced] = min(best.get((k, forced), us), us)
    for k, name in enumerate(["now"] + ([args.baseline] if args.baseline else [])):
        plain, rebuilt = best[k, False], best[k, True]
        print(f"{name}: batch-step {plain:.0f} us, with one rebuild {rebuilt:.0f} us, one rebuild event {rebuilt - plain:.0f} us")
    if args.baseline:
        same = all(np.array_equal(getattr(runs[0][0], n), getattr(runs[1][0], n))
                   for n in ("x", "y", "vx", "vy", "omega", "phi"))
        print(f"trajectories bit-identical: {same}")


if __name__ == "__main__":
    main()
