"""The package's analysis on measured tests (:class:`~.tables.MeasuredTest`), and ``analyse FILE…``.

Each function hands the measured columns (SI units) to the analysis the simulations use; none
has a rule of its own beyond pooling replicate points:

* :func:`amplitude_sweep_summary` — :func:`particleShear.analysis.sweep.sweep_summary` (plateau,
  linear limits, flow point, the R package's points, bootstrap intervals); the replicate samples
  (several tests or files measured at the same amplitudes) are its seeds.
* :func:`frequency_sweep_table` — mean G′, G″ per frequency over replicates, |G*|, tan δ, |η*|.
* :func:`measured_laos` — :func:`particleShear.analysis.laos.laos` of a raw strain/stress waveform.
* :func:`flow_curve_fit` — :func:`particleShear.analysis.flow_curve.herschel_bulkley_bootstrap`
  (replicate flow curves are its seeds).
* :func:`relaxation_summary`, :func:`creep_summary` — the plateau and final-rate rules of
  :mod:`particleShear.analysis.rheometry` that the simulated relaxation and creep runs use
  (:func:`particleShear.run.rheometer_analysis.analyse_record`).

Replicates rarely hit exactly the same amplitude (rate, frequency): points of different tests
whose values lie within a relative ``rtol`` (default 2 %) of the first of a group are pooled
at the geometric mean of the group.

:func:`analyse_files` reads files (:func:`~.readers.read_rheometer`), analyses every test and
writes ``<file stem>_analysis.csv`` next to each file (or into ``out``); :func:`main` is
``particleShear analyse FILE… `` (:mod:`particleShear.analysis.cli` hands it a command line
whose paths are files).
"""
__docformat__ = "numpy"
import math
import os
import sys
import warnings

import numpy as np

from ..analysis.flow_curve import herschel_bulkley_bootstrap
from ..analysis.laos import laos
from ..analysis.rheometry import final_rate, plateau
from ..analysis.sweep import CHARACTERISTICS, sweep_summary
from ..sweep.table import atomic_text, row_line
from .readers import read_rheometer
from .tables import KINDS

__all__ = ["ANALYSIS_COLUMNS", "amplitude_sweep_summary", "analyse_files", "analyse_tests", "creep_summary",
           "flow_curve_fit", "frequency_sweep_table", "main", "measured_laos", "relaxation_summary"]

#: columns of the table :func:`analyse_files` writes: name → (unit, description)
ANALYSIS_COLUMNS = {
    "source": ("", "the file (several, ';'-separated, for pooled replicates)"),
    "test": ("", "the test (interval, step) of the file, or 'pooled'"),
    "kind": ("", "the kind of test (experiment.tables.KINDS)"),
    "n_tests": ("1", "tests pooled (replicates)"),
    "quantity": ("", "what is summarised"),
    "value": ("unit", "its value (empty: undefined)"),
    "ci_low": ("unit", "lower end of its interval (bootstrap percentile; empty: none)"),
    "ci_high": ("unit", "upper end of its interval"),
    "unit": ("", "unit of value, ci_low, ci_high ('1': dimensionless)"),
    "flag": ("", "analysis.sweep.FLAGS for an amplitude sweep, 'degenerate_fit' for a flow curve, else 'ok'"),
}


def _tests_of(tests, kind):
    tests = [tests] if hasattr(tests, "kind") else list(tests)
    if not tests:
        raise ValueError(f"tests is empty: allowed one or more {kind} tests")
    for t in tests:
        if t.kind != kind:
            raise ValueError(f"a {t.kind} test ({t.meta.get('name', '')!r}) among the {kind} tests")
    return [t.finite() for t in tests]


def _pool(values, rtol):
    """Values → the geometric mean of their group (sorted values within ``rtol`` of the group's first)."""
    v = np.asarray(values, float)
    order = np.argsort(v, kind="stable")
    out = np.empty_like(v)
    start = 0
    while start < len(order):
        end = start + 1
        while end < len(order) and v[order[end]] <= v[order[start]] * (1 + rtol):
            end += 1
        group = order[start:end]
        out[group] = math.exp(np.mean(np.log(v[group]))) if (v[group] > 0).all() else v[group].mean()
        start = end
    return out


