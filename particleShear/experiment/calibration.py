"""Calibrate a simulated campaign against a measured amplitude sweep: which grid point, and which E.

:func:`calibrate` takes a measured amplitude sweep (one :class:`~particleShear.experiment.tables.MeasuredTest`
of kind ``amplitude_sweep``, or several: replicate samples) and a sweep folder whose runs cover a grid
of microscopic parameters (μ, crosslinking, packing, contact law …) at several amplitudes with seeds,
and ranks the grid points — the groups of ``particleShear analyse``
(:func:`particleShear.analysis.cli.group_runs`: every parameter but the amplitude, seeds pooled) — by
how well their *normalised* sweeps match the measured one.

The rule (docs/experiment.md):

1. the mean curves: the simulated runs are averaged per amplitude (seeds); each measured replicate is
   interpolated (linearly in log γ₀) onto the amplitudes of all replicates within the range they all
   cover, and averaged;
2. the overlap: the amplitudes both the measured and the simulated mean curve cover,
   ``[max(γ_min), min(γ_max)]``; the comparison points are the amplitudes of either curve there;
3. normalisation: both curves are interpolated linearly in log γ₀ onto the comparison points and
   divided by their own G′ at the first of them (the plateau G′_p, the ``sweep_summary`` plateau when
   both sweeps start at the same amplitude);
4. the mismatch: the root mean square over the comparison points of the differences of G′/G′_p and
   G″/G′_p (dimensionless; 0 for curves of the same shape, whatever their modulus);
5. the modulus scale: s = G′_p(measured)/G′_p(simulated).  The simulated moduli are proportional to
   the spheres' Young modulus at fixed dimensionless parameters (G ∝ E), so the E to use is
   s·``Young_modulus_spheres`` of the grid point.

Intervals are percentile bootstrap intervals: in each replicate the runs of every simulated amplitude
are resampled with replacement (as :func:`particleShear.analysis.sweep.sweep_summary` does, with the
same Student widening of the replicate means) and so are the measured replicates (whole curves); the
mismatch and the scale are recomputed, and ``p_best`` is the fraction of replicates in which a grid
point ranks first.  With one measured replicate the measured curve is held fixed (its sample-to-sample
spread is then not in the intervals).

Assumptions (:data:`ASSUMPTIONS`, printed with every ranking): the simulation's rate is dimensionless
(f·τ, ``relative_frequency``) — a rheometer sweep at f Hz is compared with a campaign run at the
f·τ the material's τ gives (the amplitudes are matched, the frequency is not); the 2D stress is a
force per length of the cell per metre of depth, reported in Pa and compared with the 3D moduli as
they are (no 2D→3D geometric factor: such a factor would be absorbed into s, i.e. into E).

``particleShear calibrate MEASURED… DIR`` is the command line (:func:`main`).
"""
__docformat__ = "numpy"
import math
import os
import sys

import numpy as np

from .tables import ASSUMPTIONS, RANKING_COLUMNS, Calibration, MeasuredTest  # noqa: F401 - re-exported
from ..analysis.sweep import N_BOOT_MAX, _student_factor, _widen_log
from ..run.guard import SuggestingParser
from .readers import read_rheometer
from ..analysis.cli import group_runs
from ..plot_tools import _has_matplotlib, read_sweep_table
from .figure import plot_calibration

__all__ = ["ASSUMPTIONS", "RANKING_COLUMNS", "Calibration", "calibrate", "measured_curve", "main"]

