"""Microstructure of runs and sweeps: per-run columns and the irreversibility onset of a sweep (issue 49).

A run measured with ``stroboscopic=True`` carries ``result.microstructure``, the per-cycle arrays of
the stroboscopic observer (:class:`particleShear.engine.microstructure.Stroboscope`).
:func:`micro_measures` turns them into the results-table columns :data:`MICRO_COLUMNS` (NaN for a
run without the observer), and :func:`irreversibility_onset` finds the amplitude where an
amplitude sweep becomes irreversible, with a bootstrap interval over seeds, beside the flow point
and softening point of :func:`~particleShear.analysis.sweep.sweep_summary`
(:func:`onset_summary`); :func:`onset_figure` draws G′, G″ and the irreversibility against the
amplitude on a shared axis (needs matplotlib).  Definitions: docs/microstructure.md.
"""
__docformat__ = "numpy"
import math

import numpy as np

from ..engine.microstructure import TRANSIENT_CYCLES, irreversibility
from .sweep import sweep_summary

__all__ = ["MICRO_COLUMNS", "ONSET_THRESHOLD", "micro_measures", "irreversibility_onset", "onset_summary",
           "onset_figure"]

#: the per-run microstructure columns of the results table (NaN unless the run was stroboscopic)
MICRO_COLUMNS = ("irreversibility", "moved_fraction", "Z_rattler_free", "rattler_fraction", "contact_change_rate")

#: irreversibility (mean squared non-affine displacement per cycle / r_mean²) that marks the onset:
#: an rms non-affine displacement of 0.1 mean radii per cycle, the "moved" threshold of the observer
ONSET_THRESHOLD = 0.01


def micro_measures(micro, transient=TRANSIENT_CYCLES):
    """The per-run columns :data:`MICRO_COLUMNS` of a run's :meth:`Stroboscope.replica` arrays.

    After the ``transient`` first cycles (all cycles when there are not more):
    ``irreversibility`` (:func:`irreversibility`, mean squared non-affine displacement per cycle
    / r_mean²), ``moved_fraction`` (mean fraction of spheres moved more than the threshold per
    cycle), ``contact_change_rate`` (contacts made + broken per cycle per contact at the start of
    the cycle); over the snapshots after the transient, ``Z_rattler_free`` (mean contacts per
    non-rattler sphere) and ``rattler_fraction``.

    Parameters
    ----------
    micro : dict or None
        ``result.microstructure``; None (a run without the observer) gives None in every column
        (empty in the table: not evaluated).
    transient : int, default :data:`TRANSIENT_CYCLES`
        Cycles left out.

    Returns
    -------
    dict
        Column → float (dimensionless; NaN where the observer saw no cycle); None without the observer.
    """
    if micro is None:
        return {c: None for c in MICRO_COLUMNS}
    row = {c: math.nan for c in MICRO_COLUMNS}
    if not len(micro["msd"]):
        return row
    n = len(micro["msd"])
    k = transient if n > transient else n - 1
    row["irreversibility"] = irreversibility(micro["msd"], micro["r_mean"], transient)
    row["moved_fraction"] = float(np.mean(micro["moved"][k:]))
    changes = (micro["made"] + micro["broken"])[k:].astype(float)
    before = micro["contacts_before"][k:].astype(float)
    row["contact_change_rate"] = float(np.mean(changes / np.where(before > 0, before, np.nan)))
    row["Z_rattler_free"] = float(np.nanmean(micro["Z"][k + 1:])) if np.isfinite(micro["Z"][k + 1:]).any() else math.nan
    row["rattler_fraction"] = float(np.mean(micro["rattler_fraction"][k + 1:]))
    return row