def _check_rtol(rtol):
    if isinstance(rtol, bool) or not isinstance(rtol, (int, float)) or not 0 <= rtol < 1:
        raise ValueError(f"rtol={rtol!r} is out of range: allowed 0 <= rtol < 1")
    return float(rtol)


def amplitude_sweep_summary(tests, n_boot=2000, confidence=0.95, rng=0, rtol=0.02):
    """:func:`~particleShear.analysis.sweep.sweep_summary` of measured amplitude sweeps.

    Parameters
    ----------
    tests : MeasuredTest or list of MeasuredTest
        Amplitude sweeps (replicate samples: their points at one amplitude are the seeds there).
    n_boot : int, optional
        Bootstrap replicates (default 2000).
    confidence : float, optional
        Level of the intervals (default 0.95).
    rng : None, int or numpy.random.Generator, optional
        Source of the resampling (default 0: reproducible).
    rtol : float, optional
        Amplitudes of different tests within this relative distance are one amplitude (default 0.02).

    Returns
    -------
    particleShear.analysis.sweep.SweepSummary
        Amplitudes absolute, moduli in Pa.

    Raises
    ------
    ValueError
        A test of another kind, or as ``sweep_summary``.
    """
    tests = _tests_of(tests, "amplitude_sweep")
    rtol = _check_rtol(rtol)
    A = np.concatenate([t["strain_amplitude"] for t in tests])
    gp = np.concatenate([t["Gp"] for t in tests])
    gpp = np.concatenate([t["Gpp"] for t in tests])
    return sweep_summary(_pool(A, rtol), gp, gpp, n_boot=n_boot, confidence=confidence, rng=rng)


def frequency_sweep_table(tests, rtol=0.02):
    """Mean G′, G″ of measured frequency sweeps per frequency, with |G*|, tan δ and |η*|.

    Parameters
    ----------
    tests : MeasuredTest or list of MeasuredTest
        Frequency sweeps (replicates are averaged at each frequency).
    rtol : float, optional
        Frequencies of different tests within this relative distance are one (default 0.02).

    Returns
    -------
    dict of numpy.ndarray
        Sorted by frequency: ``angular_frequency`` (rad/s), ``frequency`` (Hz), ``n`` (points
        averaged), ``Gp``, ``Gpp``, ``Gp_sd``, ``Gpp_sd`` (Pa; standard deviation over the
        replicates, NaN for one), ``G_star`` = hypot(G′, G″) (Pa), ``tan_delta`` = G″/G′ (1),
        ``eta_star`` = |G*|/ω (Pa·s).
    """
    tests = _tests_of(tests, "frequency_sweep")
    rtol = _check_rtol(rtol)
    w = _pool(np.concatenate([t["angular_frequency"] for t in tests]), rtol)
    gp = np.concatenate([t["Gp"] for t in tests])
    gpp = np.concatenate([t["Gpp"] for t in tests])
    ws, inv = np.unique(w, return_inverse=True)
    n = np.bincount(inv)
    mean_p, mean_pp = np.bincount(inv, gp) / n, np.bincount(inv, gpp) / n

    def sd(x, m):
        var = np.bincount(inv, (x - m[inv]) ** 2) / np.maximum(n - 1, 1)
        return np.where(n > 1, np.sqrt(var), np.nan)
    gstar = np.hypot(mean_p, mean_pp)
    with np.errstate(divide="ignore", invalid="ignore"):
        tan = mean_pp / mean_p
    return {"angular_frequency": ws, "frequency": ws / (2 * math.pi), "n": n, "Gp": mean_p, "Gpp": mean_pp,
            "Gp_sd": sd(gp, mean_p), "Gpp_sd": sd(gpp, mean_pp), "G_star": gstar, "tan_delta": tan,
            "eta_star": gstar / ws}


