"""Irreversibility onset against the flow and softening points on a small amplitude sweep (issue 49).

Runs ``--seeds`` seeds at each amplitude with ``stroboscopic=True`` and prints the onset
(:func:`particleShear.analysis.microstructure.onset_summary`) beside the flow point and softening
strain with their bootstrap intervals; writes the runs to ``--csv`` and the figure to ``--figure``.

    python benchmarks/stroboscopic_onset.py --N 30 --seeds 8
"""
import argparse
import csv

import numpy as np

from particleShear import doParticleShearSimulation
from particleShear.analysis.microstructure import onset_figure, onset_summary

AMPLITUDES = (0.002, 0.005, 0.01, 0.02, 0.05, 0.1, 0.2, 0.5)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--N", type=int, default=30)
    ap.add_argument("--seeds", type=int, default=8)
    ap.add_argument("--periods", type=float, default=3)
    ap.add_argument("--csv", default="stroboscopic_onset.csv")
    ap.add_argument("--figure", default=None)
    a = ap.parse_args(argv)
    rows = []
    for seed in range(a.seeds):
        for A in AMPLITUDES:
            r = doParticleShearSimulation(N=a.N, theAmplitude=A, periods=a.periods, pre_periods=1, post_periods=1,
                                          doDrawing=False, saveData=False, plotStress=False, verbose=False,
                                          seed=seed, return_result=True, stroboscopic=True)
            m = r.measures
            rows.append(dict(seed=seed, amplitude=A, Gp=r.G_surface[0], Gpp=r.G_surface[1],
                             irreversibility=m["irreversibility"], moved_fraction=m["moved_fraction"],
                             Z_rattler_free=m["Z_rattler_free"], contact_change_rate=m["contact_change_rate"]))
            print(rows[-1], flush=True)
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