def _crossing(A, y, threshold):
    """First amplitude where ``y`` reaches ``threshold`` between measured amplitudes (log-log
    interpolation; linear in log A where a bracketing value is <= 0); NaN when it never does,
    ``A[0]`` when the smallest amplitude is already at or above it (then flagged by the caller)."""
    above = np.flatnonzero(y >= threshold)
    if not len(above):
        return math.nan
    k = int(above[0])
    if k == 0:
        return float(A[0])
    a0, a1, y0, y1 = A[k - 1], A[k], y[k - 1], y[k]
    if y0 > 0 and y1 > 0:
        w = (math.log(threshold) - math.log(y0)) / (math.log(y1) - math.log(y0))
    else:
        w = (threshold - y0) / (y1 - y0)
    return float(math.exp(math.log(a0) + w * (math.log(a1) - math.log(a0))))


def irreversibility_onset(amplitude, irr, threshold=ONSET_THRESHOLD, n_boot=2000, confidence=0.95, rng=0):
    """Amplitude where the mean irreversibility of an amplitude sweep first reaches ``threshold``.

    The runs (seeds) at each amplitude are averaged (NaN runs left out); the onset is the first
    crossing of ``threshold`` by the mean curve, interpolated linearly in log irreversibility
    against log amplitude between the bracketing amplitudes.  The interval is a percentile
    bootstrap: the seeds are resampled with replacement within each amplitude, the crossing found
    again, and the ``(1 ± confidence)/2`` percentiles taken over the replicates where it is finite.

    Parameters
    ----------
    amplitude : array_like (m,)
        Strain amplitude of each run, > 0.
    irr : array_like (m,)
        Irreversibility of each run (the ``irreversibility`` column, dimensionless).
    threshold : float, default :data:`ONSET_THRESHOLD`
        The onset level, > 0.
    n_boot : int, default 2000
        Bootstrap replicates, ≥ 1.
    confidence : float, default 0.95
        Interval level in (0, 1).
    rng : int or numpy.random.Generator, default 0
        The bootstrap's random source.

    Returns
    -------
    dict
        "onset" (float; NaN when never reached), "low", "high" (interval; NaN without finite
        replicates), "flag" ("" | "below_range": already above at the smallest amplitude, the onset
        is at most that | "above_range": never reached, the onset exceeds the largest amplitude),
        "defined_fraction" (of the replicates), "amplitudes", "mean" (the mean curve).

    Raises
    ------
    ValueError
        Naming ``amplitude``, ``irr``, ``threshold``, ``n_boot`` or ``confidence`` and the value
        out of range.
    """
    A = np.asarray(amplitude, float)
    y = np.asarray(irr, float)
    if A.ndim != 1 or A.shape != y.shape or not len(A):
        raise ValueError(f"amplitude and irr must be 1-D of one length >= 1, got shapes {A.shape} and {y.shape}")
    if not (np.isfinite(A).all() and (A > 0).all()):
        raise ValueError(f"amplitude={A!r} is out of range: allowed finite values > 0")
    if not (isinstance(threshold, (int, float)) and math.isfinite(threshold) and threshold > 0):
        raise ValueError(f"threshold={threshold!r} is out of range: allowed a finite number > 0")
    if isinstance(n_boot, bool) or not isinstance(n_boot, (int, np.integer)) or n_boot < 1:
        raise ValueError(f"n_boot={n_boot!r} is out of range: allowed an integer >= 1")
    if not 0 < confidence < 1:
        raise ValueError(f"confidence={confidence!r} is out of range: allowed 0 < confidence < 1")
    rng = np.random.default_rng(rng)
    ok = np.isfinite(y)
    levels = np.unique(A[ok])
    groups = [y[ok & (A == a)] for a in levels]
    mean = np.array([g.mean() for g in groups])
    onset = _crossing(levels, mean, threshold)
    flag = "above_range" if math.isnan(onset) else ("below_range" if len(levels) and mean[0] >= threshold else "")
    boots = np.empty(n_boot)
    for k in range(n_boot):       # replicates (not spheres): a few thousand crossings of a short curve
        m = np.array([g[rng.integers(0, len(g), len(g))].mean() for g in groups])
        boots[k] = _crossing(levels, m, threshold)
    fin = boots[np.isfinite(boots)]
    q = (1 - confidence) / 2
    low, high = (np.quantile(fin, [q, 1 - q]) if len(fin) else (math.nan, math.nan))
    return {"onset": onset, "low": float(low), "high": float(high), "flag": flag,
            "defined_fraction": float(len(fin) / n_boot), "amplitudes": levels, "mean": mean}


