"""Period-by-period storage and loss moduli: an uncertainty and a steadiness check on every G′, G″.

The package's :func:`~particleShear.simulation.evaluation.demodulation` projects the stress over
the window ``[(pre+e)/f, (pre+P)/f]`` (``e = 1`` if ``P >= 2``, else 0: the first excitation
period is skipped as a transient), with the phase ``2π(f t − pre)`` and ``t`` the time since the
start of the protocol (``pre`` baseline periods before the excitation, ``P`` excitation periods).
:func:`period_moduli` demodulates each *whole* excitation period ``k = e … floor(P) − 1`` of that
window on its own, the samples with ``(pre+k)/f <= t < (pre+k+1)/f``:

.. math::

    G'_k = \\frac{\\sum s\\,m}{\\gamma_0 \\sum s^2},\\qquad
    G''_k = \\frac{\\sum c\\,m}{\\gamma_0 \\sum c^2},\\qquad
    s = \\sin 2\\pi(f t - pre),\\ c = \\cos 2\\pi(f t - pre),

``m`` the stress (Pa), ``γ₀`` the strain amplitude: the one-parameter least-squares amplitudes of
``demodulation`` (no drift correction; a stress offset cancels on a whole, evenly sampled period).
The spread of the ``G'_k`` gives the standard error of their mean, and their straight-line
trend over the measurement tells a steady response from one still settling
(:class:`PeriodModuli`).  :func:`measured_period_count` says from the protocol alone how many
whole periods the window holds, so a caller can warn before a run (fewer than 2 give no error
bar, fewer than 3 no steadiness check).
"""
__docformat__ = "numpy"
import dataclasses
import math
import numbers

import numpy as np

__all__ = ["PeriodModuli", "measured_period_count", "period_moduli", "t_critical", "FALSE_ALARM"]

#: A period with fewer samples is not a whole measured period.
MIN_SAMPLES_PER_PERIOD = 8
#: A period whose samples leave a gap (its ends included) longer than this fraction of the
#: period is not a whole measured period (data that stop or start inside it).
MAX_GAP_FRACTION = 1 / 8
#: default probability that ``steady`` is False for a response without trend (both moduli together)
FALSE_ALARM = 0.05
#: A trend below this fraction of |G*| is below the resolution of the demodulation and never counts.
TREND_RESOLUTION = 1e-9


@dataclasses.dataclass(frozen=True, eq=False)
class PeriodModuli:
    """The moduli of each whole excitation period and their statistics (made by :func:`period_moduli`; frozen).

    ``trend`` is the ordinary-least-squares slope of the per-period values against the period
    index times the index span ``k_last − k_first`` (``n_periods − 1`` when no period was left
    out): the change of the modulus across the measurement.  ``steady`` is False when, for G′ or
    for G″, the trend is significantly larger than its own error: ``|trend| > t_c·trend_se``
    (and above ``1e-9·|G*|``, the rounding level), where under the hypothesis of no trend and
    independent Gaussian per-period errors ``trend/trend_se`` follows Student's t with
    ``n − 2`` degrees of freedom and t_c is its two-sided ``false_alarm/2`` critical value
    (Bonferroni over the two moduli): a response without trend is called unsteady with
    probability at most ``false_alarm`` whatever the number of periods (t_c = 25.5 for n = 3,
    6.2 for n = 4, 3.5 for n = 6, 2.24 for n → ∞ at the default 0.05), so few periods detect
    only a large drift.  A trend is only a *linear* drift; a response that oscillates from
    period to period shows in ``Gp_se`` instead.

    Parameters
    ----------
    period : numpy.ndarray of int
        The index k of each measured period (0 = the first excitation period).
    Gp : numpy.ndarray
        G′ of each measured period (Pa).
    Gpp : numpy.ndarray
        G″ of each measured period (Pa).
    n_periods : int
        Number of measured periods (``len(Gp)``).
    n_expected : int
        Whole periods the protocol's window holds (:func:`measured_period_count`); more than
        ``n_periods`` when some of them have too few samples (the data do not cover them).
    Gp_mean, Gpp_mean : float
        Means of the per-period values (Pa); NaN without a period.
    Gp_se, Gpp_se : float
        Standard errors of the means, ``std(ddof=1)/√n`` (Pa); NaN when ``n < 2``.
    Gp_trend, Gpp_trend : float
        Change across the measurement, OLS slope per period × ``(k_last − k_first)`` (Pa); NaN when ``n < 2``.
    Gp_trend_se, Gpp_trend_se : float
        Standard errors of the trends from the OLS residuals (Pa); NaN when ``n < 3``.
    steady : bool or None
        True: no significant trend in G′ or G″; False: one of them drifts (see above); None when
        ``n < 3`` (a trend cannot be judged against its own error).
    """

    period: np.ndarray
    Gp: np.ndarray
    Gpp: np.ndarray
    n_periods: int
    n_expected: int
    Gp_mean: float
    Gpp_mean: float
    Gp_se: float
    Gpp_se: float
    Gp_trend: float
    Gpp_trend: float
    Gp_trend_se: float
    Gpp_trend_se: float
    steady: object


