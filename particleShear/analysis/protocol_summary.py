"""The summaries ``python -m particleShear analyse`` gives of the steady, relaxation and creep runs of a folder.

Rows of these protocols hold one summary of one run (docs/protocols.md), no G′ and G″.  They are
grouped as the oscillatory rows are (:func:`particleShear.analysis.grouping.measured_row`: the
protocol and the parameters it reads split groups; only seeds are pooled), except that the rate
``relative_rate`` of a steady run does not split its group: a steady group is a flow curve.

``steady``
    The Herschel–Bulkley fit of the group's flow curve
    (:func:`particleShear.analysis.flow_curve.fit_flow_curve`): ``sigma_y`` (Pa), ``K`` (Pa·sⁿ),
    ``n`` with their bootstrap intervals over the seeds; it needs finished runs at >= 3 rates.  A
    fit with a parameter on a bound of the law is flagged ``degenerate_fit``, the reasons in
    ``note`` (:attr:`particleShear.analysis.flow_curve.HerschelBulkley.degenerate`).
``relaxation``
    ``G_plateau_<estimator>`` (Pa) and ``residual_stress`` (Pa): the mean over the runs with the
    percentile bootstrap interval of the mean (of a modulus on the log scale,
    :func:`particleShear.analysis.sweep.modulus_interval`: >= 0, none for a mean <= 0).
``creep``
    ``creep_rate`` (1/s), ``creep_viscosity`` (Pa·s), ``strain_plateau`` and ``residual_stress``
    (Pa), likewise.

The table is long: one row per group and quantity (:data:`COLUMNS` before the parameters that
differ between groups are put after ``protocol``).
"""
__docformat__ = "numpy"
import math
import zlib

import numpy as np

from ..protocols import PROTOCOLS
from .flow_curve import fit_flow_curve
from .grouping import SUMMARY_PROTOCOLS, measured_row, row_protocol, short_value
from .sweep import modulus_interval
from .verdicts import counts_note, verdict_counts

__all__ = ["COLUMNS", "FLAGS", "QUANTITIES", "protocol_summaries", "summary_columns"]

#: the ``flag`` of a row of ``analysis_protocols.csv`` → meaning
FLAGS = {"ok": "a value with its interval",
         "degenerate_fit": ("a Herschel-Bulkley parameter on a bound of the law (sigma_y = 0, n = 2 or n near 0): the "
                            "fit does not describe the flow curve; the reasons are in note"),
         "non_positive": "a modulus whose mean is <= 0: the value, no interval (a modulus interval is >= 0)",
         "undefined": "no value (no finished run, or no fit)"}

#: the quantities summarised per protocol: name (``{est}`` the estimator) → unit (each protocol's
#: ``quantities``, :mod:`particleShear.protocols`)
QUANTITIES = {name: dict(p.quantities) for name, p in PROTOCOLS.items() if p.quantities}

#: columns of ``analysis_protocols.csv``: name → (type, unit, description); the varying parameters
#: follow ``protocol``
COLUMNS = {
    "group": ("str", "", "the group: its parameters that differ between the groups of the folder"),
    "protocol": ("str", "", "the protocol of the group's runs: steady, relaxation or creep"),
    "quantity": ("str", "", ("what is summarised: a column of results.csv (mean over the runs) or, for steady "
                             "runs, a parameter of the Herschel-Bulkley fit sigma_y + K*rate^n of the flow curve")),
    "unit": ("str", "", "unit of value, ci_low, ci_high"),
    "estimator": ("str", "", "the stress used: surface (plate forces) or internal (overall stress tensor)"),
    "n_runs": ("int", "1", "finished runs (status ok, finite value) of the group that count"),
    "n_flagged": ("int", "1", "runs of the group (status ok) whose verdict is flagged (docs/analysis.md \"Verdicts\")"),
    "n_failed": ("int", "1", "runs of the group whose status is not ok"),
    "n_rates": ("int", "1", "distinct rates with a finished run (steady groups; empty otherwise)"),
    "value": ("float", "", "the mean over the runs, or the fitted parameter (unit: column unit; empty: undefined)"),
    "ci_low": ("float", "", "lower end of the bootstrap percentile interval (level: confidence)"),
    "ci_high": ("float", "", "upper end of the bootstrap percentile interval (level: confidence)"),
    "confidence": ("float", "1", "level of the bootstrap percentile intervals"),
    "n_boot": ("int", "1", "bootstrap replicates (runs, or whole flow curves, resampled with replacement)"),
    "bootstrap_seed": ("int", "1", "--seed of the bootstrap (empty: fresh entropy, not reproducible)"),
    "flag": ("str", "", "what the value is: one of ok, degenerate_fit, non_positive, undefined "
                        "(analysis.protocol_summary.FLAGS)"),
    "note": ("str", "", "what deserves a look: one run (degenerate interval), runs left out, no fit, why a fit is "
                        "degenerate"),
}