def measured_laos(test, f=None, n_max=15):
    """:func:`~particleShear.analysis.laos.laos` of a measured raw waveform.

    Parameters
    ----------
    test : MeasuredTest
        A ``laos`` test (time in s, strain absolute, stress in Pa).
    f : float, optional
        Excitation frequency (Hz); default ``meta["omega"]/2π`` (RepTate's ``omega=``, rad/s) or
        ``meta["frequency"]`` (Hz).
    n_max : int, optional
        Highest harmonic fitted (default 15).

    Returns
    -------
    particleShear.analysis.laos.LaosResult

    Raises
    ------
    ValueError
        Not a laos test, no frequency known, or as ``laos``.
    """
    test = _tests_of(test, "laos")[0]
    if f is None:
        if "omega" in test.meta:
            f = float(test.meta["omega"]) / (2 * math.pi)
        elif "frequency" in test.meta:
            f = float(test.meta["frequency"])
        else:
            raise ValueError(f"the laos test {test.meta.get('name', '')!r} gives no frequency (meta omega in rad/s "
                             "or frequency in Hz): give f= (Hz)")
    return laos(test["time"], test["strain"], test["stress"], f, n_max=n_max)


def flow_curve_fit(tests, n_boot=2000, confidence=0.95, rng=0, rtol=0.02):
    """Herschel–Bulkley fit (:func:`~particleShear.analysis.flow_curve.herschel_bulkley_bootstrap`) of measured flow curves.

    Parameters
    ----------
    tests : MeasuredTest or list of MeasuredTest
        Flow curves (shear rate in 1/s, stress in Pa); each replicate is one seed.
    n_boot : int, optional
        Bootstrap replicates (default 2000).
    confidence : float, optional
        Level of the intervals (default 0.95).
    rng : None, int or numpy.random.Generator, optional
        Source of the resampling (default 0).
    rtol : float, optional
        Rates of different tests within this relative distance are one rate (default 0.02).

    Returns
    -------
    particleShear.analysis.flow_curve.FlowCurveFit
        σ_y (Pa), K (Pa·sⁿ), n with intervals.
    """
    tests = _tests_of(tests, "flow_curve")
    rtol = _check_rtol(rtol)
    rates = _pool(np.concatenate([t["shear_rate"] for t in tests]), rtol)
    grid = np.unique(rates)
    table = np.full((len(grid), len(tests)), np.nan)
    start = 0
    for j, t in enumerate(tests):
        r = rates[start:start + len(t)]
        start += len(t)
        for k in range(len(grid)):
            hit = r == grid[k]
            if hit.any():
                table[k, j] = t["stress"][hit].mean()
    return herschel_bulkley_bootstrap(grid, table, n_boot=n_boot, confidence=confidence, rng=rng)


def relaxation_summary(test, fraction=0.2):
    """The relaxation modulus's plateau (:func:`particleShear.analysis.rheometry.plateau`) of a measured test.

    Parameters
    ----------
    test : MeasuredTest
        A ``relaxation`` test (time in s, G in Pa).
    fraction : float, optional
        Last part of the time span averaged (default 0.2, as the simulated relaxation runs).

    Returns
    -------
    dict
        ``G_plateau`` and ``G_plateau_se`` (Pa; blocked mean and standard error), ``G_initial``
        (Pa, G at the first time), ``t_first``, ``t_last`` (s), ``n_points``.
    """
    test = _tests_of(test, "relaxation")[0]
    t, G = test["time"], test["G"]
    ba = plateau(t, G, fraction)
    return {"G_plateau": float(ba.mean), "G_plateau_se": float(ba.sem), "G_initial": float(G[0]),
            "t_first": float(t[0]), "t_last": float(t[-1]), "n_points": len(t)}


def creep_summary(test, fraction=0.2):
    """Final creep rate, viscosity and strain plateau of a measured creep test (:mod:`particleShear.analysis.rheometry`).

    Parameters
    ----------
    test : MeasuredTest
        A ``creep`` test (time in s, strain absolute; ``meta["stress"]`` in Pa for the viscosity
        and compliance).
    fraction : float, optional
        Last part of the time span fitted and averaged (default 0.2).

    Returns
    -------
    dict
        ``creep_rate``, ``creep_rate_se`` (1/s, :func:`~particleShear.analysis.rheometry.final_rate`),
        ``creep_viscosity`` (Pa·s, stress / rate; inf for a rate <= 0, NaN without a stress),
        ``strain_plateau``, ``strain_plateau_se`` (1, :func:`~particleShear.analysis.rheometry.plateau`),
        ``compliance_final`` (1/Pa, last strain / stress; NaN without a stress), ``stress`` (Pa).
    """
    test = _tests_of(test, "creep")[0]
    t, g = test["time"], test["strain"]
    s0 = float(test.meta.get("stress", math.nan))
    rate, rate_se = final_rate(t, g, fraction)
    ba = plateau(t, g, fraction)
    visc = (s0 / rate if rate > 0 else math.inf) if math.isfinite(s0) else math.nan
    return {"creep_rate": float(rate), "creep_rate_se": float(rate_se), "creep_viscosity": float(visc),
            "strain_plateau": float(ba.mean), "strain_plateau_se": float(ba.sem),
            "compliance_final": float(g[-1] / s0) if math.isfinite(s0) and s0 else math.nan, "stress": s0}


