"""Cost of the stroboscopic observer (issue 49): protocol wall time with ``stroboscopic`` off and on.

The observer also times its own snapshots (``result.microstructure["seconds"]``), which a loaded
machine measures far more steadily than the difference of two runs.  The same run (one seed) is measured alternately off and on, ``--repeats`` times each; the
protocol phase's wall time (``result.timings["protocol"]``, s) is compared by the median of the
paired ratios on/off.  The moduli of each pair are checked to be identical (the observer only reads).

    python benchmarks/stroboscopic_cost.py --N 150 --periods 3 --repeats 3
"""
import argparse
import os
import statistics
import time

from particleShear import doParticleShearSimulation

#: the NumPy engine's figures (docs/performance.md); PARTICLESHEAR_BACKEND=numba times the compiled loop
os.environ.setdefault("PARTICLESHEAR_BACKEND", "numpy")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--N", type=int, default=150)
    ap.add_argument("--periods", type=float, default=3)
    ap.add_argument("--amplitude", type=float, default=0.1)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--seed", type=int, default=1)
    a = ap.parse_args(argv)
    kw = dict(N=a.N, theAmplitude=a.amplitude, periods=a.periods, pre_periods=1, post_periods=1, doDrawing=False,
              saveData=False, plotStress=False, verbose=False, seed=a.seed, return_result=True)
    ratios, off_t, on_t, own = [], [], [], []
    t0 = time.perf_counter()
    for _ in range(a.repeats):
        off = doParticleShearSimulation(**kw)
        on = doParticleShearSimulation(stroboscopic=True, **kw)
        assert off.G_surface == on.G_surface and off.G_internal == on.G_internal
        off_t.append(off.timings["protocol"])
        on_t.append(on.timings["protocol"])
        ratios.append(on_t[-1] / off_t[-1])
        own.append(on.microstructure["seconds"] / on_t[-1])
    print(f"N={a.N} periods={a.periods} amplitude={a.amplitude} repeats={a.repeats} "
          f"(wall {time.perf_counter() - t0:.0f} s)")
    print(f"protocol off: median {statistics.median(off_t):.3f} s  {['%.3f' % t for t in off_t]}")
    print(f"protocol on : median {statistics.median(on_t):.3f} s  {['%.3f' % t for t in on_t]}")
    print(f"cost of the observer: median paired ratio on/off - 1 = {100 * (statistics.median(ratios) - 1):+.1f} % "
          f"(pairs {['%+.1f %%' % (100 * (r - 1)) for r in ratios]})")
    print(f"time inside the observer's snapshots / protocol time: median {100 * statistics.median(own):.2f} % "
          "(the per-step check of the step count is not included; it is a set lookup)")


if __name__ == "__main__":
    main()