_CHUNK = 20_000     # bootstrap replicates drawn at once (memory: chunk × runs indices)


def _float(text):
    try:
        v = float(text)
    except (TypeError, ValueError):
        return math.nan
    return v


def _mean_interval(values, n_boot, confidence, rng, modulus=False):
    """(mean, low, high) of ``values`` with the percentile bootstrap interval of the mean; of a modulus
    (``modulus=True``) by :func:`particleShear.analysis.sweep.modulus_interval` (>= 0; NaN for a mean <= 0)."""
    v = np.asarray(values, dtype=float)
    n = len(v)
    means = np.empty(n_boot)
    for start in range(0, n_boot, _CHUNK):   # bounded memory whatever the number of runs
        stop = min(n_boot, start + _CHUNK)
        means[start:stop] = v[rng.integers(0, n, size=(stop - start, n))].mean(axis=1)
    if modulus:
        return (float(v.mean()),) + modulus_interval(means, float(v.mean()), confidence)
    q = (1 - confidence) / 2
    return float(v.mean()), float(np.quantile(means, q)), float(np.quantile(means, 1 - q))


def summary_columns(varying):
    """Columns of ``analysis_protocols.csv``: ``{name: (type, unit, description)}`` in table order.

    Parameters
    ----------
    varying : list of str
        The parameter columns that differ between the groups.

    Returns
    -------
    dict
    """
    cols = {"group": COLUMNS["group"], "protocol": COLUMNS["protocol"]}
    for name in varying:
        if name != "protocol":
            cols[name] = ("str", "", f"parameter {name} of doParticleShearSimulation (docs/parameters.md), as in "
                                     "results.csv")
    cols.update({k: v for k, v in COLUMNS.items() if k not in cols})
    return cols


def protocol_summaries(rows, names, estimator="surface", n_boot=2000, confidence=0.95, seed=None):
    """The summaries of the steady, relaxation and creep runs of a results table (module docstring).

    Parameters
    ----------
    rows : list of dict
        Rows of ``results.csv`` (text cells); rows of other protocols are ignored.
    names : list of str
        The parameter columns that may split groups (those of the table, less the ones that
        change neither the physics nor the output).
    estimator : {"surface", "internal"}, optional
        Which stress (default "surface").
    n_boot : int, optional
        Bootstrap replicates (checked by the caller).
    confidence : float, optional
        Level of the intervals.
    seed : int or None, optional
        Seed of the bootstrap: each group's stream is derived from it and the group's parameters.

    Returns
    -------
    out : list of dict
        One row per group and quantity (keys: :func:`summary_columns`).
    varying : list of str
        The parameter columns that differ between the groups.
    """
    cells = {}
    for row in rows:
        proto = row_protocol(row)
        if proto not in SUMMARY_PROTOCOLS:
            continue
        q = measured_row(row)
        key = tuple((c, str(q.get(c, ""))) for c in names if not (proto == "steady" and c == "relative_rate"))
        cells.setdefault(key, []).append(q)
    if not cells:
        return [], []
    keys = sorted(cells, key=lambda k: [(0, _float(v), "") if math.isfinite(_float(v)) else (1, 0.0, v)
                                        for _, v in k])
    varying = [c for c in names if len({dict(k).get(c) for k in keys}) > 1]
    out = []
    for key in keys:
        params = dict(key)
        proto = row_protocol(params)
        # a protocol's parameters only (the cells another protocol's rows fill are empty here)
        label = ", ".join(f"{n}={short_value(params[n])}" for n in varying if params.get(n, "") != "") \
            or f"protocol={proto}"
        stream = "\x1f".join(f"{k}={v}" for k, v in sorted(params.items()) if v != "")
        rng = np.random.default_rng(None if seed is None else [int(seed), zlib.crc32(stream.encode("utf-8"))])
        base = {"group": label, "protocol": proto, "estimator": estimator, "confidence": confidence,
                "n_boot": n_boot, "bootstrap_seed": seed}
        base.update({n: params.get(n, "") for n in varying if n != "protocol"})
        group = cells[key]
        ok = [r for r in group if str(r.get("status", "")).strip() == "ok"]
        n_failed, n_flagged, flags = verdict_counts(group)
        base.update(n_flagged=n_flagged, n_failed=n_failed)
        first = len(out)
        if proto == "steady":
            out.extend(_steady(group, ok, base, estimator, n_boot, confidence, rng, fit_flow_curve))
        else:
            out.extend(_quantities(proto, group, ok, base, estimator, n_boot, confidence, rng))
        counted = counts_note(len(ok), n_failed, n_flagged, flags)
        for row in out[first:]:
            row["note"] = "; ".join(x for x in (counted, row["note"]) if x)
    return out, varying


