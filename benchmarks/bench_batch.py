"""Throughput of batched runs against single runs, measured in one process (one core).

Prints, in one run:

* a single default run ``doParticleShearSimulation(doDrawing=False, plotStress=False, verbose=False)``
  (measured by the engine as a batch of one; the fastest of ``--single-repeat`` seeds is the
  reference) and the same run drawn without a window (``doDrawing=True, renderer="none"``: the
  engine with its observers),
  wall time and µs per protocol step;
* a series of ``--batch`` default-scene runs with ``batch_size=--batch``, ``executor=None,
  max_workers=1`` (one worker process): wall time per run, its ratio to the single run
  (target ≤ 1/3, goal 1/5) and µs per replica-step of the protocol (target ≤ 90 µs at N = 150).

Run it with ``OMP_NUM_THREADS=1``.  Usage: python benchmarks/bench_batch.py [--batch B] [--seed S]
[--relative-frequency F] (a larger F shortens every run by the same factor, for a quick look).
"""
import argparse
import os
import time

from particleShear import doParticleShearSimulation, doParticleShearSimulationSeries

#: the NumPy engine's figures (docs/performance.md); PARTICLESHEAR_BACKEND=numba times the compiled loop
os.environ.setdefault("PARTICLESHEAR_BACKEND", "numpy")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--batch", type=int, default=32)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--relative-frequency", type=float, default=0.025)
    ap.add_argument("--single-repeat", type=int, default=3, help="single runs timed (the fastest is the reference)")
    args = ap.parse_args()
    kw = dict(doDrawing=False, plotStress=False, relative_frequency=args.relative_frequency)

    walls = []
    for r in range(args.single_repeat):
        t0 = time.perf_counter()
        single = doParticleShearSimulation(seed=args.seed + r, verbose=False, return_result=True, **kw)
        walls.append(time.perf_counter() - t0)
    w_single = min(walls)     # the fastest single run: the conservative reference for the ratio
    print(f"single run (engine, batch of one): best of {len(walls)} {w_single:.2f} s "
          f"(all: {', '.join(f'{w:.2f}' for w in walls)}), protocol {single.N_steps} steps, "
          f"{1e6 * single.timings['protocol'] / single.N_steps:.0f} us/step")

    t0 = time.perf_counter()
    classic = doParticleShearSimulation(seed=args.seed, verbose=False, return_result=True,
                                        **dict(kw, doDrawing=True), renderer="none")
    w_classic = time.perf_counter() - t0
    print(f"single run (drawn, no window):     {w_classic:.2f} s, "
          f"{1e6 * classic.timings['protocol'] / classic.N_steps:.0f} us/step")

    t0 = time.perf_counter()
    res = doParticleShearSimulationSeries(N_repetitions=args.batch, batch_size=args.batch, executor=None,
                                          max_workers=1, seed=args.seed, **kw)
    w_batch = time.perf_counter() - t0
    per_run = w_batch / len(res)
    step = sum(r.timings["protocol"] for r in res) / sum(r.N_steps for r in res)
    print(f"series of {len(res)} runs, batch_size={args.batch}: {w_batch:.2f} s, {per_run:.3f} s per run "
          f"= {per_run / w_single:.3f} of the single run (target <= 0.333, goal 0.2)")
    print(f"  per run: constitution {sum(r.timings['constitution'] for r in res) / len(res):.3f} s, "
          f"pre-equilibration {sum(r.timings['pre_equilibration'] for r in res) / len(res):.3f} s, "
          f"protocol {sum(r.timings['protocol'] for r in res) / len(res):.3f} s")
    print(f"  protocol: {1e6 * step:.1f} us per replica-step at N = {single.parameters['N']} (target <= 90 us; "
          "LAMMPS pair_style granular: 46-51 us per single-replica step)")
    scale = 0.025 / args.relative_frequency      # a run's length scales with 1/relative_frequency
    print(f"  a campaign of 50,000 default runs (the paper's, ~30,000 CPU-hours on particleShear 1.0.2) on one core: "
          f"{50000 * per_run * scale / 3600:.1f} core-hours batched, {50000 * w_single * scale / 3600:.1f} single")


if __name__ == "__main__":
    main()