# ------------------------------------------------------------------------------------------------------------------
def _row(tests, quantity, value, unit, lo=math.nan, hi=math.nan, flag="ok"):
    pooled = len(tests) > 1
    return {"source": ";".join(dict.fromkeys(str(t.meta.get("source", "")) for t in tests)),
            "test": "pooled" if pooled else str(tests[0].meta.get("name", "")), "kind": tests[0].kind,
            "n_tests": len(tests), "quantity": quantity, "value": float(value), "ci_low": float(lo),
            "ci_high": float(hi), "unit": unit, "flag": flag}


def _analyse_group(tests, n_boot, confidence, seed):
    """Rows and notes of one group of tests of one kind."""
    kind, rows, notes = tests[0].kind, [], []
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", UserWarning)
        if kind == "amplitude_sweep":
            s = amplitude_sweep_summary(tests, n_boot=n_boot, confidence=confidence, rng=seed)
            d = s.to_dict()
            rows.append(_row(tests, "n_amplitudes", d["n_amplitudes"], "1"))
            for name, (unit, _) in CHARACTERISTICS.items():
                rows.append(_row(tests, name, d[name], unit, d[name + "_ci_low"], d[name + "_ci_high"],
                                 d[name + "_flag"]))
        elif kind == "frequency_sweep":
            tab = frequency_sweep_table(tests)
            i0 = 0
            rows += [_row(tests, "n_frequencies", len(tab["angular_frequency"]), "1"),
                     _row(tests, "omega_min", tab["angular_frequency"][i0], "rad/s"),
                     _row(tests, "omega_max", tab["angular_frequency"][-1], "rad/s"),
                     _row(tests, "Gp_at_omega_min", tab["Gp"][i0], "Pa"),
                     _row(tests, "Gpp_at_omega_min", tab["Gpp"][i0], "Pa"),
                     _row(tests, "tan_delta_at_omega_min", tab["tan_delta"][i0], "1"),
                     _row(tests, "Gp_at_omega_max", tab["Gp"][-1], "Pa"),
                     _row(tests, "Gpp_at_omega_max", tab["Gpp"][-1], "Pa")]
        elif kind == "flow_curve":
            fit = flow_curve_fit(tests, n_boot=n_boot, confidence=confidence, rng=seed)
            flag = "degenerate_fit" if fit.degenerate else "ok"
            for name, unit in (("sigma_y", "Pa"), ("K", "Pa·s^n"), ("n", "1")):
                lo, hi = fit.intervals[name]
                rows.append(_row(tests, name, getattr(fit.fit, name), unit, lo, hi, flag))
            if fit.degenerate:
                notes.append(f"Herschel-Bulkley fit degenerate: {fit.degenerate}")
        elif kind == "relaxation":
            for t in tests:
                r = relaxation_summary(t)
                se = r["G_plateau_se"]
                rows += [_row([t], "G_plateau", r["G_plateau"], "Pa", max(r["G_plateau"] - 2 * se, 0.0),
                               r["G_plateau"] + 2 * se),
                         _row([t], "G_initial", r["G_initial"], "Pa"), _row([t], "t_last", r["t_last"], "s")]
        elif kind == "creep":
            for t in tests:
                r = creep_summary(t)
                rows += [_row([t], "creep_rate", r["creep_rate"], "1/s", r["creep_rate"] - 2 * r["creep_rate_se"],
                              r["creep_rate"] + 2 * r["creep_rate_se"]),
                         _row([t], "creep_viscosity", r["creep_viscosity"], "Pa·s"),
                         _row([t], "strain_plateau", r["strain_plateau"], "1"),
                         _row([t], "compliance_final", r["compliance_final"], "1/Pa")]
        elif kind == "laos":
            for t in tests:
                r = measured_laos(t)
                rows += [_row([t], "strain_amplitude", r.strain_amplitude, "1"), _row([t], "frequency", r.frequency, "Hz"),
                         _row([t], "Gp1", r.Gp[0], "Pa"), _row([t], "Gpp1", r.Gpp[0], "Pa"),
                         _row([t], "G_M", r.G_M, "Pa"), _row([t], "G_L", r.G_L, "Pa"),
                         _row([t], "eta_M", r.eta_M, "Pa·s"), _row([t], "eta_L", r.eta_L, "Pa·s"),
                         _row([t], "S", r.S, "1"), _row([t], "T", r.T, "1"), _row([t], "I3_I1", r.I3_I1, "1"),
                         _row([t], "Q", r.Q, "1")]
    notes += [" ".join(str(w.message).split()) for w in caught]
    return rows, notes