def _check_number(name, x, allowed, ok):
    if isinstance(x, bool) or not isinstance(x, numbers.Real) or not math.isfinite(x) or not ok(x):
        raise ValueError(f"{name} must be {allowed}, got {x!r}")
    return float(x)


def _check_protocol(pre_periods, periods):
    pre = _check_number("pre_periods", pre_periods, "a finite number >= 0 (baseline periods)", lambda x: x >= 0)
    P = _check_number("periods", periods, "a finite number > 0 (excitation periods)", lambda x: x > 0)
    return pre, P


def _first_measured(P):
    """``e``: the first excitation period is skipped as a transient when there are at least two."""
    return 1 if P >= 2 else 0


def measured_period_count(pre_periods, periods):
    """How many whole excitation periods the demodulation window holds, from the protocol alone.

    The window is ``[(pre+e)/f, (pre+P)/f]`` with ``e = 1`` if ``P >= 2`` else 0, so it holds the
    whole periods ``k = e … floor(P) − 1``: ``max(0, floor(P) − e)``.  For example ``P = 1``: 1
    (the only period is measured), ``P = 2``: 1, ``P = 5``: 4, ``P = 2.5``: 1, ``P = 0.5``: 0.

    Parameters
    ----------
    pre_periods : float
        Baseline periods before the excitation (≥ 0; it shifts the window, not the count).
    periods : float
        Excitation periods P (> 0).

    Returns
    -------
    int
        The number of whole periods; fewer than 2 give no standard error, fewer than 3 no
        steadiness check in :func:`period_moduli`.

    Raises
    ------
    ValueError
        ``pre_periods`` < 0, ``periods`` ≤ 0, or either not a finite number.
    """
    _, P = _check_protocol(pre_periods, periods)
    return max(0, math.floor(P) - _first_measured(P))


