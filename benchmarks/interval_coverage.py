"""Coverage of the bootstrap intervals of ``sweep_summary`` on model amplitude sweeps.

Each sweep is the model G′ = G₀/(1+x²), G″ = r·G₀·x/(1+x²), x = A/A_c (G₀ = 1000 Pa, r = 0.5,
A_c = 0.05; its flow point G′ = G″ is A_c/r = 0.1 and log G′ − log G″ is linear in log A, so the
log-log interpolated flow point is exact) at 5 amplitudes 0.0005 … 1.58 with n seeds each; every
seed's G′ and G″ are the model's times independent normal factors 1 + s′·ε, 1 + s″·ε.  The seed
spreads are those of the simulation over packings (docs/accuracy.md: 10 % for G′ and 40 % for G″
at N = 150) and, for comparison, 10 % for both.  For each setting M independent sweeps are drawn
and summarised with the default 95 % intervals (Student width on the log scale); the coverage is
the fraction of sweeps whose interval holds the true value, with its binomial standard error
√(c(1 − c)/M).  Printed per setting: the coverage of the plateau, of the mean G′ and G″ at every
amplitude (pooled), of the flow point, the fraction of flow points reported as bounds or with open
intervals, and the smallest lower end of any modulus interval (>= 0 by construction).

    python benchmarks/interval_coverage.py            # M = 400 sweeps per setting, n_boot = 1000
    python benchmarks/interval_coverage.py --quick    # M = 100, for a check (coverage ± 2 %)

Runs in a few minutes on one core (prints the time).  NumPy only.
"""
import argparse
import math
import sys
import time
import warnings

import numpy as np

from particleShear.analysis.sweep import sweep_summary

G0, R, AC = 1000.0, 0.5, 0.05
AMPLITUDES = AC * np.logspace(-2, 1.5, 5)
SETTINGS = [(2, 0.10, 0.40), (4, 0.10, 0.40), (10, 0.10, 0.40), (4, 0.10, 0.10), (10, 0.10, 0.10)]


def model(A):
    x = np.asarray(A, float) / AC
    return G0 / (1 + x ** 2), R * G0 * x / (1 + x ** 2)


def coverage(n, s_gp, s_gpp, M, n_boot, rng):
    A = np.repeat(AMPLITUDES, n)
    gp0, gpp0 = model(A)
    gp_true, gpp_true = model(AMPLITUDES)
    hits = {"plateau": 0, "G′ means": 0, "G″ means": 0, "flow point": 0}
    means_total = 0
    bounds = opened = 0
    lowest = math.inf
    for _ in range(M):
        gp = gp0 * (1 + s_gp * rng.standard_normal(A.size))
        gpp = gpp0 * (1 + s_gpp * rng.standard_normal(A.size))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)
            s = sweep_summary(A, gp, gpp, n_boot=n_boot, rng=rng)
        hits["plateau"] += s.plateau_ci[0] <= gp_true[0] <= s.plateau_ci[1]
        hits["G′ means"] += int(np.sum((s.Gp_ci[:, 0] <= gp_true) & (gp_true <= s.Gp_ci[:, 1])))
        hits["G″ means"] += int(np.sum((s.Gpp_ci[:, 0] <= gpp_true) & (gpp_true <= s.Gpp_ci[:, 1])))
        means_total += len(AMPLITUDES)
        flag = s.flags["flow_point"]
        bounds += flag in ("lower_bound", "upper_bound")
        opened += flag.startswith("open")
        lo, hi = s.flow_point_ci
        hits["flow point"] += bool(lo <= AC / R <= hi)     # a bound or no interval counts as a miss
        ends = np.r_[s.Gp_ci[:, 0], s.Gpp_ci[:, 0], s.plateau_ci[0]]
        if np.isfinite(ends).any():
            lowest = min(lowest, float(np.nanmin(ends)))
    out = {k: v / (means_total if "means" in k else M) for k, v in hits.items()}
    return out, bounds / M, opened / M, lowest, {k: (means_total if "means" in k else M) for k in hits}


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--quick", action="store_true", help="100 sweeps per setting instead of 400")
    p.add_argument("--sweeps", type=int, default=None, help="sweeps per setting (default 400, --quick 100)")
    p.add_argument("--n-boot", type=int, default=1000, help="bootstrap replicates per sweep (default 1000)")
    p.add_argument("--seed", type=int, default=20261206, help="seed of the model draws and the bootstraps")
    args = p.parse_args(argv)
    M = args.sweeps or (100 if args.quick else 400)
    rng = np.random.default_rng(args.seed)
    t0 = time.perf_counter()
    print(f"95 % intervals of sweep_summary (default: Student width on the log scale), {M} model sweeps per row, "
          f"n_boot = {args.n_boot}, seed {args.seed}")
    print(f"{'seeds':>5} {'sd G′':>6} {'sd G″':>6} | {'plateau':>8} {'G′ means':>8} {'G″ means':>8} "
          f"{'flow pt':>8} | {'bound':>6} {'open':>6} {'min low (Pa)':>12}")
    for n, a, b in SETTINGS:
        cov, bounds, opened, lowest, counts = coverage(n, a, b, M, args.n_boot, rng)
        cells = " ".join(f"{100 * cov[k]:7.1f}%" for k in ("plateau", "G′ means", "G″ means", "flow point"))
        print(f"{n:5d} {100 * a:5.0f}% {100 * b:5.0f}% | {cells} | {100 * bounds:5.1f}% {100 * opened:5.1f}% "
              f"{lowest:12.4g}")
    se = 100 * math.sqrt(0.95 * 0.05 / M)
    print(f"binomial standard error of a coverage near 95 %: {se:.1f} % (plateau, flow point over {M} sweeps), "
          f"{se / math.sqrt(len(AMPLITUDES)):.1f} % (means over {M * len(AMPLITUDES)} intervals)")
    print(f"time: {time.perf_counter() - t0:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
