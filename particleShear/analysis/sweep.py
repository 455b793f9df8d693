"""Summary of an amplitude sweep with seeds: mean curves, characteristic points, bootstrap intervals.

:func:`sweep_summary` takes a sweep in long format — one entry per run: strain amplitude, G′, G″
— with several runs (seeds) per amplitude, and returns a :class:`SweepSummary`: the mean G′ and G″
per amplitude, the characteristics of the mean curve, and for each a percentile bootstrap interval
in which the seeds are resampled with replacement within each amplitude.

The characteristics (:data:`CHARACTERISTICS`):

plateau
    Mean G′ at the smallest amplitude (Pa).
linear_limit_5, linear_limit_10
    The amplitude where the mean G′ first falls 5 % (10 %) below the plateau, interpolated
    linearly in log G′ against log A between the two bracketing amplitudes.
flow_point
    The amplitude where mean G′ = mean G″
    (:func:`particleShear.analysis.curves.yield_point` with ``interpolation="log"``).
low_strain_plateau, softening, soft_plateau, yield
    The four points of the R package's stress curve
    (:func:`particleShear.analysis.curves.stress_curve_points` with its default guesses), each a
    strain and the G′ and G″ there; in the flat names ``<point>_strain``, ``<point>_Gp``,
    ``<point>_Gpp``.

Every characteristic carries a flag (:data:`FLAGS`): a point beyond the measured amplitudes is a
bound (``lower_bound``: the flow point is larger than the largest amplitude), never a number with a
zero-width interval; the points that need a curve are refused below :data:`MIN_POINT_AMPLITUDES`
amplitudes; an interval is given only beside an estimate.  Moduli intervals (Pa) never go below 0:
the Student widening of the bootstrap means is done on their logarithm, and a modulus whose point
estimate is <= 0 gets no interval (flag ``non_positive``).

NumPy only (no pandas, no SciPy).
"""
__docformat__ = "numpy"
import dataclasses
import math
import numbers
import types
import warnings

import numpy as np

from .curves import CURVE_POINTS, stress_curve_points, yield_point
from .periods import t_critical

__all__ = ["CHARACTERISTICS", "CURVE_COLUMNS", "DEFAULT_SEED", "FLAGS", "MIN_POINT_AMPLITUDES", "MODULUS_NAMES",
           "N_BOOT_MAX", "POINT_NAMES", "SCALAR_NAMES", "SweepSummary", "modulus_interval", "sweep_summary"]

#: most bootstrap replicates (``n_boot``, CLI ``--n-boot``) of the analyses: 100,000 replicates put
#: the percentile ends of a 95 % interval within about 0.1 % of their limit, and keep the arrays of
#: one group (replicates × amplitudes, replicates × seeds) to a few tens of MB
N_BOOT_MAX = 100_000

#: seed of the bootstrap of ``python -m particleShear analyse`` and ``plot`` when none is given (``--seed``
#: overrides): the same call prints the same intervals
DEFAULT_SEED = 0

#: fewest distinct amplitudes for the characteristics read off the shape of the curve (linear limits,
#: flow point, the R package's four points): one amplitude sets the plateau, a second confirms it, and a
#: transition needs two more to be bracketed; with fewer only the plateau and the mean curves are given
MIN_POINT_AMPLITUDES = 4

#: flag of a characteristic (column ``<name>_flag`` of analysis.csv) → meaning
FLAGS = {
    "ok": "an estimate with its interval",
    "lower_bound": ("censored: the point lies beyond the largest amplitude; the value is that amplitude, a lower "
                    "bound (printed '> value'), no interval"),
    "upper_bound": ("censored: the point lies below the smallest amplitude; the value is that amplitude, an upper "
                    "bound (printed '< value'), no interval"),
    "open_above": ("an estimate whose interval reaches beyond the largest amplitude (more than (1 - confidence)/2 "
                   "of the replicates censored there): ci_high is that amplitude, a lower bound of the true end"),
    "open_below": ("an estimate whose interval reaches below the smallest amplitude: ci_low is that amplitude, an "
                   "upper bound of the true end"),
    "open_both": "open_above and open_below at once",
    "too_few_amplitudes": f"not computed: the sweep has fewer than {MIN_POINT_AMPLITUDES} distinct amplitudes",
    "undefined": "no value and no interval (no such point on the mean curve, or a log of a non-positive mean)",
    "non_positive": "a modulus whose point estimate is <= 0: the value, no interval (a modulus interval is >= 0)",
}

