"""Characteristic points of an amplitude sweep, as the downstream R evaluation reads them.

An amplitude sweep G′(γ₀), G″(γ₀) of a soft solid has a low-strain plateau, a softening
(G′ starts to fall and G″ peaks), a soft plateau (G′ falls more slowly, G″ has a minimum) and a
yield point (G′ = G″, the crossover to flow).  The rules below are those of the R package
particleShearEvaluation that the paper behind the method used, written as definitions on arrays
(docs/analysis.md), so that a user without R gets the same numbers.
"""
__docformat__ = "numpy"
import math

import numpy as np

__all__ = ["yield_point", "stress_curve_points", "CURVE_POINTS"]

#: the names of the four characteristic points, in the order of the sweep
CURVE_POINTS = ("low_strain_plateau", "softening", "soft_plateau", "yield")

_NAN_POINT = (math.nan, math.nan, math.nan)


def _arrays(strain, Gp, Gpp):
    s = np.asarray(strain, dtype=float).ravel()
    gp = np.asarray(Gp, dtype=float).ravel()
    gpp = np.asarray(Gpp, dtype=float).ravel()
    if not (len(s) == len(gp) == len(gpp)):
        raise ValueError(f"strain, Gp and Gpp must have one length, got {len(s)}, {len(gp)} and {len(gpp)}")
    return s, gp, gpp


def _yield_bracket(s, gp, gpp, interpolation):
    """(strain, G′, G″) at the crossover; G′, G″ interpolated linearly in strain at it."""
    if interpolation not in ("log", "linear"):
        raise ValueError(f"interpolation={interpolation!r} is not allowed: use 'log' or 'linear'")
    if len(s) == 0:
        return _NAN_POINT
    order = np.argsort(-s, kind="stable")          # decreasing strain; ties keep their input order
    s, gp, gpp = s[order], gp[order], gpp[order]
    above = np.flatnonzero(gp > gpp)
    if len(above) == 0:
        return _NAN_POINT
    k = int(above[0])
    if k == 0:
        return float(s[0]), float(gp[0]), float(gpp[0])
    a, b = k - 1, k
    with np.errstate(divide="ignore", invalid="ignore"):
        if interpolation == "linear":
            da, db = gp[a] - gpp[a], gp[b] - gpp[b]
            x = s[a] + (0.0 - da) * (s[b] - s[a]) / (db - da)
        else:
            if min(s[a], s[b], gp[a], gp[b], gpp[a], gpp[b]) <= 0:
                return _NAN_POINT
            da = math.log(gp[a]) - math.log(gpp[a])
            db = math.log(gp[b]) - math.log(gpp[b])
            la, lb = math.log(s[a]), math.log(s[b])
            x = math.exp(la + (0.0 - da) * (lb - la) / (db - da))
        w = (x - s[a]) / (s[b] - s[a]) if s[b] != s[a] else 0.5   # a tie in strain: the mean of the two
    return float(x), float(gp[a] + w * (gp[b] - gp[a])), float(gpp[a] + w * (gpp[b] - gpp[a]))


def yield_point(strain, Gp, Gpp, interpolation="log"):
    """The strain where G′ = G″ (the yield or flow point), read from above.

    The points are ordered by decreasing strain (ties keep their order); k is the first
    position in that order with G′ > G″.  No such point: NaN (the sample never behaves as a
    solid).  k the first point (G′ > G″ already at the largest strain): its strain.  Otherwise
    the zero of G′ − G″ interpolated between positions k − 1 and k: linearly in strain for
    ``interpolation="linear"`` (the R package's rule), or of log G′ − log G″ linearly in
    log strain for ``"log"`` (exact for power laws; NaN when a value there is not positive).

    Parameters
    ----------
    strain : array_like
        Strain amplitudes γ₀ (dimensionless), any order, repeats allowed.
    Gp, Gpp : array_like
        G′ and G″ (Pa) at those amplitudes, same length.
    interpolation : {"log", "linear"}, default "log"
        How to interpolate between the bracketing points.

    Returns
    -------
    float
        The crossover strain (dimensionless), or NaN.

    Raises
    ------
    ValueError
        When the lengths differ or ``interpolation`` is not one of the two.
    """
    s, gp, gpp = _arrays(strain, Gp, Gpp)
    return _yield_bracket(s, gp, gpp, interpolation)[0]


def _first_extreme(values, largest):
    """0-based position of the first maximum (minimum) over the non-NaN values; None when all are NaN.

    NaN (a slope between repeated strains) is skipped, as R's which.max skips NA, so it can neither
    win nor tie with an infinite slope.
    """
    ok = np.flatnonzero(~np.isnan(values))
    if len(ok) == 0:
        return None
    v = values[ok]
    return int(ok[np.argmax(v) if largest else np.argmin(v)])


def _at_position(pos, ls, gp, gpp):
    """(strain, G′, G″) at a possibly half-integer 0-based position: ln s, G′, G″ linear in position."""
    lo, hi = int(math.floor(pos)), int(math.ceil(pos))
    w = pos - lo
    return (float(math.exp(ls[lo] + w * (ls[hi] - ls[lo]))), float(gp[lo] + w * (gp[hi] - gp[lo])),
            float(gpp[lo] + w * (gpp[hi] - gpp[lo])))


