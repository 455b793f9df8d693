"""Compare the package's G′, G″ with the R evaluation's on every saved run of a sweep folder.

    python examples/compare_r_evaluation.py DIR

DIR is a sweep folder made with ``saveData = true`` (e.g. examples/amplitude_sweep_analysis.toml).
For each ``ok`` row the run file is read back (verified) and re-evaluated as the R package does
(:func:`particleShear.analysis.evaluate_run`: initiation period dropped, jumps corrected, phase
origin at the first measured sample); printed are the relative differences R/package − 1 of both
estimators, per amplitude (median and largest |difference|) and over all runs.
"""
import csv
import os
import sys

import numpy as np

from particleShear.analysis import evaluate_run


def main(folder):
    with open(os.path.join(folder, "results.csv"), newline="", encoding="utf-8") as fh:
        rows = [r for r in csv.DictReader(fh) if r["status"] == "ok" and r["output_path"]]
    diffs = {}   # (estimator, modulus) -> list of (amplitude, relative difference)
    for r in rows:
        ev = evaluate_run(os.path.join(folder, r["output_path"]))
        for est in ev:
            for k, name in enumerate(("Gp", "Gpp")):
                pkg = float(r[f"{name}_{est}"])
                diffs.setdefault((est, name), []).append((float(r["theAmplitude"]), ev[est][k] / pkg - 1))
    print(f"{len(rows)} runs of {folder}: R evaluation / package - 1")
    print(f"{'estimator':>9} {'modulus':>7} {'amplitude':>9} {'median |d|':>11} {'max |d|':>9}")
    for (est, name), vals in sorted(diffs.items()):
        a = np.array(vals)
        for amp in np.unique(a[:, 0]):
            d = np.abs(a[a[:, 0] == amp, 1])
            print(f"{est:>9} {name:>7} {amp:>9g} {np.median(d):>11.2%} {d.max():>9.2%}")
        d = np.abs(a[:, 1])
        print(f"{est:>9} {name:>7} {'all':>9} {np.median(d):>11.2%} {d.max():>9.2%}")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else ".")