#: the characteristics that are one number each
SCALAR_NAMES = ("plateau", "linear_limit_5", "linear_limit_10", "flow_point")
#: the points of :func:`particleShear.analysis.curves.stress_curve_points`, in strain order
POINT_NAMES = CURVE_POINTS
_POINT_PARTS = (("strain", "1", "strain amplitude"), ("Gp", "Pa", "mean G′"), ("Gpp", "Pa", "mean G″"))
_POINT_TEXT = {"low_strain_plateau": "low-strain plateau point", "softening": "softening point",
               "soft_plateau": "soft-plateau point", "yield": "yield point (G′ = G″)"}

#: flat name → (unit, description) of every characteristic, in table order ("1": dimensionless)
CHARACTERISTICS = {
    "plateau": ("Pa", "mean G′ at the smallest amplitude"),
    "linear_limit_5": ("1", "amplitude where the mean G′ first falls 5 % below the plateau (log-log interpolation)"),
    "linear_limit_10": ("1", "amplitude where the mean G′ first falls 10 % below the plateau (log-log interpolation)"),
    "flow_point": ("1", "amplitude where mean G′ = mean G″ (log-log interpolation, curves.yield_point)"),
}
for _p in POINT_NAMES:
    for _part, _unit, _what in _POINT_PARTS:
        CHARACTERISTICS[f"{_p}_{_part}"] = (_unit, (f"{_what} of the {_POINT_TEXT[_p]} of the R package's "
                                                    "stress curve (curves.stress_curve_points) on the mean curve"))
del _p, _part, _unit, _what

#: the characteristics that are moduli (Pa): their intervals are >= 0 (:func:`modulus_interval`)
MODULUS_NAMES = tuple(name for name, (unit, _) in CHARACTERISTICS.items() if unit == "Pa")
#: the characteristics that are strains read off the curve, and may be censored by the measured range
_CENSORABLE = ("linear_limit_5", "linear_limit_10", "flow_point", "yield_strain")

#: columns of :meth:`SweepSummary.curve_rows`: name → (unit, description)
CURVE_COLUMNS = {
    "amplitude": ("1", "strain amplitude"),
    "n_seeds": ("1", "number of runs (seeds) at this amplitude"),
    "Gp_mean": ("Pa", "mean G′ over the seeds"),
    "Gp_ci_low": ("Pa", "lower end of the bootstrap interval of the mean G′"),
    "Gp_ci_high": ("Pa", "upper end of the bootstrap interval of the mean G′"),
    "Gpp_mean": ("Pa", "mean G″ over the seeds"),
    "Gpp_ci_low": ("Pa", "lower end of the bootstrap interval of the mean G″"),
    "Gpp_ci_high": ("Pa", "upper end of the bootstrap interval of the mean G″"),
}


def _frozen(a):
    a = np.array(a, dtype=float)
    a.flags.writeable = False
    return a


