"""Steady values, errors and time grids of the rheometer's protocols (docs/protocols.md).

Pure NumPy functions on recorded series:

- :func:`block_average` — mean and standard error of a correlated series by blocking
  (Flyvbjerg & Petersen, J. Chem. Phys. 91, 461 (1989));
- :func:`transient_end` — the end of an initial transient by MSER-5 (White, Simulation 69, 323
  (1997));
- :func:`steady_state` — both: the steady value after the transient;
- :func:`log_grid` — bin averages on log-spaced times (G(t), J(t));
- :func:`plateau` — the long-time value of a series;
- :func:`final_rate` — the final slope of a series (a creep rate) with a blocked error.
"""
__docformat__ = "numpy"
import collections
import math

import numpy as np

from .sweep import _vector

__all__ = ["BlockAverage", "SteadyState", "block_average", "transient_end", "steady_state", "log_grid", "plateau",
           "final_rate"]

BlockAverage = collections.namedtuple("BlockAverage", "mean sem block_size n")
SteadyState = collections.namedtuple("SteadyState", "mean sem t_transient i_transient n_used block_size")


def _series(name, x):
    """``x`` as a finite 1-D float array (the sweep analysis's check; ValueError naming ``name``)."""
    return _vector(name, x)


def _fraction(fraction):
    if not (isinstance(fraction, (int, float)) and 0 < fraction <= 1):
        raise ValueError(f"fraction={fraction!r} is out of range: allowed 0 < fraction <= 1")
    return float(fraction)


def block_average(x, min_blocks=8):
    """Mean and standard error of the mean of a correlated series by blocking.

    The series is halved repeatedly by averaging neighbouring pairs; at each level the naive
    standard error ``std(ddof=1)/√n`` of the blocks is computed, and the largest of them over the
    levels with at least ``min_blocks`` blocks is returned: the naive error grows with the block
    size until the blocks are uncorrelated and is flat (within its own scatter) beyond, so the
    maximum is the plateau value or slightly above it — a conservative error.

    Parameters
    ----------
    x : array_like (n,)
        The series (finite).
    min_blocks : int, default 8
        Fewest blocks a level may have (≥ 2).

    Returns
    -------
    BlockAverage
        ``mean``, ``sem`` (NaN for n < 2), ``block_size`` (samples per block at the chosen level), ``n``.

    Raises
    ------
    ValueError
        For a series that is not 1-D and finite, or ``min_blocks`` < 2.
    """
    a = _series("x", x)
    if not (isinstance(min_blocks, int) and min_blocks >= 2):
        raise ValueError(f"min_blocks={min_blocks!r} is out of range: allowed an integer >= 2")
    n = len(a)
    if n < 2:
        return BlockAverage(float(a.mean()) if n else math.nan, math.nan, 1, n)
    best, size, level = a.std(ddof=1) / math.sqrt(n), 1, 1
    b = a
    while len(b) // 2 >= min_blocks:
        m = len(b) // 2
        b = 0.5 * (b[:2 * m:2] + b[1:2 * m:2])
        level *= 2
        sem = b.std(ddof=1) / math.sqrt(m)
        if sem > best:
            best, size = sem, level
    return BlockAverage(float(a.mean()), float(best), size, n)


