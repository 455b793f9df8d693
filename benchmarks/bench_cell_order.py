"""The compiled step at N = 10,000 with the spheres labelled in cell order against the order drawn (not a test).

Issue 47 names spatial sorting of the spheres by cell as the next lever at large N: the candidate
lists are ordered by sphere label (``i << 32 | j``), so a pair's second sphere is read from
anywhere in the sphere arrays when labels are random in space.  This benchmark builds the bench
scene of ``bench_step.build`` twice from one seed, the same positions and sizes labelled as drawn
and in ``bench_step.cell_order`` (rows of cells, 1.25 large-sphere diameters wide), and times the
compiled blocks of ``bench_compiled.py`` (256 steps, as the protocols run them) alternately in one
process, one thread.  The two scenes are one packing under two labellings, so their trajectories
differ only by rounding (the order of the force sums): the ratio is the lever's size, not a
change of physics.

Usage: python benchmarks/bench_cell_order.py [--n 10000] [--steps 256] [--blocks 6]
"""
import os

for _v in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ[_v] = "1"
os.environ["PARTICLESHEAR_BACKEND"] = "numba"

import argparse  # noqa: E402
import statistics  # noqa: E402
import sys  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bench_compiled  # noqa: E402
import bench_step  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=10_000, help="spheres (default 10,000)")
    ap.add_argument("--steps", type=int, default=256, help="steps per compiled block (default 256)")
    ap.add_argument("--blocks", type=int, default=6, help="timed blocks per labelling (default 6)")
    a = ap.parse_args()
    runs = {name: bench_compiled.engine([bench_step.build(a.n, seed=1, by_cell=by_cell)], "numba blocks")
            for name, by_cell in (("as drawn", False), ("cell order", True))}
    for run in runs.values():
        run(5)                          # the compile (or the cache load) is not timed
    ns = {name: [] for name in runs}
    for k in range(a.blocks):
        for name in (list(runs) if k % 2 else list(runs)[::-1]):
            ns[name].append(runs[name](a.steps) / (a.steps * a.n) * 1e9)
    ratio = [c / d for d, c in zip(ns["as drawn"], ns["cell order"])]
    print(f"| labels | ns per particle-step, median (min) | N = {a.n}, blocks of {a.steps} steps |")
    print("|---|---|---|")
    for name, v in ns.items():
        print(f"| {name} | {statistics.median(v):.1f} ({min(v):.1f}) | |")
    print(f"\ncell order / as drawn, block by block: median {statistics.median(ratio):.3f} "
          f"(range {min(ratio):.3f}–{max(ratio):.3f})")


if __name__ == "__main__":
    main()