def analyse_tests(tests, pool=False, n_boot=2000, confidence=0.95, seed=0):
    """Summaries of measured tests, one long table (:data:`ANALYSIS_COLUMNS`).

    Parameters
    ----------
    tests : list of MeasuredTest
        The tests.
    pool : bool, optional
        Treat the amplitude sweeps, the frequency sweeps and the flow curves as replicates of one
        sample each (pooled, intervals over them); default False: each test alone.
    n_boot : int, optional
        Bootstrap replicates (default 2000).
    confidence : float, optional
        Level of the intervals (default 0.95; the relaxation and creep intervals are ± 2 standard
        errors).
    seed : int or None, optional
        Seed of the bootstrap (default 0).

    Returns
    -------
    rows : list of dict
        Rows with the columns of :data:`ANALYSIS_COLUMNS`.
    notes : list of str
        Warnings of the analyses (one replicate: zero-width intervals, …), prefixed by the test.
    """
    groups = []
    if pool:
        by_kind = {}
        for t in tests:
            if t.kind in ("amplitude_sweep", "frequency_sweep", "flow_curve"):
                by_kind.setdefault(t.kind, []).append(t)
            else:
                groups.append([t])
        groups = list(by_kind.values()) + groups
    else:
        groups = [[t] for t in tests]
    rows, notes = [], []
    for g in groups:
        r, n = _analyse_group(g, n_boot, confidence, seed)
        rows += r
        label = "pooled " + g[0].kind if len(g) > 1 else str(g[0].meta.get("name", g[0].kind))
        notes += [f"{label}: {x}" for x in dict.fromkeys(n)]
    return rows, notes


def _write(path, rows):
    cols = list(ANALYSIS_COLUMNS)
    with atomic_text(path) as fh:
        fh.write(row_line({c: c for c in cols}, cols))
        for r in rows:
            fh.write(row_line({k: (None if isinstance(v, float) and not math.isfinite(v) else v)
                               for k, v in r.items()}, cols))


def analyse_files(paths, out=None, kind=None, units=None, pool=False, n_boot=2000, confidence=0.95, seed=0):
    """Read measured files (:func:`~.readers.read_rheometer`), analyse every test, write the tables.

    Parameters
    ----------
    paths : list of str
        Measured files.
    out : str, optional
        Folder for the tables (created); default next to each file.
    kind : str, optional
        The kind of every test (default: read from the columns).
    units : dict, optional
        Units of columns that the files do not state (``{"Shear Strain": "%"}``).
    pool : bool, optional
        Pool the sweeps and flow curves of all files as replicates (:func:`analyse_tests`); the
        table is then ``measured_analysis.csv`` in ``out`` or the first file's folder.
    n_boot : int, optional
        Bootstrap replicates (default 2000).
    confidence : float, optional
        Level of the intervals (default 0.95).
    seed : int or None, optional
        Seed of the bootstrap (default 0).

    Returns
    -------
    dict
        ``rows`` (all rows), ``notes``, ``written`` (paths of the tables), ``tests`` (the tests read).

    Raises
    ------
    ValueError
        As :func:`~.readers.read_rheometer` and the analyses.
    """
    read = [(p, read_rheometer(p, kind=kind, units=units)) for p in paths]
    if out is not None:
        os.makedirs(out, exist_ok=True)
    all_rows, notes, written = [], [], []
    if pool:
        tests = [t for _, ts in read for t in ts]
        rows, notes = analyse_tests(tests, pool=True, n_boot=n_boot, confidence=confidence, seed=seed)
        target = os.path.join(out or os.path.dirname(os.path.abspath(paths[0])), "measured_analysis.csv")
        _write(target, rows)
        all_rows, written = rows, [target]
    else:
        for p, ts in read:
            rows, n = analyse_tests(ts, n_boot=n_boot, confidence=confidence, seed=seed)
            stem = os.path.splitext(os.path.basename(p))[0] + "_analysis.csv"
            target = os.path.join(out or os.path.dirname(os.path.abspath(p)), stem)
            _write(target, rows)
            all_rows += rows
            notes += n
            written.append(target)
    return {"rows": all_rows, "notes": notes, "written": written, "tests": [t for _, ts in read for t in ts]}