@dataclasses.dataclass(frozen=True, eq=False)
class SweepSummary:
    """Mean curves and characteristics of an amplitude sweep with bootstrap intervals (frozen).

    Made by :func:`sweep_summary`.  Arrays are read-only, mappings are read-only views.  An
    interval is ``(low, high)``, the percentile interval of the bootstrap replicates that define
    the quantity; (NaN, NaN) when none does, when the point estimate is undefined or a bound, or for
    a modulus whose estimate is <= 0; ``defined_fraction`` says how many replicates defined it and
    ``flags`` what the value is (:data:`FLAGS`).

    Parameters
    ----------
    amplitudes : numpy.ndarray
        The sorted unique strain amplitudes, shape (n,).
    n_seeds : numpy.ndarray
        Number of runs at each amplitude, shape (n,), int.
    Gp_mean, Gpp_mean : numpy.ndarray
        Mean G′ and G″ over the runs at each amplitude (Pa), shape (n,).
    Gp_ci, Gpp_ci : numpy.ndarray
        Percentile bootstrap interval of each mean (Pa), shape (n, 2), >= 0; NaN where the mean is
        <= 0 (:func:`modulus_interval`).
    plateau : float
        Mean G′ at the smallest amplitude (Pa).
    plateau_ci : tuple of float
        Its interval.
    linear_limit_5, linear_limit_10 : float
        Amplitude where the mean G′ first falls 5 % (10 %) below the plateau; the largest
        amplitude if it never does (flag ``lower_bound``); NaN if the plateau or the G′ just past
        the limit is not positive (no log-log interpolation).
    linear_limit_5_ci, linear_limit_10_ci : tuple of float
        Their intervals.
    flow_point : float
        Amplitude where mean G′ = mean G″ (log-log interpolation); the largest amplitude if G′ > G″
        there (flag ``lower_bound``), the smallest if G′ never exceeds G″ (flag ``upper_bound``);
        NaN if the bracketing means are not positive.
    flow_point_ci : tuple of float
        Its interval.
    points : mapping
        ``{name: (strain, G′, G″)}`` for the names of :data:`POINT_NAMES`, from
        :func:`~particleShear.analysis.curves.stress_curve_points` on the mean curve (NaN where
        undefined).
    points_ci : mapping
        ``{name: array of shape (3, 2)}``: rows strain, G′, G″; columns low, high.
    defined_fraction : mapping
        Flat name of :data:`CHARACTERISTICS` → fraction of the bootstrap replicates in which it
        is finite (a censored replicate counts, at the end of the measured range).
    flags : mapping
        Flat name of :data:`CHARACTERISTICS` → a key of :data:`FLAGS`.
    confidence : float
        Confidence level of the intervals.
    n_boot : int
        Number of bootstrap replicates.
    """

    amplitudes: np.ndarray
    n_seeds: np.ndarray
    Gp_mean: np.ndarray
    Gpp_mean: np.ndarray
    Gp_ci: np.ndarray
    Gpp_ci: np.ndarray
    plateau: float
    plateau_ci: tuple
    linear_limit_5: float
    linear_limit_5_ci: tuple
    linear_limit_10: float
    linear_limit_10_ci: tuple
    flow_point: float
    flow_point_ci: tuple
    points: types.MappingProxyType
    points_ci: types.MappingProxyType
    defined_fraction: types.MappingProxyType
    flags: types.MappingProxyType
    confidence: float
    n_boot: int

    def value(self, name):
        """Point estimate and interval of one characteristic by its flat name.

        Parameters
        ----------
        name : str
            A key of :data:`CHARACTERISTICS` (``"flow_point"``, ``"yield_strain"``, …).

        Returns
        -------
        tuple
            ``(value, (low, high))``, floats.

        Raises
        ------
        ValueError
            For an unknown name.
        """
        if name not in CHARACTERISTICS:
            raise ValueError(f"name={name!r} is invalid: allowed one of {list(CHARACTERISTICS)}")
        if name in SCALAR_NAMES:
            return getattr(self, name), tuple(getattr(self, name + "_ci"))
        point, part = next((p, name[len(p) + 1:]) for p in POINT_NAMES if name.startswith(p + "_"))
        i = [q[0] for q in _POINT_PARTS].index(part)
        return self.points[point][i], (float(self.points_ci[point][i, 0]), float(self.points_ci[point][i, 1]))

    def to_dict(self):
        """The summary as one flat row (the characteristics' part of a row of ``analysis.csv``).

        Returns
        -------
        dict
            ``n_runs``, ``n_amplitudes``, ``amplitude_min``, ``amplitude_max``, ``n_seeds_min``,
            ``n_seeds_max``, ``confidence``, ``n_boot``, then for each name of
            :data:`CHARACTERISTICS`: ``name``, ``name_ci_low``, ``name_ci_high``,
            ``name_defined`` (fraction of replicates), ``name_flag`` (a key of :data:`FLAGS`).  Python
            floats, ints and str; NaN where undefined.
        """
        out = {"n_runs": int(self.n_seeds.sum()), "n_amplitudes": len(self.amplitudes),
               "amplitude_min": float(self.amplitudes[0]), "amplitude_max": float(self.amplitudes[-1]),
               "n_seeds_min": int(self.n_seeds.min()), "n_seeds_max": int(self.n_seeds.max()),
               "confidence": float(self.confidence), "n_boot": int(self.n_boot)}
        for name in CHARACTERISTICS:
            v, (lo, hi) = self.value(name)
            out[name] = float(v)
            out[name + "_ci_low"] = float(lo)
            out[name + "_ci_high"] = float(hi)
            out[name + "_defined"] = float(self.defined_fraction[name])
            out[name + "_flag"] = self.flags[name]
        return out

    def curve_rows(self):
        """The mean curves, one dict per amplitude (columns of :data:`CURVE_COLUMNS`).

        Returns
        -------
        list of dict
        """
        return [{"amplitude": float(a), "n_seeds": int(n), "Gp_mean": float(gp), "Gp_ci_low": float(gpc[0]),
                 "Gp_ci_high": float(gpc[1]), "Gpp_mean": float(gpp), "Gpp_ci_low": float(gppc[0]),
                 "Gpp_ci_high": float(gppc[1])}
                for a, n, gp, gpc, gpp, gppc in zip(self.amplitudes, self.n_seeds, self.Gp_mean, self.Gp_ci,
                                                    self.Gpp_mean, self.Gpp_ci)]


