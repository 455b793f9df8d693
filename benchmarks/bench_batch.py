"""Throughput of batched runs against single runs, measured in one process (one core).

Prints, in one run:

* a single default run ``doParticleShearSimulation(doDrawing=False, plotStress=False, verbose=False)``
  (measured by the engine as a batch of one) and the same run through the documented classes
  (forced with a progress callback), wall time and µs per protocol step;
* a series of ``--batch`` default-scene runs with ``batch_size=--batch``, ``executor=None,
  max_workers=1`` (one worker process): wall time per run, its ratio to the single run
  (target ≤ 1/3, goal 1/5) and µs per replica-step of the protocol (target ≤ 90 µs at N = 150).

Run it with ``OMP_NUM_THREADS=1``.  Usage: python benchmarks/bench_batch.py [--batch B] [--seed S]
[--relative-frequency F] (a larger F shortens every run by the same factor, for a quick look).
"""
import argparse
import time

from particleShear import doParticleShearSimulation, doParticleShearSimulationSeries


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--batch", type=int, default=32)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--relative-frequency", type=float, default=0.025)
    args = ap.parse_args()
    kw = dict(doDrawing=False, plotStress=False, relative_frequency=args.relative_frequency)

    t0 = time.perf_counter()
    single = doParticleShearSimulation(seed=args.seed, verbose=False, return_result=True, **kw)
    w_single = time.perf_counter() - t0
    print(f"single run (engine, batch of one): {w_single:.2f} s, protocol {single.N_steps} steps, "
          f"{1e6 * single.timings['protocol'] / single.N_steps:.0f} us/step")

    t0 = time.perf_counter()
    classic = doParticleShearSimulation(seed=args.seed, verbose=False, return_result=True,
                                        progress=lambda *a: None, **kw)
    w_classic = time.perf_counter() - t0
    print(f"single run (documented classes):   {w_classic:.2f} s, "
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


if __name__ == "__main__":
    main()