def _t_two_sided(x, dof):
    """P(|T| ≤ x) for Student's t with an integer number of degrees of freedom (A&S 26.7.3–4)."""
    theta = math.atan(x / math.sqrt(dof))
    c2 = math.cos(theta) ** 2
    if dof % 2:           # odd: (2/π)(θ + sin θ cos θ (1 + 2/3 cos² θ + 2·4/(3·5) cos⁴ θ + …))
        term, total = 1.0, 1.0
        for j in range(1, (dof - 1) // 2):
            term *= c2 * (2 * j) / (2 * j + 1)
            total += term
        series = math.sin(theta) * math.cos(theta) * total if dof > 1 else 0.0
        return 2 / math.pi * (theta + series)
    term, total = 1.0, 1.0  # even: sin θ (1 + 1/2 cos² θ + 1·3/(2·4) cos⁴ θ + …)
    for j in range(1, dof // 2):
        term *= c2 * (2 * j - 1) / (2 * j)
        total += term
    return math.sin(theta) * total


def t_critical(dof, alpha):
    """The two-sided critical value of Student's t: P(|T| > t_c) = ``alpha``.

    Parameters
    ----------
    dof : int
        Degrees of freedom (≥ 1).
    alpha : float
        Two-sided tail probability, 0 < alpha < 1.

    Returns
    -------
    float
        t_c (bisection to 1e-12 relative on the closed-form distribution function).

    Raises
    ------
    ValueError
        For ``dof`` < 1 or ``alpha`` outside (0, 1).
    """
    if isinstance(dof, bool) or not isinstance(dof, numbers.Integral) or dof < 1:
        raise ValueError(f"dof={dof!r} is not allowed: an integer >= 1")
    if not (isinstance(alpha, numbers.Real) and 0 < alpha < 1):
        raise ValueError(f"alpha={alpha!r} is not allowed: a number in (0, 1)")
    lo, hi = 0.0, 1.0
    while 1 - _t_two_sided(hi, int(dof)) > alpha:
        hi *= 2.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if 1 - _t_two_sided(mid, int(dof)) > alpha:
            lo = mid
        else:
            hi = mid
        if hi - lo <= 1e-12 * hi:
            break
    return 0.5 * (lo + hi)


def _trend(k, y):
    """OLS trend across the index span and its standard error (NaN where undefined)."""
    n = len(y)
    if n < 2:
        return math.nan, math.nan
    x = k - k.mean()
    sxx = float(x @ x)
    slope = float(x @ (y - y.mean())) / sxx
    span = float(k[-1] - k[0])
    if n < 3:
        return slope * span, math.nan
    residual = y - y.mean() - slope * x
    se = math.sqrt(float(residual @ residual) / (n - 2) / sxx)
    return slope * span, se * span


def period_moduli(t, stress, f, strain_amplitude, pre_periods, periods, false_alarm=FALSE_ALARM):
    """G′ and G″ of each whole excitation period of the demodulation window, with their spread and trend.

    Parameters
    ----------
    t : array_like
        Sample times since the start of the protocol (s), 1-D (the times of
        :func:`~particleShear.simulation.evaluation.demodulation`; any order).
    stress : array_like
        Shear stress samples (Pa), same shape as ``t``, signed as for ``demodulation``.
    f : float
        Excitation frequency (Hz), > 0.
    strain_amplitude : float
        Strain amplitude γ₀ (absolute strain), > 0: the strain is ``γ₀ sin 2π(f t − pre)``.
    pre_periods : float
        Baseline periods before the excitation (≥ 0).
    periods : float
        Excitation periods P (> 0).
    false_alarm : float, default 0.05
        Largest probability that ``steady`` is False for a response without trend (0 < … < 1).

    Returns
    -------
    PeriodModuli
        The per-period moduli, their means, standard errors, trends and the steadiness verdict.
        A period of the window with fewer than 8 samples, or whose samples leave a gap longer
        than 1/8 period (its ends included), is not a whole measured period and is left out.

    Raises
    ------
    ValueError
        ``t``/``stress`` not 1-D, of different shapes or not finite; ``f`` or ``strain_amplitude``
        not a finite number > 0; ``pre_periods`` < 0 or ``periods`` ≤ 0 or not finite.

    Notes
    -----
    No drift correction is applied (``demodulation`` subtracts a baseline drift estimate); on an
    evenly sampled whole period a constant offset cancels exactly, a linear drift ``D·t`` (Pa/s) leaks
    ``−D/(π f γ₀)`` into each G′ (and nothing into G″).
    """
    t = np.asarray(t, dtype=float)
    stress = np.asarray(stress, dtype=float)
    if t.ndim != 1:
        raise ValueError(f"t must be a 1-D array, got shape {t.shape}")
    if stress.shape != t.shape:
        raise ValueError(f"stress must have the shape of t {t.shape}, got {stress.shape}")
    for name, a in (("t", t), ("stress", stress)):
        if not np.all(np.isfinite(a)):
            bad = int(np.flatnonzero(~np.isfinite(a))[0])
            raise ValueError(f"{name} must be finite everywhere, got {a[bad]!r} at index {bad}")
    f = _check_number("f", f, "a finite frequency > 0 (Hz)", lambda x: x > 0)
    amplitude = _check_number("strain_amplitude", strain_amplitude, "a finite strain amplitude > 0",
                              lambda x: x > 0)
    pre, P = _check_protocol(pre_periods, periods)
    false_alarm = _check_number("false_alarm", false_alarm, "a probability in (0, 1)", lambda x: 0 < x < 1)
    e = _first_measured(P)
    n_expected = max(0, math.floor(P) - e)

    order = np.argsort(t, kind="stable")
    t = t[order]
    stress = stress[order]
    ks, gps, gpps = [], [], []
    first, stop = e, e + n_expected
    if len(t):     # only the periods the data reach (a long protocol with a short record)
        first = max(first, math.floor(f * t[0] - pre))
        stop = min(stop, math.floor(f * t[-1] - pre) + 1)
    for k in range(first, stop):
        start, end = (pre + k) / f, (pre + k + 1) / f
        lo, hi = np.searchsorted(t, start, side="left"), np.searchsorted(t, end, side="left")
        tk = t[lo:hi]
        if len(tk) < MIN_SAMPLES_PER_PERIOD:
            continue
        gaps = np.diff(np.concatenate(([start], tk, [end])))
        if gaps.max() > MAX_GAP_FRACTION / f * (1 + 1e-9):
            continue
        phase = 2 * math.pi * (f * tk - pre)
        s, c, m = np.sin(phase), np.cos(phase), stress[lo:hi]
        ks.append(k)
        gps.append(float(s @ m) / float(s @ s) / amplitude)
        gpps.append(float(c @ m) / float(c @ c) / amplitude)
    k = np.array(ks, dtype=int)
    Gp = np.array(gps, dtype=float)
    Gpp = np.array(gpps, dtype=float)
    n = len(k)

    def mean_se(y):
        if n == 0:
            return math.nan, math.nan
        return float(np.mean(y)), (float(np.std(y, ddof=1)) / math.sqrt(n) if n >= 2 else math.nan)

    Gp_mean, Gp_se = mean_se(Gp)
    Gpp_mean, Gpp_se = mean_se(Gpp)
    Gp_trend, Gp_trend_se = _trend(k, Gp)
    Gpp_trend, Gpp_trend_se = _trend(k, Gpp)
    if n >= 3:
        floor = TREND_RESOLUTION * math.hypot(Gp_mean, Gpp_mean)
        tc = t_critical(n - 2, false_alarm / 2)
        steady = not any(abs(tr) > max(tc * se, floor)
                         for tr, se in ((Gp_trend, Gp_trend_se), (Gpp_trend, Gpp_trend_se)))
    else:
        steady = None
    for a in (k, Gp, Gpp):
        a.setflags(write=False)
    return PeriodModuli(period=k, Gp=Gp, Gpp=Gpp, n_periods=n, n_expected=n_expected,
                        Gp_mean=Gp_mean, Gpp_mean=Gpp_mean, Gp_se=Gp_se, Gpp_se=Gpp_se,
                        Gp_trend=Gp_trend, Gpp_trend=Gpp_trend, Gp_trend_se=Gp_trend_se,
                        Gpp_trend_se=Gpp_trend_se, steady=steady)