# ---------------------------------------------------------------------------------------------
# checks and curves
# ---------------------------------------------------------------------------------------------
def _check(measured, estimator, n_boot, confidence, seed):
    if estimator not in ("surface", "internal"):
        raise ValueError(f"estimator={estimator!r} is invalid: allowed one of ('surface', 'internal')")
    if isinstance(n_boot, bool) or not isinstance(n_boot, (int, np.integer)) or not 1 <= n_boot <= N_BOOT_MAX:
        raise ValueError(f"n_boot={n_boot!r} is invalid: allowed an integer in [1, {N_BOOT_MAX}]")
    if isinstance(confidence, bool) or not isinstance(confidence, (int, float)) or not 0 < confidence < 1:
        raise ValueError(f"confidence={confidence!r} is invalid: allowed a number in (0, 1)")
    if seed is not None and (isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0):
        raise ValueError(f"seed={seed!r} is invalid: allowed None or an integer >= 0")
    tests = [measured] if isinstance(measured, MeasuredTest) else list(measured) if isinstance(
        measured, (list, tuple)) else None
    if not tests or not all(isinstance(t, MeasuredTest) for t in tests):
        raise ValueError(f"measured={type(measured).__name__} is invalid: allowed a MeasuredTest of kind "
                         "'amplitude_sweep' or a non-empty list of them (replicates)")
    curves = []
    for i, t in enumerate(tests):
        if t.kind != "amplitude_sweep":
            raise ValueError(f"measured[{i}].kind={t.kind!r} is invalid: allowed 'amplitude_sweep'")
        t = t.finite()
        A, gp, gpp = t["strain_amplitude"], t["Gp"], t["Gpp"]
        keep = A > 0
        A, gp, gpp = A[keep], gp[keep], gpp[keep]
        u = np.unique(A)
        if len(u) < 2:
            raise ValueError(f"measured[{i}] has {len(u)} distinct positive amplitude(s): allowed >= 2")
        curves.append((u, np.array([gp[A == a].mean() for a in u]), np.array([gpp[A == a].mean() for a in u])))
    return curves


def _weights(x_from, x_to):
    """Matrix W (len(x_to), len(x_from)): y(x_to) = W @ y(x_from), linear in log x (x_to inside the range)."""
    lf, lt = np.log(x_from), np.log(x_to)
    eye = np.eye(len(x_from))
    return np.stack([np.interp(lt, lf, eye[j]) for j in range(len(x_from))], axis=1)


def measured_curve(curves):
    """The mean measured curve of replicate curves (rule step 1 of the module docstring).

    Parameters
    ----------
    curves : list of (A, G′, G″)
        One per replicate: sorted unique amplitudes (1) and the moduli there (Pa).

    Returns
    -------
    grid : numpy.ndarray
        The amplitudes (1).
    per_replicate : numpy.ndarray
        Shape (replicates, 2, len(grid)): G′ and G″ of each replicate on the grid (Pa).

    Raises
    ------
    ValueError
        When the replicates share no range of amplitudes.
    """
    lo, hi = max(c[0][0] for c in curves), min(c[0][-1] for c in curves)
    grid = np.unique(np.concatenate([c[0] for c in curves]))
    grid = grid[(grid >= lo * (1 - 1e-12)) & (grid <= hi * (1 + 1e-12))]
    if len(grid) < 2:
        raise ValueError(f"measured: the replicates share no range of amplitudes (common range [{lo:g}, {hi:g}])")
    reps = []
    for A, gp, gpp in curves:
        W = _weights(A, grid)
        reps.append(np.stack([W @ gp, W @ gpp]))
    return grid, np.array(reps)


def _comparison(grid_m, A_s):
    lo, hi = max(grid_m[0], A_s[0]), min(grid_m[-1], A_s[-1])
    if not hi > lo:
        return None
    x = np.unique(np.concatenate([grid_m, A_s, [lo, hi]]))
    return x[(x >= lo) & (x <= hi)]