def _quantities(proto, group, ok, base, estimator, n_boot, confidence, rng):
    """The rows of one relaxation or creep group: the mean of each quantity with its interval."""
    out = []
    for pattern, unit in QUANTITIES[proto].items():
        name = pattern.format(est=estimator)
        values = [_float(r.get(name)) for r in ok]
        finite = [v for v in values if math.isfinite(v)]
        notes = []
        if len(finite) < len(group):
            notes.append(f"{len(group) - len(finite)} of {len(group)} run(s) left out (not ok, or "
                         f"{name} not finite)")
        row = dict(base, quantity=name, unit=unit, n_runs=len(finite), n_rates=None, flag="ok")
        modulus = pattern.startswith("G_")
        if finite:
            row["value"], row["ci_low"], row["ci_high"] = _mean_interval(finite, n_boot, confidence, rng,
                                                                         modulus=modulus)
            if len(finite) == 1:
                notes.append("one run: degenerate interval")
            if modulus and not row["value"] > 0:
                row["flag"] = "non_positive"
                notes.append(f"mean {name} <= 0: no interval")
        else:
            row["value"] = row["ci_low"] = row["ci_high"] = math.nan
            row["flag"] = "undefined"
        row["note"] = "; ".join(notes)
        out.append(row)
    return out


def _steady(group, ok, base, estimator, n_boot, confidence, rng, fit_flow_curve):
    """The rows of one steady group: the Herschel–Bulkley parameters of its flow curve."""
    typed = []
    for r in group:
        rate, stress = _float(r.get("strain_rate")), _float(r.get(f"stress_{estimator}"))
        good = str(r.get("status", "")).strip() == "ok" and math.isfinite(rate) and math.isfinite(stress)
        typed.append({"protocol": "steady", "relative_rate": _float(r.get("relative_rate")),
                      "repetition": int(_float(r.get("repetition")) if math.isfinite(_float(r.get("repetition")))
                                        else 0),
                      "status": "ok" if good else "failed", "strain_rate": rate,
                      f"stress_{estimator}": stress if good else None})
    n_ok = sum(1 for t in typed if t["status"] == "ok")
    n_rates = len({t["relative_rate"] for t in typed if t["status"] == "ok"})
    note, fit = "", None
    if n_rates < 3:
        note = f"finished runs at {n_rates} rate(s): a Herschel-Bulkley fit needs >= 3"
    else:
        try:
            fit = fit_flow_curve(typed, estimator, n_boot=n_boot, confidence=confidence, rng=rng)
        except ValueError as exc:
            note = "no Herschel-Bulkley fit: " + " ".join(str(exc).split())
    flag = "undefined" if fit is None else "degenerate_fit" if fit.degenerate else "ok"
    if fit is not None and fit.degenerate:
        note = "; ".join(("degenerate Herschel-Bulkley fit: " + "; ".join(fit.degenerate),) + ((note,) if note else ()))
    if n_ok < len(group):
        note = "; ".join(x for x in (note, f"{len(group) - n_ok} of {len(group)} run(s) left out (not ok, or no "
                                           f"finite stress_{estimator})") if x)
    rows = []
    for name, unit in QUANTITIES["steady"].items():
        row = dict(base, quantity=name, unit=unit, n_runs=n_ok, n_rates=n_rates, note=note, flag=flag)
        if fit is not None:
            lo, hi = fit.intervals[name]
            row.update(value=float(getattr(fit.fit, name)), ci_low=float(lo), ci_high=float(hi))
        else:
            row.update(value=math.nan, ci_low=math.nan, ci_high=math.nan)
        rows.append(row)
    return rows