def stress_curve_points(strain, Gp, Gpp, guess_softening_strain=0.01, guess_soft_plateau_strain=0.1):
    """The four characteristic points of an amplitude sweep (the R package's definitions).

    With the points sorted by increasing strain s (stable: repeats keep their order) and
    positions k = 1…n:

    * **low strain plateau** — the smallest strain, G′ and G″ averaged over the points at it;
    * **slope** — ``d_k = (G′_{k+1} − G′_k)/(ln s_{k+1} − ln s_k)``, k = 1…n−1, padded to
      n + 1 values by repeating its first and last value, ``D_k = −(p_k + p_{k+1})/2``
      (the descent of G′ per e-fold of strain, k = 1…n);
    * **softening** — i₁ = first position of the largest ``G″_k·[g/5 ≤ s_k ≤ 5g]``
      (g = ``guess_softening_strain``, 0 outside the window), i₂ = first position of the largest
      ``D_k·[|k − i₁| ≤ 3]`` (0 outside, and that 0 can win); the point sits at position
      (i₁ + i₂)/2 — half-integer positions interpolate ln s, G′ and G″ linearly;
    * **soft plateau** — candidates k with ``s_k ≥ 1.5·s_softening`` and ``s_k ≤ 3h``
      (h = ``guess_soft_plateau_strain``); with none, the factor 3 becomes 9, 27, … up to 2187;
      j₁ = first position of the smallest G″ among the candidates, j₂ = first position of the
      smallest D_k with ``|k − j₁| ≤ 3``; the point sits at position (j₁ + j₂)/2;
    * **yield** — :func:`yield_point` with ``interpolation="linear"``, G′ and G″ interpolated
      linearly in strain there.

    NaN in the slopes (repeated strains) is skipped: it is neither the largest nor the smallest.
    At a yield bracket of two points with the same strain, G′ and G″ are their means.

    Parameters
    ----------
    strain : array_like
        Strain amplitudes (dimensionless, > 0 for the slopes), one per point; several points
        (seeds) per amplitude are allowed.
    Gp, Gpp : array_like
        G′ and G″ (Pa), same length.
    guess_softening_strain : float, default 0.01
        Centre g of the window g/5 … 5g where G″ peaks at softening.
    guess_soft_plateau_strain : float, default 0.1
        Scale h of the upper bound 3h of the soft-plateau search.

    Returns
    -------
    dict
        ``{"low_strain_plateau", "softening", "soft_plateau", "yield"}`` → ``(strain, G′, G″)``
        (dimensionless, Pa, Pa); NaN where a point does not exist (no crossover, fewer than two
        points for the slopes, no soft-plateau candidate).

    Raises
    ------
    ValueError
        When the lengths differ or there are no points.
    """
    s, gp, gpp = _arrays(strain, Gp, Gpp)
    n = len(s)
    if n == 0:
        raise ValueError("stress_curve_points needs at least one point, got none")
    order = np.argsort(s, kind="stable")
    s, gp, gpp = s[order], gp[order], gpp[order]
    at_min = s == s[0]
    out = {"low_strain_plateau": (float(s[0]), float(np.mean(gp[at_min])), float(np.mean(gpp[at_min]))),
           "softening": _NAN_POINT, "soft_plateau": _NAN_POINT,
           "yield": _yield_bracket(s, gp, gpp, "linear")}
    if n < 2:
        return out
    with np.errstate(divide="ignore", invalid="ignore"):
        ls = np.log(s)
        d = np.diff(gp) / np.diff(ls)
    p = np.concatenate(([d[0]], d, [d[-1]]))
    D = -(p[:-1] + p[1:]) / 2.0                      # length n
    k = np.arange(n)
    g = float(guess_softening_strain)
    i1 = _first_extreme(np.where((s >= g / 5) & (s <= 5 * g), gpp, 0.0), True)
    i2 = None if i1 is None else _first_extreme(np.where(np.abs(k - i1) <= 3, D, 0.0), True)
    if i2 is None:
        return out
    soft = _at_position((i1 + i2) / 2.0, ls, gp, gpp)
    out["softening"] = soft
    h = float(guess_soft_plateau_strain)
    factor = 3.0
    candidates = np.flatnonzero((s >= 1.5 * soft[0]) & (s <= factor * h))
    if len(candidates) == 0:
        factor = 9.0
        candidates = np.flatnonzero((s >= 1.5 * soft[0]) & (s <= factor * h))
        while factor < 1000 and len(candidates) == 0:
            factor *= 3.0
            candidates = np.flatnonzero((s >= 1.5 * soft[0]) & (s <= factor * h))
    if len(candidates):
        c1 = _first_extreme(gpp[candidates], False)
        j1 = None if c1 is None else int(candidates[c1])
        window = np.flatnonzero(np.abs(k - j1) <= 3) if j1 is not None else np.zeros(0, dtype=int)
        c2 = _first_extreme(D[window], False) if len(window) else None
        if c2 is not None:
            out["soft_plateau"] = _at_position((j1 + int(window[c2])) / 2.0, ls, gp, gpp)
    return out