def onset_summary(amplitude, Gp, Gpp, irr, threshold=ONSET_THRESHOLD, n_boot=2000, confidence=0.95, rng=0):
    """The irreversibility onset beside the flow point and softening point of the same sweep.

    Parameters
    ----------
    amplitude, Gp, Gpp, irr : array_like (m,)
        Per run: strain amplitude, G′ and G″ (Pa), irreversibility.
    threshold, n_boot, confidence, rng
        As :func:`irreversibility_onset` (the sweep summary uses the same ``rng`` seed).

    Returns
    -------
    dict
        "onset": :func:`irreversibility_onset`; "flow_point", "softening_strain",
        "linear_limit_10": ``(estimate, low, high)`` from
        :func:`~particleShear.analysis.sweep.sweep_summary`; "summary": the SweepSummary.
    """
    onset = irreversibility_onset(amplitude, irr, threshold, n_boot, confidence, rng)
    summ = sweep_summary(amplitude, Gp, Gpp, n_boot=n_boot, confidence=confidence, rng=rng)
    out = {"onset": onset, "summary": summ}
    for name in ("flow_point", "softening_strain", "linear_limit_10"):
        v, (low, high) = summ.value(name)
        out[name] = (float(v), float(low), float(high))
    return out


def onset_figure(amplitude, Gp, Gpp, irr, path=None, threshold=ONSET_THRESHOLD, onset=None):
    """G′, G″ (top) and the irreversibility (bottom) against the strain amplitude on a shared log axis.

    Parameters
    ----------
    amplitude, Gp, Gpp, irr : array_like (m,)
        Per run (seeds are averaged per amplitude; every run drawn as a faint point).
    path : str, optional
        Save the figure there (format from the suffix).
    threshold : float, default :data:`ONSET_THRESHOLD`
        Drawn as a dashed line on the irreversibility panel.
    onset : dict, optional
        :func:`irreversibility_onset`'s result, drawn as a vertical band.

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    ImportError
        Without matplotlib (the ``[plot]`` extra).
    """
    from matplotlib.figure import Figure
    A, Gp, Gpp, y = (np.asarray(v, float) for v in (amplitude, Gp, Gpp, irr))
    levels = np.unique(A)
    mean = lambda v: np.array([np.nanmean(v[A == a]) for a in levels])   # noqa: E731
    fig = Figure(figsize=(5.5, 6))
    ax1, ax2 = fig.subplots(2, 1, sharex=True)
    ax1.plot(A, Gp, ".", color="C0", alpha=0.3)
    ax1.plot(A, Gpp, ".", color="C1", alpha=0.3)
    ax1.plot(levels, mean(Gp), "o-", color="C0", label="G′")
    ax1.plot(levels, mean(Gpp), "s-", color="C1", label="G″")
    ax1.set_xscale("log")
    ax1.set_yscale("log")
    ax1.set_ylabel("modulus (Pa)")
    ax1.legend()
    ax2.plot(A, y, ".", color="C2", alpha=0.3)
    ax2.plot(levels, mean(y), "o-", color="C2", label="irreversibility")
    ax2.axhline(threshold, ls="--", color="gray", lw=1)
    ax2.set_yscale("log")
    ax2.set_xlabel("strain amplitude γ₀")
    ax2.set_ylabel("⟨|Δr_na|²⟩ per cycle / r²")
    if onset is not None and math.isfinite(onset.get("onset", math.nan)):
        for ax in (ax1, ax2):
            ax.axvline(onset["onset"], color="C2", lw=1)
            if math.isfinite(onset["low"]):
                ax.axvspan(onset["low"], onset["high"], color="C2", alpha=0.15)
    fig.tight_layout()
    if path is not None:
        fig.savefig(path, dpi=120)
    return fig
