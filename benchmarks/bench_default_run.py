"""Wall time of the default run ``doParticleShearSimulation(doDrawing=False, plotStress=False)``.

Prints the total wall time, the per-phase split (constitution = ensemble build and
relaxation, pre-equilibration with fixed plates, measurement protocol, demodulation,
output) and the moduli.  Target: total <= 10 s on one core.

Usage: python benchmarks/bench_default_run.py [--seed S] [--repeat R]
"""
import argparse
import os
import time

from particleShear import doParticleShearSimulation

#: the NumPy engine's figures (docs/performance.md); PARTICLESHEAR_BACKEND=numba times the compiled loop
os.environ.setdefault("PARTICLESHEAR_BACKEND", "numpy")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--repeat", type=int, default=1)
    args = ap.parse_args()
    for r in range(args.repeat):
        t0 = time.perf_counter()
        res = doParticleShearSimulation(doDrawing=False, plotStress=False, seed=args.seed + r, verbose=False,
                                        return_result=True)
        wall = time.perf_counter() - t0
        t = res.timings
        print(f"seed {args.seed + r}: wall {wall:.2f} s  (target <= 10 s)")
        for phase in ("constitution", "pre_equilibration", "protocol", "demodulation", "output"):
            print(f"  {phase:18s} {t.get(phase, 0.0):7.3f} s")
        print(f"  protocol steps {res.N_steps}, {1e6 * t['protocol'] / res.N_steps:.0f} us/step")
        print(f"  G' = {res.G_internal[0]:.2f} Pa, G'' = {res.G_internal[1]:.2f} Pa (overall tensor); "
              f"G' = {res.G_surface[0]:.2f} Pa, G'' = {res.G_surface[1]:.2f} Pa (surface forces)")


if __name__ == "__main__":
    main()
