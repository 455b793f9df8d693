"""Cost of one run of each protocol: a single call and the per-run share of a batch, same process.

Whole calls of ``doParticleShearSimulation(seed=s, doDrawing=False, protocol=...)`` and of
``run_batch`` over ``--batch`` seeds, at the defaults unless ``--N`` is given (docs/protocols.md,
"Cost").  Both are timed in this one run, so their ratio is meaningful on a noisy machine.

    python benchmarks/bench_protocols.py [--N 150] [--batch 8]
"""
import argparse
import os
import time
import warnings

from particleShear import doParticleShearSimulation
from particleShear.run.batch import run_batch

#: the NumPy engine's figures (docs/performance.md); PARTICLESHEAR_BACKEND=numba times the compiled loop
os.environ.setdefault("PARTICLESHEAR_BACKEND", "numpy")

PROTOCOLS = {
    "oscillatory": {},
    "steady": dict(protocol="steady", relative_rate=0.01, total_strain=2.0),
    "relaxation": dict(protocol="relaxation", hold_time=200.0),
    "creep": dict(protocol="creep", creep_stress=50.0, hold_time=200.0),
    "amplitude_sweep": dict(protocol="amplitude_sweep", sweep_amplitudes=[0.05, 0.1, 0.2]),
    "frequency_sweep": dict(protocol="frequency_sweep", sweep_frequencies=[0.025, 0.05]),
}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--N", type=int, default=150)
    ap.add_argument("--batch", type=int, default=8)
    ap.add_argument("--only", nargs="*", default=None, help="protocols to time (default: all)")
    args = ap.parse_args(argv)
    warnings.simplefilter("ignore")
    base = dict(N=args.N, doDrawing=False, verbose=False)
    print(f"N = {args.N}, batch of {args.batch} seeds; whole calls, wall time per run")
    print(f"{'protocol':<16} {'single (s)':>11} {'batch/run (s)':>14} {'ratio':>6}")
    for name, kw in PROTOCOLS.items():
        if args.only and name not in args.only:
            continue
        t0 = time.perf_counter()
        doParticleShearSimulation(**base, **kw, seed=1)
        single = time.perf_counter() - t0
        t0 = time.perf_counter()
        run_batch([dict(base, **kw, seed=s) for s in range(1, args.batch + 1)])
        per = (time.perf_counter() - t0) / args.batch
        print(f"{name:<16} {single:11.2f} {per:14.2f} {per / single:6.2f}", flush=True)


if __name__ == "__main__":
    main()
