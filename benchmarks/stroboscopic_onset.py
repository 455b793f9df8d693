"""Irreversibility onset against the flow and softening points on a small amplitude sweep (issue 49).

Runs ``--seeds`` seeds at each amplitude with ``stroboscopic=True`` and prints the onset
(:func:`particleShear.analysis.microstructure.onset_summary`) beside the flow point and softening
strain with their bootstrap intervals; writes the runs to ``--csv`` and the figure to ``--figure``.
The seeds of one amplitude run as one batch (:func:`particleShear.run.batch.run_batch`: the same
results as single runs, bit for bit, in a fraction of the time).  The finding of
docs/microstructure.md ("Finding") is the output of

    python benchmarks/stroboscopic_onset.py --N 40 --seeds 16 --periods 4

(6.7 min on one shared core; run from the repository root with ``PYTHONPATH=.`` so the
working tree is the package imported).
"""
import argparse
import csv
import time

import numpy as np

from particleShear.analysis.microstructure import onset_figure, onset_summary
from particleShear.run.batch import run_batch

AMPLITUDES = (0.002, 0.005, 0.01, 0.02, 0.05, 0.1, 0.2, 0.3, 0.5, 0.7, 1.0)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--N", type=int, default=40)
    ap.add_argument("--seeds", type=int, default=16)
    ap.add_argument("--periods", type=float, default=4)
    ap.add_argument("--csv", default="stroboscopic_onset.csv")
    ap.add_argument("--figure", default=None)
    a = ap.parse_args(argv)
    rows = []
    t0 = time.perf_counter()
    print(f"N={a.N} seeds={a.seeds} periods={a.periods} amplitudes={AMPLITUDES}", flush=True)
    for A in AMPLITUDES:
        kw = dict(N=a.N, theAmplitude=A, periods=a.periods, pre_periods=1, post_periods=1, doDrawing=False,
                  saveData=False, plotStress=False, verbose=False, stroboscopic=True)
        for seed, r in enumerate(run_batch([dict(kw, seed=seed) for seed in range(a.seeds)])):
            m = r.measures
            rows.append(dict(seed=seed, amplitude=A, Gp=r.G_surface[0], Gpp=r.G_surface[1],
                             irreversibility=m["irreversibility"], moved_fraction=m["moved_fraction"],
                             Z_rattler_free=m["Z_rattler_free"], contact_change_rate=m["contact_change_rate"]))
        at = [r for r in rows if r["amplitude"] == A]
        med = lambda k: float(np.median([r[k] for r in at]))   # noqa: E731
        print(f"A={A:g}: median G'={med('Gp'):.4g} Pa G''={med('Gpp'):.4g} Pa irreversibility={med('irreversibility'):.3g} "
              f"moved={med('moved_fraction'):.3g} Z={med('Z_rattler_free'):.3g} "
              f"contact_change_rate={med('contact_change_rate'):.3g} ({time.perf_counter() - t0:.0f} s)", flush=True)
    with open(a.csv, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    col = lambda k: np.array([r[k] for r in rows])   # noqa: E731
    out = onset_summary(col("amplitude"), col("Gp"), col("Gpp"), col("irreversibility"), n_boot=2000, rng=0)
    o = out["onset"]
    print(f"irreversibility onset: {o['onset']:.4g} [{o['low']:.4g}, {o['high']:.4g}] flag={o['flag']!r}")
    for name in ("softening_strain", "linear_limit_10", "flow_point"):
        v = out[name]
        print(f"{name}: {v[0]:.4g} [{v[1]:.4g}, {v[2]:.4g}]")
    if a.figure:
        onset_figure(col("amplitude"), col("Gp"), col("Gpp"), col("irreversibility"), a.figure, onset=o)


if __name__ == "__main__":
    main()