def _fmt(v):
    return "–" if not (isinstance(v, (int, float)) and math.isfinite(v)) else f"{v:.4g}"


def _human(rows):
    lines, last = [], None
    for r in rows:
        head = (r["source"], r["test"], r["kind"])
        if head != last:
            lines.append(f"{os.path.basename(r['source']) if ';' not in r['source'] else r['source']} — "
                         f"{r['test']} ({r['kind']}, {r['n_tests']} test(s))")
            last = head
        ci = f" [{_fmt(r['ci_low'])}, {_fmt(r['ci_high'])}]" if math.isfinite(r["ci_low"]) else ""
        flag = f" ({r['flag']})" if r["flag"] != "ok" else ""
        lines.append(f"  {r['quantity']:<26} {_fmt(r['value'])}{ci} {r['unit']}{flag}")
    return "\n".join(lines) + "\n"


def main(argv):
    """``particleShear analyse FILE… [--out DIR] [--kind K] [--units NAME=UNIT …] [--pool] [--json] [--n-boot N]
    [--confidence C] [--seed S]``: measured rheometer files.

    Parameters
    ----------
    argv : list of str
        The arguments after ``analyse``.

    Returns
    -------
    int
        0 written; 2 invalid input (message on stderr naming file, line and column).
    """
    import argparse
    import json

    p = argparse.ArgumentParser(prog="particleShear analyse", description="Analyse measured rheometer files "
                                "(RheoCompass, TRIOS, RepTate, CSV/TSV): a summary per test with units, written "
                                "to FILE_analysis.csv next to each file or into --out.")
    p.add_argument("files", nargs="+", metavar="FILE")
    p.add_argument("--out", metavar="DIR", default=None, help="folder for the tables (default: next to each file)")
    p.add_argument("--kind", choices=sorted(KINDS), default=None, help="the kind of every test (default: from the "
                   "columns)")
    p.add_argument("--units", metavar="NAME=UNIT", action="append", default=[],
                   help="the unit of a column the file does not state, e.g. --units 'Shear Strain=%%'")
    p.add_argument("--pool", action="store_true", help="pool the sweeps and flow curves of all files as replicates")
    p.add_argument("--json", action="store_true", help="print the rows as JSON")
    p.add_argument("--n-boot", type=int, default=2000, metavar="N")
    p.add_argument("--confidence", type=float, default=0.95, metavar="C")
    p.add_argument("--seed", type=int, default=0, metavar="S")
    try:
        args = p.parse_args(argv)
    except SystemExit as exc:
        return int(exc.code or 0) and 2
    units = {}
    for u in args.units:
        if "=" not in u:
            print(f"particleShear analyse: --units {u!r} is invalid: allowed NAME=UNIT", file=sys.stderr)
            return 2
        k, v = u.rsplit("=", 1)
        units[k] = v
    try:
        res = analyse_files(args.files, out=args.out, kind=args.kind, units=units or None, pool=args.pool,
                            n_boot=args.n_boot, confidence=args.confidence, seed=args.seed)
    except (ValueError, OSError) as exc:
        print(f"particleShear analyse: {' '.join(str(exc).split())}", file=sys.stderr)
        return 2
    for note in res["notes"]:
        print(f"particleShear analyse: note: {note}", file=sys.stderr)
    if args.json:
        print(json.dumps([{k: (None if isinstance(v, float) and not math.isfinite(v) else v) for k, v in r.items()}
                          for r in res["rows"]], ensure_ascii=False))
    else:
        sys.stdout.write(_human(res["rows"]))
        for w in res["written"]:
            print(f"wrote {w}")
    return 0