# ---------------------------------------------------------------------------------------------
# checks
# ---------------------------------------------------------------------------------------------
def _vector(name, x):
    try:
        a = np.asarray(x, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{name} is invalid: allowed a 1-D sequence of real numbers, got {type(x).__name__}") \
            from None
    if a.ndim != 1:
        raise ValueError(f"{name} is invalid: allowed a 1-D sequence of real numbers, got shape {a.shape}")
    bad = ~np.isfinite(a)
    if bad.any():
        i = int(np.argmax(bad))
        raise ValueError(f"{name}[{i}]={float(a[i])!r} is out of range: allowed finite numbers")
    return a


def _short(a):
    """``a`` as a short list text for a message."""
    items = [f"{x:g}" for x in a[:6]]
    return "[" + ", ".join(items) + (", ...]" if len(a) > 6 else "]")


def _check(amplitude, Gp, Gpp, n_boot, confidence, rng):
    A, gp, gpp = _vector("amplitude", amplitude), _vector("Gp", Gp), _vector("Gpp", Gpp)
    if not (len(A) == len(gp) == len(gpp)):
        raise ValueError(f"amplitude, Gp, Gpp are invalid: allowed equal lengths, got {len(A)}, {len(gp)}, "
                         f"{len(gpp)}")
    if (A <= 0).any():
        i = int(np.argmax(A <= 0))
        raise ValueError(f"amplitude[{i}]={float(A[i])!r} is out of range: allowed amplitude > 0")
    n_amp = len(np.unique(A))
    if n_amp < 2:
        raise ValueError(f"amplitude={_short(A)} is out of range: {n_amp} distinct value(s), allowed at least 2 "
                         "distinct amplitudes")
    return (A, gp, gpp) + _check_resampling(n_boot, confidence, rng)


def _check_resampling(n_boot, confidence, rng):
    """The checked bootstrap settings ``(n_boot, confidence, generator)`` (ValueError otherwise)."""
    if isinstance(n_boot, (bool, np.bool_)) or not isinstance(n_boot, numbers.Integral):
        raise ValueError(f"n_boot={n_boot!r} is invalid: allowed an integer >= 1 and <= {N_BOOT_MAX} "  # noqa: TRY004
                         "(CLI --n-boot)")
    if not 1 <= n_boot <= N_BOOT_MAX:
        raise ValueError(f"n_boot={n_boot!r} is out of range: allowed an integer >= 1 and <= {N_BOOT_MAX} "
                         "(CLI --n-boot)")
    if isinstance(confidence, (bool, np.bool_)) or not isinstance(confidence, numbers.Real) \
            or not (0 < confidence < 1):
        raise ValueError(f"confidence={confidence!r} is out of range: allowed a number in (0, 1)")
    if rng is None or isinstance(rng, np.random.Generator):
        gen = np.random.default_rng(rng)
    elif isinstance(rng, numbers.Integral) and not isinstance(rng, (bool, np.bool_)):
        if rng < 0:
            raise ValueError(f"rng={rng!r} is out of range: allowed None, an integer >= 0 or a "
                             "numpy.random.Generator")
        gen = np.random.default_rng(int(rng))
    else:
        raise ValueError(f"rng={rng!r} is invalid: allowed None, an integer >= 0 or a numpy.random.Generator")
    return int(n_boot), float(confidence), gen


# ---------------------------------------------------------------------------------------------
# characteristics of many curves at once (rows = curves)
# ---------------------------------------------------------------------------------------------
def _linear_limits(A, Gp, fraction):
    """Amplitude where each row of ``Gp`` (shape (B, n), amplitudes ``A`` ascending) first falls to
    ``(1 - fraction)`` × its first value, log-log interpolated, and whether it is censored: rows with a
    positive plateau that never fall that far get the largest amplitude and ``True``; NaN where a log
    is not defined."""
    plateau = Gp[:, 0]
    target = (1.0 - fraction) * plateau
    below = Gp[:, 1:] <= target[:, None]
    found = below.any(axis=1) & (plateau > 0)
    censored = ~below.any(axis=1) & (plateau > 0)
    j = np.argmax(below, axis=1) + 1               # first amplitude at or below the target
    rows = np.arange(len(Gp))
    g0, g1 = Gp[rows, j - 1], Gp[rows, j]           # g0 > target >= g1
    ok = found & (g1 > 0)
    out = np.full(len(Gp), np.nan)
    if ok.any():
        u = np.log(A)
        r, jj = rows[ok], j[ok]
        lg0, lg1, lt = np.log(g0[ok]), np.log(g1[ok]), np.log(target[ok])
        t = (lt - lg0) / (lg1 - lg0)                # in (0, 1]: lg1 <= lt < lg0
        out[r] = np.exp(u[jj - 1] + t * (u[jj] - u[jj - 1]))
    out[censored] = A[-1]
    return out, censored


def _curve_characteristics(A, Gp, Gpp, guesses=(0.01, 0.1)):
    """Flat characteristics (order of :data:`CHARACTERISTICS`) of each row of ``Gp``/``Gpp`` (shape (B, n),
    amplitudes ``A`` ascending) and their censoring (int8, same shape: +1 beyond the largest amplitude, −1
    below the smallest, 0 not censored); ``guesses`` = (guess_softening_strain, guess_soft_plateau_strain)
    of the R rules.  A censored strain is the end of the range; the G′, G″ of a censored yield point NaN."""
    B = len(Gp)
    names = list(CHARACTERISTICS)
    col = {name: i for i, name in enumerate(names)}
    out = np.full((B, len(names)), np.nan)
    censor = np.zeros((B, len(names)), dtype=np.int8)
    out[:, col["plateau"]] = Gp[:, 0]
    for name, frac in (("linear_limit_5", 0.05), ("linear_limit_10", 0.10)):
        out[:, col[name]], above = _linear_limits(A, Gp, frac)
        censor[above, col[name]] = 1
    # the crossing read from above (curves.yield_point): G′ > G″ at the largest amplitude → beyond the range;
    # G′ > G″ nowhere → below it
    cross_above = Gp[:, -1] > Gpp[:, -1]
    cross_below = ~(Gp > Gpp).any(axis=1)
    with np.errstate(all="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)   # logs of non-positive means: NaN, said by the docs
        for b in range(B):
            gp, gpp = Gp[b], Gpp[b]
            try:
                out[b, col["flow_point"]] = yield_point(A, gp, gpp, interpolation="log")
            except (ValueError, ZeroDivisionError):        # a log of a non-positive mean
                pass
            try:
                pts = stress_curve_points(A, gp, gpp, *guesses)
            except (ValueError, ZeroDivisionError):
                continue
            out[b, col["low_strain_plateau_strain"]:] = [float(x) for name in POINT_NAMES for x in pts[name]]
    out[~np.isfinite(out)] = np.nan
    for name in ("flow_point", "yield_strain"):
        out[cross_above, col[name]], censor[cross_above, col[name]] = A[-1], 1
        out[cross_below, col[name]], censor[cross_below, col[name]] = A[0], -1
    out[cross_above | cross_below, col["yield_Gp"]] = np.nan
    out[cross_above | cross_below, col["yield_Gpp"]] = np.nan
    return out, censor


def _percentile_interval(samples, confidence):
    """Column-wise percentile interval over the finite entries (NaN, NaN for a column with none)
    and the fraction of finite entries; ``samples`` of shape (B, m)."""
    finite = np.isfinite(samples)
    frac = finite.mean(axis=0)
    q = 50.0 * (1.0 - confidence)
    ci = np.full((samples.shape[1], 2), np.nan)
    some = finite.any(axis=0)
    if some.any():
        ci[some] = np.nanpercentile(samples[:, some], [q, 100.0 - q], axis=0).T
    return ci, frac


def modulus_interval(samples, estimate, confidence):
    """Percentile interval of the bootstrap replicates of a modulus, computed on their logarithm.

    The ``(1 ± confidence)/2`` percentiles of log(replicate) over the finite replicates (linear
    interpolation between order statistics), exponentiated: the interval is >= 0 by construction.
    A replicate <= 0 has log −∞: an interval end that falls on one is 0.  A modulus whose estimate
    is not > 0 has no interval (a log-scale interval of it does not exist; flag ``non_positive``).

    Parameters
    ----------
    samples : array_like
        Bootstrap replicates of the modulus (Pa), 1-D; NaN entries are left out.
    estimate : float
        The point estimate (Pa).
    confidence : float
        Level, in (0, 1).

    Returns
    -------
    tuple of float
        ``(low, high)`` in Pa with ``0 <= low <= high``, or ``(nan, nan)`` when ``estimate`` is not
        finite and > 0 or no replicate is finite.

    Raises
    ------
    ValueError
        ``samples`` not 1-D real numbers, or ``confidence`` not in (0, 1).

    Examples
    --------
    >>> modulus_interval([-50.0, 10.0, 100.0, 1000.0], 265.0, 0.5)   # never below 0
    (0.0, 177.82794100389225)
    """
    try:
        s = np.asarray(samples, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"samples is invalid: allowed a 1-D sequence of real numbers, got "
                         f"{type(samples).__name__}") from None
    if s.ndim != 1:
        raise ValueError(f"samples is invalid: allowed a 1-D sequence of real numbers, got shape {s.shape}")
    if isinstance(confidence, (bool, np.bool_)) or not isinstance(confidence, numbers.Real) \
            or not (0 < confidence < 1):
        raise ValueError(f"confidence={confidence!r} is out of range: allowed a number in (0, 1)")
    s = np.sort(s[np.isfinite(s)])
    if not (math.isfinite(estimate) and estimate > 0) or len(s) == 0:
        return math.nan, math.nan
    q = 0.5 * (1.0 - confidence)
    ends = []
    for p in (q, 1.0 - q):
        h = (len(s) - 1) * p
        i = int(math.floor(h))
        j = min(i + 1, len(s) - 1)
        if s[i] <= 0:                                # the end falls on a replicate with log −∞
            ends.append(0.0)
        elif s[i] == s[j]:
            ends.append(float(s[i]))
        else:
            li, lj = math.log(s[i]), math.log(s[j])    # s[j] >= s[i] > 0
            ends.append(float(math.exp(li + (h - i) * (lj - li))))
    return ends[0], ends[1]


def _characteristic_intervals(point, point_censor, reps, reps_censor, A, confidence):
    """Interval, flag of each characteristic: ``ci`` (m, 2), ``flags`` list of keys of :data:`FLAGS` (rules
    in :data:`FLAGS`; an interval only beside an estimate, moduli by :func:`modulus_interval`)."""
    q = 0.5 * (1.0 - confidence)
    ci, _ = _percentile_interval(reps, confidence)
    flags = []
    for j, name in enumerate(CHARACTERISTICS):
        v, c = point[j], int(point_censor[j])
        if c:
            flags.append("lower_bound" if c > 0 else "upper_bound")
            ci[j] = np.nan
        elif not math.isfinite(v):
            flags.append("undefined")
            ci[j] = np.nan
        elif name in MODULUS_NAMES:
            ci[j] = modulus_interval(reps[:, j], v, confidence)
            flags.append("ok" if v > 0 else "non_positive")
        elif name in _CENSORABLE:
            above = float(np.mean(reps_censor[:, j] > 0))
            below = float(np.mean(reps_censor[:, j] < 0))
            if above > q:
                ci[j, 1] = A[-1]
            if below > q:
                ci[j, 0] = A[0]
            flags.append("open_both" if above > q and below > q else "open_above" if above > q
                         else "open_below" if below > q else "ok")
        else:
            flags.append("ok")
    return ci, flags


def _widen_log(boot, mean, factor):
    """Replicate means ``boot`` (B, n) moved away from ``mean`` (n,) by ``factor`` (n,) on the log scale where
    the mean is > 0 (a replicate <= 0 there becomes 0), linearly where it is not."""
    linear = mean + factor * (boot - mean)
    with np.errstate(divide="ignore", invalid="ignore"):
        logscale = mean * np.exp(factor * (np.log(boot) - np.log(mean)))
    logscale = np.where(boot > 0, logscale, 0.0)
    return np.where(mean > 0, logscale, linear)


# ---------------------------------------------------------------------------------------------
# the summary
# ---------------------------------------------------------------------------------------------
def _student_factor(count, confidence):
    """Factor that widens a bootstrap spread of the mean of ``count`` runs to a Student-t interval.

    The bootstrap mean of n runs spreads with the ``ddof=0`` standard error, √((n−1)/n)·s/√n, and
    its percentile interval uses normal quantiles; ``√(n/(n−1))·t_{n−1}/z`` makes the interval of a
    mean the exact t interval for normal runs (1 for n = 1: nothing to widen).
    """
    from statistics import NormalDist
    alpha = 1.0 - confidence
    z = NormalDist().inv_cdf(1.0 - alpha / 2.0)
    return np.array([1.0 if c < 2 else math.sqrt(c / (c - 1.0)) * t_critical(int(c) - 1, alpha) / z
                     for c in np.atleast_1d(count).tolist()])


def sweep_summary(amplitude, Gp, Gpp, n_boot=2000, confidence=0.95, rng=None, student=True,
                  guess_softening_strain=0.01, guess_soft_plateau_strain=0.1):
    """Mean G′/G″ curves of an amplitude sweep, their characteristics and bootstrap intervals.

    The runs at each amplitude (seeds) are averaged; the characteristics of :data:`CHARACTERISTICS`
    are taken from the mean curves.  Each interval is a percentile bootstrap interval at level
    ``confidence``: in each of ``n_boot`` replicates the runs at every amplitude are resampled with
    replacement *within* that amplitude (a run keeps its pair G′, G″), the mean curves are
    recomputed and every characteristic is extracted again; the interval is the
    ``(1 ± confidence)/2`` percentiles of the replicates in which the characteristic is finite
    (``SweepSummary.defined_fraction`` says in how many it is; an interval built on few of them
    deserves little trust).  Plain percentile intervals of a mean from few seeds undercover (a
    bootstrap mean spreads with the ``ddof=0`` standard error and its percentiles are normal, not
    Student, quantiles: about 72 % instead of 95 % for 4 normal seeds, 88 % for 8).  With
    ``student=True`` (default) each replicate mean is therefore moved away from the sample mean by
    the factor ``√(n/(n−1))·t_{n−1}/z`` of its amplitude's n runs before the characteristics are
    extracted — on the log scale where the mean is > 0 (``mean·(replicate/mean)^factor``, so a
    widened modulus stays positive), linearly where it is not — which makes the interval of a
    mean the Student-t interval of its logarithm and carries that width into every characteristic
    (docs/analysis.md gives the measured coverage, ``benchmarks/interval_coverage.py``).

    Moduli intervals (the mean curves, the plateau, the G′ and G″ of the points) are
    :func:`modulus_interval`: >= 0, none for an estimate <= 0.  A strain beyond the measured
    amplitudes is reported as a bound, with no interval (flags ``lower_bound``, ``upper_bound``);
    an estimate whose replicates are censored in more than ``(1 − confidence)/2`` of the cases
    gets the range end as that end of its interval (``open_above``, ``open_below``).  An interval
    is given only beside an estimate.  With fewer than :data:`MIN_POINT_AMPLITUDES` distinct
    amplitudes only the plateau and the mean curves are computed (the other characteristics are
    NaN with the flag ``too_few_amplitudes``, and a ``UserWarning`` says so).

    With one run at an amplitude the replicates cannot vary there: its interval has zero width and
    the intervals of the characteristics understate the uncertainty (with one run everywhere, all
    intervals collapse to the point estimate).  A ``UserWarning`` says so.

    Log-log quantities (linear limits, flow point) need positive means at the bracketing
    amplitudes; where a mean is zero or negative they are NaN (no error, flag ``undefined``).

    Parameters
    ----------
    amplitude : array_like
        Strain amplitude of each run (long format, any order), > 0, finite, shape (m,).  At least
        two distinct amplitudes.
    Gp : array_like
        Storage modulus G′ of each run (Pa), finite, shape (m,).
    Gpp : array_like
        Loss modulus G″ of each run (Pa), finite, shape (m,).
    n_boot : int, optional
        Number of bootstrap replicates, 1 ... :data:`N_BOOT_MAX` (default 2000).
    confidence : float, optional
        Level of the intervals, in (0, 1) (default 0.95).
    rng : None, int or numpy.random.Generator, optional
        Source of the resampling: None (fresh entropy), an integer seed >= 0 (reproducible), or a
        Generator (used, and advanced, as is).
    student : bool, optional
        Widen the replicates to Student-t width for the number of seeds (default True); False gives
        the plain percentile bootstrap.
    guess_softening_strain, guess_soft_plateau_strain : float, optional
        Passed to :func:`~particleShear.analysis.curves.stress_curve_points` (defaults 0.01, 0.1).

    Returns
    -------
    SweepSummary

    Raises
    ------
    ValueError
        Naming the parameter, its value and the allowed range: inputs of other lengths or not
        1-D, non-finite values, an amplitude <= 0, fewer than 2 distinct amplitudes, ``n_boot``
        not an integer >= 1, ``confidence`` not in (0, 1), ``rng`` of another kind.

    Examples
    --------
    >>> import numpy as np
    >>> A = np.repeat([0.01, 0.1, 1.0, 10.0], 3)
    >>> x = A / 1.0
    >>> s = sweep_summary(A, 1000 / (1 + x**2), 500 * x / (1 + x**2), n_boot=200, rng=1)
    >>> round(s.flow_point, 6), s.flags["flow_point"]
    (2.0, 'ok')
    """
    A, gp, gpp, n_boot, confidence, gen = _check(amplitude, Gp, Gpp, n_boot, confidence, rng)
    amps, inverse = np.unique(A, return_inverse=True)
    n = len(amps)
    counts = np.bincount(inverse, minlength=n)
    order = np.argsort(inverse, kind="stable")
    starts = np.concatenate([[0], np.cumsum(counts)[:-1]])
    gp_s, gpp_s = gp[order], gpp[order]
    gp_mean = np.array([gp_s[s:s + c].mean() for s, c in zip(starts, counts)])
    gpp_mean = np.array([gpp_s[s:s + c].mean() for s, c in zip(starts, counts)])
    # bootstrap means: all indices of one amplitude drawn at once
    gp_boot = np.empty((n_boot, n))
    gpp_boot = np.empty((n_boot, n))
    for i, (s, c) in enumerate(zip(starts, counts)):
        idx = s + gen.integers(0, c, size=(n_boot, c))
        gp_boot[:, i] = gp_s[idx].mean(axis=1)
        gpp_boot[:, i] = gpp_s[idx].mean(axis=1)
    if student:
        widen = _student_factor(counts, confidence)
        gp_boot = _widen_log(gp_boot, gp_mean, widen)
        gpp_boot = _widen_log(gpp_boot, gpp_mean, widen)
    single = amps[counts == 1]
    if len(single):
        what = "every amplitude has" if len(single) == n else f"amplitude(s) {[float(a) for a in single]} have"
        warnings.warn(f"sweep_summary: {what} one run only: the bootstrap intervals there have zero width and the "
                      "intervals of the characteristics understate the uncertainty", UserWarning, stacklevel=2)
    gp_ci = np.array([modulus_interval(gp_boot[:, i], gp_mean[i], confidence) for i in range(n)])
    gpp_ci = np.array([modulus_interval(gpp_boot[:, i], gpp_mean[i], confidence) for i in range(n)])
    names = list(CHARACTERISTICS)
    k = {name: i for i, name in enumerate(names)}
    if n >= MIN_POINT_AMPLITUDES:
        guesses = (guess_softening_strain, guess_soft_plateau_strain)
        point, point_censor = _curve_characteristics(amps, gp_mean[None, :], gpp_mean[None, :], guesses)
        reps, reps_censor = _curve_characteristics(amps, gp_boot, gpp_boot, guesses)
    else:     # the plateau only: the other characteristics need the shape of the curve
        warnings.warn(f"sweep_summary: {n} distinct amplitudes: the linear limits, the flow point and the R "
                      f"package's points need >= {MIN_POINT_AMPLITUDES} and are not computed (only the plateau "
                      "and the mean curves)", UserWarning, stacklevel=2)
        point, reps = np.full((1, len(names)), np.nan), np.full((n_boot, len(names)), np.nan)
        point[0, k["plateau"]], reps[:, k["plateau"]] = gp_mean[0], gp_boot[:, 0]
        point_censor, reps_censor = np.zeros(point.shape, np.int8), np.zeros(reps.shape, np.int8)
    point, point_censor = point[0], point_censor[0]
    _, frac = _percentile_interval(reps, confidence)
    ci, flag_list = _characteristic_intervals(point, point_censor, reps, reps_censor, amps, confidence)
    if n < MIN_POINT_AMPLITUDES:
        flag_list = [f if name == "plateau" else "too_few_amplitudes" for name, f in zip(names, flag_list)]

    def scalar(name):
        return float(point[k[name]]), (float(ci[k[name], 0]), float(ci[k[name], 1]))

    points, points_ci = {}, {}
    for p in POINT_NAMES:
        rows = [k[f"{p}_{part}"] for part, _, _ in _POINT_PARTS]
        points[p] = tuple(float(point[r]) for r in rows)
        points_ci[p] = _frozen(ci[rows])
    values = {name: scalar(name) for name in SCALAR_NAMES}
    return SweepSummary(
        amplitudes=_frozen(amps), n_seeds=_frozen_int(counts), Gp_mean=_frozen(gp_mean), Gpp_mean=_frozen(gpp_mean),
        Gp_ci=_frozen(gp_ci), Gpp_ci=_frozen(gpp_ci),
        plateau=values["plateau"][0], plateau_ci=values["plateau"][1],
        linear_limit_5=values["linear_limit_5"][0], linear_limit_5_ci=values["linear_limit_5"][1],
        linear_limit_10=values["linear_limit_10"][0], linear_limit_10_ci=values["linear_limit_10"][1],
        flow_point=values["flow_point"][0], flow_point_ci=values["flow_point"][1],
        points=types.MappingProxyType(points), points_ci=types.MappingProxyType(points_ci),
        defined_fraction=types.MappingProxyType({name: float(frac[i]) for i, name in enumerate(names)}),
        flags=types.MappingProxyType(dict(zip(names, flag_list))), confidence=confidence, n_boot=n_boot)


def _frozen_int(a):
    a = np.array(a, dtype=int)
    a.flags.writeable = False
    return a