def _mismatch_and_scale(m, s):
    """m, s: arrays (..., 2, n) of G′ and G″ on the comparison points → (mismatch, scale) arrays (...)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        pm, ps = m[..., 0, :1], s[..., 0, :1]
        d = s / ps[..., None, :] - m / pm[..., None, :]
        mis = np.sqrt(np.mean(d.reshape(d.shape[:-2] + (-1,)) ** 2, axis=-1))
        scale = (pm / ps)[..., 0]
        bad = ~((pm[..., 0] > 0) & (ps[..., 0] > 0))
    return np.where(bad, np.nan, mis), np.where(bad, np.nan, scale)


def _boot_means(values_per_x, n_boot, rng, confidence):
    """Bootstrap means (B, n) of the runs at each x, Student-widened as sweep_summary widens them."""
    means = np.array([np.mean(v) for v in values_per_x])
    boot = np.empty((n_boot, len(values_per_x)))
    for j, v in enumerate(values_per_x):
        v = np.asarray(v, float)
        boot[:, j] = v[rng.integers(0, len(v), size=(n_boot, len(v)))].mean(axis=1)
    factor = _student_factor([len(v) for v in values_per_x], confidence)
    return means, _widen_log(boot, means, factor)


def _interval(samples, confidence):
    s = np.asarray(samples, float)
    s = s[np.isfinite(s)]
    if len(s) == 0:
        return (math.nan, math.nan)
    a = (1 - confidence) / 2
    return (float(np.quantile(s, a)), float(np.quantile(s, 1 - a)))


# ---------------------------------------------------------------------------------------------
# the calibration
# ---------------------------------------------------------------------------------------------
def calibrate(measured, sweep_dir, estimator="surface", n_boot=1000, seed=0, confidence=0.95):
    """Rank a simulated campaign's grid points against a measured amplitude sweep (module docstring).

    Parameters
    ----------
    measured : MeasuredTest or list of MeasuredTest
        The measured amplitude sweep (kind ``amplitude_sweep``: ``strain_amplitude`` absolute,
        ``Gp``, ``Gpp`` Pa), or several replicate samples.
    sweep_dir : str or os.PathLike
        The campaign: a sweep folder (or its ``results.csv``) with >= 2 amplitudes per grid point.
    estimator : {"surface", "internal"}, optional
        Which simulated moduli (plate forces, default, or stress tensor).
    n_boot : int, optional
        Bootstrap replicates, 1 … :data:`particleShear.analysis.sweep.N_BOOT_MAX` (default 1000).
    seed : int or None, optional
        Seed of the bootstrap (default 0: the same call gives the same intervals).
    confidence : float, optional
        Level of the intervals, in (0, 1) (default 0.95).

    Returns
    -------
    Calibration

    Raises
    ------
    ValueError
        A bad argument (named, with the allowed values), a measured sweep with fewer than 2
        amplitudes, a campaign with no grid point that overlaps it — all before the bootstrap.
    """
    curves = _check(measured, estimator, n_boot, confidence, seed)
    rows = read_sweep_table(sweep_dir)
    groups, varying, _ = group_runs(rows, estimator)
    grid, reps = measured_curve(curves)
    R = len(reps)
    rng = np.random.default_rng(seed)
    # measured replicates: resampled whole, their means Student-widened per grid amplitude
    m_mean = reps.mean(axis=0)
    if R > 1:
        idx = rng.integers(0, R, size=(n_boot, R))
        m_boot = reps[idx].mean(axis=1)                         # (B, 2, ng)
        factor = _student_factor([R] * reps.shape[2], confidence)
        m_boot = np.stack([_widen_log(m_boot[:, k, :], m_mean[k], factor) for k in range(2)], axis=1)
    else:
        m_boot = np.broadcast_to(m_mean, (n_boot,) + m_mean.shape)
    notes, points, simulated = [], [], {}
    for g in groups:
        A = np.asarray(g["amplitude"], float)
        label = ", ".join(f"{n}={g['parameters'].get(n, '')}" for n in varying) or "all runs"
        u = np.unique(A[A > 0])
        if len(u) < 2:
            notes.append(f"{label}: {len(u)} amplitude(s): left out")
            continue
        x = _comparison(grid, u)
        if x is None or len(x) < 2:
            notes.append(f"{label}: its amplitudes [{u[0]:g}, {u[-1]:g}] do not overlap the measured "
                         f"[{grid[0]:g}, {grid[-1]:g}]: left out")
            continue
        gp = [np.asarray(g["Gp"], float)[A == a] for a in u]
        gpp = [np.asarray(g["Gpp"], float)[A == a] for a in u]
        gp_mean, gp_boot = _boot_means(gp, n_boot, rng, confidence)
        gpp_mean, gpp_boot = _boot_means(gpp, n_boot, rng, confidence)
        Ws, Wm = _weights(u, x), _weights(grid, x)
        s_pt = np.stack([Ws @ gp_mean, Ws @ gpp_mean])
        s_bt = np.stack([gp_boot @ Ws.T, gpp_boot @ Ws.T], axis=1)
        m_pt = np.stack([Wm @ m_mean[0], Wm @ m_mean[1]])
        m_bt = np.einsum("bkn,xn->bkx", m_boot, Wm)
        mis, sc = _mismatch_and_scale(m_pt, s_pt)
        mis_b, sc_b = _mismatch_and_scale(m_bt, s_bt)
        try:
            E = float(g["parameters"].get("Young_modulus_spheres", "nan"))
        except ValueError:
            E = math.nan
        simulated[label] = {"A": u, "Gp": gp_mean, "Gpp": gpp_mean, "parameters": dict(g["parameters"])}
        points.append(dict(label=label, params=g["parameters"], mis=float(mis), sc=float(sc), mis_b=mis_b, sc_b=sc_b,
                           E=E, x=x, n_runs=len(A)))
    if not points:
        raise ValueError(f"sweep_dir={os.fspath(sweep_dir)!r} is invalid: no grid point with >= 2 amplitudes "
                         f"overlapping the measured range [{grid[0]:g}, {grid[-1]:g}]" +
                         (f" ({'; '.join(notes)})" if notes else ""))
    all_b = np.stack([np.where(np.isfinite(p["mis_b"]), p["mis_b"], np.inf) for p in points])   # (G, B)
    best_b = np.argmin(all_b, axis=0)
    out = []
    for i, p in enumerate(points):
        slo, shi = _interval(p["sc_b"], confidence)
        row = {"label": p["label"], **{n: p["params"].get(n, "") for n in varying},
               "mismatch": p["mis"],
               "p_best": float(np.mean(best_b == i)), "scale": p["sc"], "scale_ci_low": slo, "scale_ci_high": shi,
               "Young_modulus_spheres": p["E"], "E_to_use": p["sc"] * p["E"], "E_ci_low": slo * p["E"],
               "E_ci_high": shi * p["E"], "overlap_min": float(p["x"][0]), "overlap_max": float(p["x"][-1]),
               "n_points": len(p["x"]), "n_runs": p["n_runs"]}
        out.append(row)
    out.sort(key=lambda r: (not math.isfinite(r["mismatch"]), r["mismatch"]))
    for k, r in enumerate(out, 1):
        r["rank"] = k
    if R == 1:
        notes.append("one measured replicate: its sample-to-sample spread is not in the intervals")
    if len(out) > 1 and out[0]["p_best"] < 0.5:
        # the mismatch itself gets no interval: a resampled distance is biased upward (its percentile
        # interval can exclude the estimate); how often each point ranks first is the honest measure
        notes.append(f"the ranking is not resolved: {out[0]['label']} ranks first in {out[0]['p_best']:.0%} of the "
                     "bootstrap replicates only (more seeds or replicates, or more distinct grid points)")
    return Calibration(rows=out, varying=list(varying),
                       measured={"A": grid, "Gp": m_mean[0], "Gpp": m_mean[1], "replicates": R,
                                 "tests": [measured] if isinstance(measured, MeasuredTest) else list(measured)},
                       simulated=simulated,
                       settings={"estimator": estimator, "n_boot": int(n_boot), "confidence": float(confidence),
                                 "seed": seed, "sweep_dir": os.fspath(sweep_dir)},
                       notes=notes)


# ---------------------------------------------------------------------------------------------
# command line
# ---------------------------------------------------------------------------------------------
def _read_measured(path):
    """The amplitude sweeps of a measured file (:func:`particleShear.experiment.readers.read_rheometer`)."""
    got = read_rheometer(path)
    tests = [got] if isinstance(got, MeasuredTest) else list(got)
    sweeps = [t for t in tests if t.kind == "amplitude_sweep"]
    if not sweeps:
        raise ValueError(f"MEASURED={path!r} holds no amplitude sweep (kinds: {sorted({t.kind for t in tests})})")
    return sweeps


def build_parser():
    """Parser of ``particleShear calibrate``."""
    p = SuggestingParser(prog="particleShear calibrate",
                         description="Rank the grid points of a simulated campaign (sweep folder DIR) by how well "
                                     "their normalised amplitude sweeps (G'/G'_p, G''/G'_p against the strain "
                                     "amplitude) match a measured one, and give the Young modulus that matches the "
                                     "plateau, with bootstrap intervals (docs/experiment.md).")
    p.add_argument("measured", metavar="MEASURED", nargs="+",
                   help="measured file(s) with an amplitude sweep; several files are replicate samples")
    p.add_argument("folder", metavar="DIR", help="sweep folder of the simulated campaign (results.csv)")
    p.add_argument("--estimator", choices=("surface", "internal"), default="surface")
    p.add_argument("--n-boot", type=int, default=1000, help="bootstrap replicates (default 1000)")
    p.add_argument("--seed", type=int, default=0, help="bootstrap seed (default 0)")
    p.add_argument("--out", metavar="OUT", default=None,
                   help="folder for calibration.csv and calibration.png (default DIR)")
    return p


def main(argv=None):
    """``particleShear calibrate MEASURED… DIR [--estimator] [--n-boot] [--seed] [--out OUT]``.

    Prints the ranking, writes ``calibration.csv`` and (with matplotlib) ``calibration.png``.

    Parameters
    ----------
    argv : list of str, optional
        The arguments after ``calibrate``.

    Returns
    -------
    int
        0 done, 2 invalid input (one line on stderr).
    """
    args = build_parser().parse_args(argv)
    prog = "particleShear calibrate"
    try:
        if args.n_boot < 1:
            raise ValueError(f"--n-boot={args.n_boot} is invalid: allowed an integer >= 1")
        if args.seed < 0:
            raise ValueError(f"--seed={args.seed} is invalid: allowed an integer >= 0")
        for path in args.measured:
            if not os.path.isfile(path):
                raise ValueError(f"MEASURED={path!r} is invalid: no such file")
        tests = [t for path in args.measured for t in _read_measured(path)]
        cal = calibrate(tests, args.folder, estimator=args.estimator, n_boot=args.n_boot, seed=args.seed)
    except (ValueError, OSError) as exc:
        msg = str(exc).replace("sweep_dir=", "DIR=").replace("folder_or_csv=", "DIR=").replace("n_boot=", "--n-boot=")
        print(f"{prog}: {msg}".splitlines()[0], file=sys.stderr)
        return 2
    folder = args.folder if os.path.isdir(args.folder) else os.path.dirname(os.path.abspath(args.folder))
    out = args.out or folder
    os.makedirs(out, exist_ok=True)
    print(cal.table_text())
    print(f"wrote {cal.write_csv(os.path.join(out, 'calibration.csv'))}")
    if _has_matplotlib():
        path = os.path.join(out, "calibration.png")
        plot_calibration(cal, path=path)
        print(f"wrote {path}")
    else:
        print(f"{prog}: note: no figure: matplotlib is not installed (pip install 'particleShear[plot]')",
              file=sys.stderr)
    return 0
