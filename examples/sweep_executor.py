"""Amplitude × friction sweep on a concurrent.futures executor.

Runs ``doParticleShearSimulationSeries`` (reference iteration order) with one root seed: each run
gets its own child seed from ``numpy.random.SeedSequence(seed).spawn(n)``, so the sweep is
reproducible whatever executor runs it and in whatever order the runs finish.

Any ``concurrent.futures.Executor`` works: the default process pool, a thread pool, Dask
(``distributed.Client(...).get_executor()``), ``mpi4py.futures.MPIPoolExecutor()``, submitit, ...

Usage: python examples/sweep_executor.py [--workers 4] [--quick] [--save DIR]
"""
import argparse
import concurrent.futures
import os

from particleShear import doParticleShearSimulationSeries


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--workers", type=int, default=os.cpu_count() or 1)
    ap.add_argument("--quick", action="store_true", help="tiny ensembles and short protocols (seconds per run)")
    ap.add_argument("--save", default="", help="write the text output files into this folder")
    ap.add_argument("--seed", type=int, default=2024)
    args = ap.parse_args()

    options = dict(N=30, relative_frequency=0.1, cut_lines=3) if args.quick else {}
    with concurrent.futures.ProcessPoolExecutor(max_workers=args.workers) as pool:
        results = doParticleShearSimulationSeries(
            root_folder=args.save, amplitudes=[0.05, 0.2], mu=[0.01, 0.1], N_repetitions=2,
            do_uncrosslinked_control=True, doDrawing=False, plotStress=False, saveData=bool(args.save),
            executor=pool, seed=args.seed, **options)

    print(f"{'A':>6} {'mu':>6} {'links':>6} {'G1 overall':>12} {'G2 overall':>12} {'G1 surface':>12} "
          f"{'G2 surface':>12} {'time s':>7}")
    for r in results:
        p = r.parameters
        print(f"{p['theAmplitude']:6.3f} {p['theMu']:6.3f} {str(p['do_permanent_links']):>6} "
              f"{r.G_internal[0]:12.1f} {r.G_internal[1]:12.1f} {r.G_surface[0]:12.1f} {r.G_surface[1]:12.1f} "
              f"{r.timings['total']:7.1f}")


if __name__ == "__main__":
    main()
