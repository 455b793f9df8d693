"""Throughput of the engine on a CUDA GPU (CuPy) against NumPy on one core, in one run.

Prints, in one run:

* NumPy, one core: a single default run ``doParticleShearSimulation(doDrawing=False,
  plotStress=False)`` (the engine, a batch of one): ns per particle-step of its protocol;
* CuPy: batches of ``--sizes`` default-scene replicas (default 32, 256, 1024; N = 150, seeds
  spawned from ``--seed``) measured with ``run_batch(..., backend="cupy")`` in this process:
  wall time of the batch and of its phases per replica, ns per particle-step of the protocol
  (goal ≤ 5 at B = 1,024) and its ratio to the NumPy figure;
* the projected wall time of a 50,000-run campaign on one GPU, per batch size:
  ``(batch wall time / B) × 50,000`` — constitution (on the host, through the documented
  classes) included.

Without CuPy or a CUDA device it prints ``CuPy not available: ...`` and exits with status 0.
A batch that fails (e.g. memory) is reported and the next size is measured.  Run it with
``OMP_NUM_THREADS=1`` (one host core, as the NumPy figure).  Usage:
``python benchmarks/bench_gpu.py [--sizes 32,256,1024] [--seed S] [--relative-frequency F]``
(a larger F shortens every run by the same factor, for a quick look; the per-step figures stay
comparable, the campaign projection assumes the given F).
"""
import argparse
import sys
import time
import traceback

import numpy as np

CAMPAIGN = 50_000


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", default="32,256,1024", help="comma-separated batch sizes (replicas per GPU batch)")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--relative-frequency", type=float, default=0.025)
    args = ap.parse_args()
    try:
        sizes = [int(s) for s in args.sizes.split(",") if s.strip()]
    except ValueError:
        sizes = []
    if not sizes or min(sizes) < 1:
        ap.error(f"--sizes={args.sizes!r} is invalid: allowed comma-separated integers >= 1")

    from particleShear.engine.xp import get_backend
    try:
        get_backend("cupy")
    except ValueError as exc:
        print(f"CuPy not available: {exc}")
        return 0
    import cupy

    from particleShear import doParticleShearSimulation
    from particleShear.run.batch import run_batch

    kw = dict(doDrawing=False, plotStress=False, verbose=False, relative_frequency=args.relative_frequency)
    props = cupy.cuda.runtime.getDeviceProperties(cupy.cuda.Device().id)
    name = props["name"].decode() if isinstance(props["name"], bytes) else props["name"]
    print(f"device: {name}, CuPy {cupy.__version__}, NumPy {np.__version__}")

    t0 = time.perf_counter()
    single = doParticleShearSimulation(seed=args.seed, return_result=True, backend="numpy", **kw)
    w_single = time.perf_counter() - t0
    N = single.parameters["N"]
    ns_numpy = 1e9 * single.timings["protocol"] / (single.N_steps * N)
    print(f"NumPy, one core, single default run: {w_single:.2f} s, protocol {single.N_steps} steps, "
          f"{ns_numpy:.0f} ns per particle-step (N = {N})")

    children = np.random.SeedSequence(args.seed).spawn(max(sizes))
    for B in sizes:
        runs = [dict(kw, seed=children[k]) for k in range(B)]
        try:
            t0 = time.perf_counter()
            res = run_batch(runs, backend="cupy")
            cupy.cuda.Device().synchronize()
            wall = time.perf_counter() - t0
        except Exception:  # noqa: BLE001 - report and measure the next size
            print(f"B = {B}: failed")
            traceback.print_exc(file=sys.stdout)
            continue
        share = {k: sum(r.timings.get(k, 0.0) for r in res) / B for k in ("constitution", "pre_equilibration",
                                                                          "protocol")}
        steps = res[0].N_steps
        ns = 1e9 * share["protocol"] / (steps * N)   # per-replica share of the protocol / (steps × N)
        per_run = wall / B
        campaign_h = per_run * CAMPAIGN / 3600
        print(f"CuPy, B = {B}: batch {wall:.1f} s = {per_run:.3f} s per run (constitution "
              f"{share['constitution']:.3f}, pre-equilibration {share['pre_equilibration']:.3f}, protocol "
              f"{share['protocol']:.3f} s per replica); protocol {ns:.2f} ns per particle-step "
              f"({ns_numpy / ns:.0f}x NumPy's single replica; goal <= 5 ns at B = 1024)")
        print(f"  projected {CAMPAIGN:,}-run campaign on one GPU in batches of {B}: {campaign_h:.1f} h "
              f"(per-run time x {CAMPAIGN:,}, constitution included)")
        g = [r.G_surface[0] for r in res]
        print(f"  G' (surface) of the replicas: mean {np.mean(g):.1f} Pa, sd {np.std(g):.1f} Pa")
        del res
        cupy.get_default_memory_pool().free_all_blocks()
    return 0


if __name__ == "__main__":
    sys.exit(main())