def transient_end(x, batch=5):
    """Index where the initial transient of ``x`` ends, by MSER-5.

    The series is cut into batch means of ``batch`` samples; for each truncation d (in batches,
    0 … k/2) the marginal standard error ``Σ_{j≥d} (m_j − m̄_d)² / (k − d)²`` is computed, and
    the d that minimises it is the end of the transient (searched over the first half only, as
    the rule prescribes).

    Parameters
    ----------
    x : array_like (n,)
        The series (finite).
    batch : int, default 5
        Samples per batch mean (≥ 1).

    Returns
    -------
    int
        The first sample of the steady part (0 when there is no transient or fewer than 2 batches).

    Raises
    ------
    ValueError
        For a series that is not 1-D and finite, or ``batch`` < 1.
    """
    a = _series("x", x)
    if not (isinstance(batch, int) and batch >= 1):
        raise ValueError(f"batch={batch!r} is out of range: allowed an integer >= 1")
    k = len(a) // batch
    if k < 2:
        return 0
    m = a[:k * batch].reshape(k, batch).mean(axis=1)
    # suffix sums of m and m² give every truncation's statistic in one pass
    s1 = np.cumsum(m[::-1])[::-1]
    s2 = np.cumsum((m * m)[::-1])[::-1]
    d = np.arange(k // 2 + 1)
    cnt = k - d
    ss = s2[d] - s1[d] ** 2 / cnt
    return int(d[np.argmin(ss / cnt ** 2)]) * batch


def steady_state(t, x, min_blocks=8):
    """The steady value of ``x`` after its initial transient (:func:`transient_end`, :func:`block_average`).

    Parameters
    ----------
    t : array_like (n,)
        Sample times (s).
    x : array_like (n,)
        The series.
    min_blocks : int, default 8
        As :func:`block_average`.

    Returns
    -------
    SteadyState
        ``mean``, ``sem``, ``t_transient`` (time at which the steady part begins), ``i_transient``,
        ``n_used``, ``block_size``.

    Raises
    ------
    ValueError
        For series of different lengths, or as :func:`block_average`.
    """
    tt, a = _series("t", t), _series("x", x)
    if len(tt) != len(a):
        raise ValueError(f"t and x have lengths {len(tt)} and {len(a)}: allowed equal lengths")
    if not len(a):
        raise ValueError("x is empty: allowed a series of at least one sample")
    i = transient_end(a)
    ba = block_average(a[i:], min_blocks)
    return SteadyState(ba.mean, ba.sem, float(tt[i]), i, ba.n, ba.block_size)


def log_grid(t, y, n_per_decade=10, t_min=None):
    """Bin averages of ``y`` on log-spaced bins of ``t`` > 0 (empty bins dropped).

    Bin edges ``t_min·10^(k/n_per_decade)``; each bin gives the geometric mean of its times, the
    mean of its values and the standard error of its samples about the bin's own linear trend in
    log t (the within-bin scatter with the curve's fall across the bin removed; the samples of a
    bin are correlated, so read it as a spread, not an independent error).

    Parameters
    ----------
    t, y : array_like (n,)
        Times (s) and values.
    n_per_decade : int, default 10
        Bins per decade of time (≥ 1).
    t_min : float or None
        First edge (> 0); default the smallest positive time.

    Returns
    -------
    t_mid, y_mean, y_sem : ndarray (m,)
        Geometric-mean time, mean, and the standard error of the bin's samples about its own
        linear trend in log t (NaN for bins of fewer than 3 samples: no spread to tell).
    count : ndarray of int (m,)
        Samples per bin.

    Raises
    ------
    ValueError
        For series of different lengths, non-finite values, ``n_per_decade`` < 1 or ``t_min`` ≤ 0.
    """
    tt, a = _series("t", t), _series("y", y)
    if len(tt) != len(a):
        raise ValueError(f"t and y have lengths {len(tt)} and {len(a)}: allowed equal lengths")
    if not (isinstance(n_per_decade, int) and n_per_decade >= 1):
        raise ValueError(f"n_per_decade={n_per_decade!r} is out of range: allowed an integer >= 1")
    pos = tt > 0
    tt, a = tt[pos], a[pos]
    if t_min is None:
        t_min = float(tt.min()) if len(tt) else 1.0
    if not (math.isfinite(t_min) and t_min > 0):
        raise ValueError(f"t_min={t_min!r} is out of range: allowed a finite value > 0")
    keep = tt >= t_min
    tt, a = tt[keep], a[keep]
    if not len(tt):
        e = np.empty(0)
        return e, e, e, np.empty(0, dtype=int)
    k = np.floor(np.log10(tt / t_min) * n_per_decade + 1e-12).astype(int)
    bins, inv, count = np.unique(k, return_inverse=True, return_counts=True)
    mean = np.bincount(inv, a) / count
    # the spread about each bin's own linear trend in log t: a curve that falls steeply across a
    # bin (G(t) right after the ramp) is a trend, not scatter; fewer than 3 samples have no spread
    x = np.log(tt)
    dx = x - (np.bincount(inv, x) / count)[inv]
    dev = a - mean[inv]
    sxx = np.bincount(inv, dx * dx)
    slope = np.where(sxx > 0, np.bincount(inv, dx * dev) / np.where(sxx > 0, sxx, 1.0), 0.0)
    res = dev - slope[inv] * dx
    var = np.bincount(inv, res * res) / np.maximum(count - 2, 1)
    sem = np.where(count > 2, np.sqrt(var / count), np.nan)
    t_mid = np.exp(np.bincount(inv, np.log(tt)) / count)
    return t_mid, mean, sem, count


def _window(t, y, fraction):
    tt, a = _series("t", t), _series("y", y)
    if len(tt) != len(a):
        raise ValueError(f"t and y have lengths {len(tt)} and {len(a)}: allowed equal lengths")
    if not len(a):
        raise ValueError("y is empty: allowed a series of at least one sample")
    f = _fraction(fraction)
    lo = tt[-1] - f * (tt[-1] - tt[0])
    w = tt >= lo
    return tt[w], a[w]


def plateau(t, y, fraction=0.2, min_blocks=8):
    """The long-time value of ``y``: :func:`block_average` over the last ``fraction`` of the time span.

    Parameters
    ----------
    t, y : array_like (n,)
        Times (s) and values.
    fraction : float, default 0.2
        Part of the span averaged (0 < fraction ≤ 1).
    min_blocks : int, default 8
        As :func:`block_average`.

    Returns
    -------
    BlockAverage

    Raises
    ------
    ValueError
        For series of different lengths or empty, non-finite values, or ``fraction`` outside (0, 1].
    """
    _, a = _window(t, y, fraction)
    return block_average(a, min_blocks)


def final_rate(t, y, fraction=0.2, blocks=5):
    """Final slope dy/dt of ``y`` over the last ``fraction`` of the span, with a blocked error.

    The slope is the least-squares slope over the window; its error is the standard error of the
    slopes of ``blocks`` contiguous parts of the window (``std(ddof=1)/√blocks``): each part's
    slope carries the part's own noise, so their spread measures the error of correlated noise
    as well, where the least-squares formula would assume independent samples.

    Parameters
    ----------
    t, y : array_like (n,)
        Times (s) and values.
    fraction : float, default 0.2
        Part of the span fitted (0 < fraction ≤ 1).
    blocks : int, default 5
        Contiguous parts for the error (≥ 2).

    Returns
    -------
    slope, slope_se : float
        In units of y per s (NaN error with fewer than 2 samples per part).

    Raises
    ------
    ValueError
        For series of different lengths or empty, non-finite values, ``fraction`` outside (0, 1]
        or ``blocks`` < 2.
    """
    if not (isinstance(blocks, int) and blocks >= 2):
        raise ValueError(f"blocks={blocks!r} is out of range: allowed an integer >= 2")
    tt, a = _window(t, y, fraction)
    if len(tt) < 2 or tt[-1] == tt[0]:
        return math.nan, math.nan
    slope = float(np.polyfit(tt, a, 1)[0])
    parts = [p for p in zip(np.array_split(tt, blocks), np.array_split(a, blocks)) if len(p[0]) >= 2]
    if len(parts) < blocks:
        return slope, math.nan
    s = np.array([np.polyfit(pt, pa, 1)[0] for pt, pa in parts])
    return slope, float(s.std(ddof=1) / math.sqrt(blocks))
