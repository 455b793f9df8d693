"""Herschel–Bulkley fit of a flow curve, with bootstrap intervals over seeds.

A steady-shear flow curve — shear stress σ against shear rate γ̇ — of a yield-stress material is
commonly described by the Herschel–Bulkley law

    σ(γ̇) = σ_y + K·γ̇ⁿ,    σ_y ≥ 0,  K > 0,  0 < n ≤ 2,

with the yield stress σ_y (Pa), the consistency K (Pa·sⁿ) and the flow index n (dimensionless;
n = 1 is a Bingham fluid, σ_y = 0 a power-law fluid, n < 1 shear thinning).

:func:`herschel_bulkley_fit` fits it by (weighted) least squares in σ; :func:`herschel_bulkley_bootstrap`
fits the mean flow curve of several runs (seeds) per rate and gives percentile bootstrap intervals
of σ_y, K and n, the seeds resampled with replacement.

The fit is a profile least squares: for a fixed n the law is linear in (σ_y, K), solved exactly
under σ_y ≥ 0, K ≥ 0; the residual sum of squares of that solution is then minimised over n by a
grid of :data:`N_GRID` points in (0, 2] and a golden-section refinement between the neighbours of
the best grid point.

A fit with a parameter on a bound of the law — σ_y = 0, n = 2, or n below the first grid point
2/:data:`N_GRID` — is degenerate: the law does not describe the data there, or σ_y and K trade off
(:attr:`HerschelBulkley.degenerate` gives the reasons; ``analyse`` flags the rows ``degenerate_fit``).

NumPy only (no SciPy).
"""
__docformat__ = "numpy"
import dataclasses
import math
import types
import warnings

import numpy as np

from .sweep import _check_resampling, _percentile_interval, _vector

__all__ = ["FlowCurveFit", "HerschelBulkley", "N_GRID", "N_LOW", "fit_flow_curve", "flow_curve_table", "herschel_bulkley_bootstrap",
           "herschel_bulkley_fit"]

#: number of flow indices n = 2k/N_GRID (k = 1 … N_GRID) of the coarse search
N_GRID = 41
_N_MAX = 2.0
#: flow index below which a fit counts as on its lower bound n → 0 (the first grid point 2/N_GRID ≈ 0.049):
#: the stress then hardly depends on the rate and σ_y and K are not separately determined
N_LOW = _N_MAX / N_GRID
_N_MIN = 1e-3                 # lower end of the refinement below the first grid point
_GOLDEN_STEPS = 60            # bracket width 2·2/41 · 0.618^60 ≈ 3e-14
_INV_PHI = (math.sqrt(5.0) - 1.0) / 2.0
_PARAMETERS = ("sigma_y", "K", "n")


@dataclasses.dataclass(frozen=True)
class HerschelBulkley:
    """A fitted Herschel–Bulkley law σ = σ_y + K·γ̇ⁿ (frozen).

    Made by :func:`herschel_bulkley_fit`.

    Parameters
    ----------
    sigma_y : float
        Yield stress σ_y (Pa), >= 0.
    K : float
        Consistency K (Pa·sⁿ), > 0.
    n : float
        Flow index n (dimensionless), in (0, 2].
    rss : float
        Weighted residual sum of squares Σ wᵢ (σᵢ − σ_y − K·γ̇ᵢⁿ)² of the fit (Pa²).
    """

    sigma_y: float
    K: float
    n: float
    rss: float

    @property
    def degenerate(self):
        """Why the fit is degenerate — a parameter on a bound of the law; empty when none is.

        Returns
        -------
        tuple of str
            One reason per parameter on a bound: σ_y = 0 (no yield stress resolved), n = 2 (the
            stress curves upward more steeply than the law allows), n < :data:`N_LOW` (the stress
            hardly depends on the rate: σ_y and K trade off).
        """
        out = []
        if self.sigma_y <= 0:
            out.append("sigma_y on its bound 0: no yield stress resolved (a power law fits as well)")
        if self.n >= _N_MAX * (1 - 1e-9):
            out.append(f"n = {self.n:.3g} on its upper bound {_N_MAX:g}: the stress rises more steeply than the law "
                       "allows (K and sigma_y not meaningful)")
        elif self.n < N_LOW:
            out.append(f"n = {self.n:.3g} below {N_LOW:.3g}, at its lower bound 0: the stress hardly depends on the "
                       "rate (sigma_y and K trade off)")
        return tuple(out)

    def stress(self, rate):
        """Shear stress of the law at the given shear rates.

        Parameters
        ----------
        rate : float or array_like
            Shear rate γ̇ (1/s), finite, >= 0.

        Returns
        -------
        float or numpy.ndarray
            σ_y + K·γ̇ⁿ (Pa), a float for a scalar rate, otherwise an array of the shape of ``rate``.

        Raises
        ------
        ValueError
            ``rate`` not real, not finite or negative.
        """
        try:
            r = np.asarray(rate, dtype=float)
        except (TypeError, ValueError):
            raise ValueError(f"rate={rate!r} is invalid: allowed real numbers >= 0") from None
        bad = ~np.isfinite(r) | (r < 0)
        if bad.any():
            raise ValueError(f"rate={float(r.flat[int(np.argmax(bad))])!r} is out of range: allowed finite "
                             "numbers >= 0")
        out = self.sigma_y + self.K * r ** self.n
        return float(out) if out.ndim == 0 else out


@dataclasses.dataclass(frozen=True, eq=False)
class FlowCurveFit:
    """Herschel–Bulkley fit of a mean flow curve with bootstrap intervals (frozen).

    Made by :func:`herschel_bulkley_bootstrap`.

    Parameters
    ----------
    fit : HerschelBulkley
        The fit of the per-rate means over the seeds.
    intervals : mapping
        ``{"sigma_y": (low, high), "K": (low, high), "n": (low, high)}``: percentile bootstrap
        interval of each parameter (units of :class:`HerschelBulkley`); (NaN, NaN) when no
        replicate could be fitted.
    n_boot : int
        Number of bootstrap replicates.
    confidence : float
        Confidence level of the intervals.
    n_seeds : int
        Number of seeds (columns of the stress table).

    Notes
    -----
    ``degenerate`` (the reasons of :attr:`HerschelBulkley.degenerate` of ``fit``) is empty for a
    fit whose parameters are inside the bounds of the law.
    """

    fit: HerschelBulkley
    intervals: types.MappingProxyType
    n_boot: int
    confidence: float
    n_seeds: int

    @property
    def yield_stress(self):
        """The fitted yield stress σ_y (Pa), ``fit.sigma_y``."""
        return self.fit.sigma_y

    @property
    def degenerate(self):
        """Why the point fit is degenerate (:attr:`HerschelBulkley.degenerate`); empty when it is not."""
        return self.fit.degenerate


# ---------------------------------------------------------------------------------------------
# the fit of many data sets with shared rates at once (rows = data sets)
# ---------------------------------------------------------------------------------------------
def _solve(x, y, w):
    """Least squares of ``y ≈ a + k·x`` with a >= 0, k >= 0, row by row.

    ``x`` shape (B, m) or (m,), ``y`` and ``w`` shape (B, m).  The two-variable problem is solved
    exactly: the unconstrained solution where it is feasible, otherwise the best of the boundary
    solutions (a = 0; k = 0; a = k = 0).  Returns ``a, k, rss`` of shape (B,)."""
    x = np.broadcast_to(x, y.shape)
    with np.errstate(all="ignore"):
        sw = w.sum(axis=1)
        xm = (w * x).sum(axis=1) / sw
        ym = (w * y).sum(axis=1) / sw
        dx, dy = x - xm[:, None], y - ym[:, None]
        k_free = (w * dx * dy).sum(axis=1) / (w * dx * dx).sum(axis=1)
        a_free = ym - k_free * xm
        k_zero_a = (w * x * y).sum(axis=1) / (w * x * x).sum(axis=1)
        cand_a = np.stack([a_free, np.zeros_like(ym), ym, np.zeros_like(ym)])
        cand_k = np.stack([k_free, k_zero_a, np.zeros_like(ym), np.zeros_like(ym)])
        res = y[None] - cand_a[:, :, None] - cand_k[:, :, None] * x[None]
        rss = (w[None] * res * res).sum(axis=2)
    ok = (cand_a >= 0) & (cand_k >= 0) & np.isfinite(rss)
    rss = np.where(ok, rss, np.inf)
    best = np.argmin(rss, axis=0)
    rows = np.arange(y.shape[0])
    return cand_a[best, rows], cand_k[best, rows], rss[best, rows]


def _fit_rows(rate, y, w):
    """Herschel–Bulkley fit of each row of ``y`` (shape (B, m)) at the shared ``rate`` (m,) with
    weights ``w`` (B, m; 0 drops a point).  Returns ``sigma_y, K, n, rss`` of shape (B,); NaN in
    rows with fewer than 3 distinct rates of positive weight, n = NaN where K = 0 (n undefined)."""
    B = y.shape[0]
    ref = math.exp(float(np.mean(np.log(rate))))      # rates scaled to O(1): a conditioned x = (γ̇/ref)ⁿ
    u = np.log(rate / ref)
    grid = _N_MAX * np.arange(1, N_GRID + 1) / N_GRID
    rss_grid = np.stack([_solve(np.exp(n * u), y, w)[2] for n in grid], axis=1)   # (B, N_GRID)
    kbest = np.argmin(rss_grid, axis=1)
    lo = np.where(kbest > 0, grid[np.maximum(kbest - 1, 0)], _N_MIN)
    hi = grid[np.minimum(kbest + 1, N_GRID - 1)]

    def rss_at(n):
        return _solve(np.exp(n[:, None] * u[None, :]), y, w)[2]

    # golden section on [lo, hi], all rows at once (rss is evaluated at two interior points)
    c, d = hi - _INV_PHI * (hi - lo), lo + _INV_PHI * (hi - lo)
    fc, fd = rss_at(c), rss_at(d)
    for _ in range(_GOLDEN_STEPS):
        left = fc <= fd                               # the minimum lies in [lo, d]
        hi, lo = np.where(left, d, hi), np.where(left, lo, c)
        c_new = np.where(left, hi - _INV_PHI * (hi - lo), d)
        d_new = np.where(left, c, lo + _INV_PHI * (hi - lo))
        c, d = c_new, d_new
        moved = np.where(left, c, d)
        f_moved = rss_at(moved)
        fc, fd = np.where(left, f_moved, fd), np.where(left, fc, f_moved)
    n_ref = np.where(fc <= fd, c, d)
    rss_ref = np.minimum(fc, fd)
    n = np.where(rss_ref <= rss_grid[np.arange(B), kbest], n_ref, grid[kbest])
    a, k, rss = _solve(np.exp(n[:, None] * u[None, :]), y, w)
    distinct = np.array([len(np.unique(rate[row > 0])) for row in w])
    bad = (distinct < 3) | ~np.isfinite(rss)
    K = k / ref ** n
    n = np.where(k > 0, n, np.nan)
    out = [np.where(bad, np.nan, v) for v in (a, K, n, rss)]
    return tuple(out)


# ---------------------------------------------------------------------------------------------
# the public fits
# ---------------------------------------------------------------------------------------------
def _check_rates(rate, name="rate"):
    r = _vector(name, rate)
    if (r <= 0).any():
        i = int(np.argmax(r <= 0))
        raise ValueError(f"{name}[{i}]={float(r[i])!r} is out of range: allowed shear rates > 0")
    return r


def _result(a, K, n, rss):
    if not (K > 0):
        raise ValueError("stress is out of range: no Herschel-Bulkley fit with K > 0 exists, the stress does not "
                         "increase with the rate; allowed a flow curve whose stress increases with the rate")
    return HerschelBulkley(sigma_y=float(a), K=float(K), n=float(n), rss=float(rss))


def herschel_bulkley_fit(rate, stress, weights=None):
    """Least-squares fit of the Herschel–Bulkley law σ = σ_y + K·γ̇ⁿ to a flow curve.

    Minimises Σ wᵢ (σᵢ − σ_y − K·γ̇ᵢⁿ)² under σ_y >= 0, K > 0, 0 < n <= 2.  For a fixed n the law
    is linear in (σ_y, K): the weighted linear least squares is solved exactly, and where it gives
    σ_y < 0 (or K < 0) the best solution on the boundary (σ_y = 0, a power law) is taken.  The
    residual sum of squares of that solution is minimised over n on a grid of :data:`N_GRID` values
    in (0, 2] and refined by golden-section search between the neighbours of the best grid value
    (a flow index at the edge n = 2 means the data curve more steeply than the law allows).

    Parameters
    ----------
    rate : array_like
        Shear rate γ̇ of each point (1/s), finite, > 0, shape (m,); at least 3 distinct rates (of
        positive weight).
    stress : array_like
        Shear stress σ of each point (Pa), finite, shape (m,).
    weights : array_like, optional
        Weight wᵢ of each point, finite, >= 0, shape (m,) (e.g. 1/variance of a mean); default
        all 1.  A weight 0 leaves the point out.

    Returns
    -------
    HerschelBulkley

    Raises
    ------
    ValueError
        Naming the parameter, its value and the allowed range: inputs not 1-D or of other lengths,
        non-finite values, a rate <= 0, a negative weight, fewer than 3 distinct rates of positive
        weight, or a stress that does not increase with the rate (no fit with K > 0).

    Examples
    --------
    >>> import numpy as np
    >>> rate = np.logspace(-2, 2, 9)
    >>> hb = herschel_bulkley_fit(rate, 5.0 + 2.0 * rate ** 0.5)
    >>> round(hb.sigma_y, 6), round(hb.K, 6), round(hb.n, 6)
    (5.0, 2.0, 0.5)
    """
    r = _check_rates(rate)
    s = _vector("stress", stress)
    w = np.ones_like(r) if weights is None else _vector("weights", weights)
    if not (len(r) == len(s) == len(w)):
        raise ValueError(f"rate, stress, weights are invalid: allowed equal lengths, got {len(r)}, {len(s)}, "
                         f"{len(w)}")
    if (w < 0).any():
        i = int(np.argmax(w < 0))
        raise ValueError(f"weights[{i}]={float(w[i])!r} is out of range: allowed weights >= 0")
    distinct = len(np.unique(r[w > 0]))
    if distinct < 3:
        raise ValueError(f"rate is out of range: {distinct} distinct rate(s) of positive weight, allowed at least 3")
    return _result(*(v[0] for v in _fit_rows(r, s[None, :], w[None, :])))


def herschel_bulkley_bootstrap(rate, stress, n_boot=2000, confidence=0.95, rng=None):
    """Herschel–Bulkley fit of the mean flow curve of several seeds, with bootstrap intervals.

    The point fit is :func:`herschel_bulkley_fit` (unit weights) of the per-rate means over the
    seeds, NaN entries (failed runs) left out of the mean; a rate with no finite entry is left out
    of the fit.  In each of ``n_boot`` replicates the seeds (columns, i.e. whole flow curves) are
    resampled with replacement, the means and the fit are recomputed; the interval of each
    parameter is the ``(1 ± confidence)/2`` percentiles of the replicates that could be fitted (a
    replicate with fewer than 3 rates left, or without K > 0, is left out).  The intervals are
    plain percentile intervals, which undercover slightly for few seeds (the spread of a bootstrap
    mean of s seeds is √((s−1)/s) times the standard error).

    Parameters
    ----------
    rate : array_like
        Shear rate γ̇ of each row (1/s), finite, > 0, shape (n_rates,).
    stress : array_like
        Shear stress (Pa), shape (n_rates, n_seeds): column j is the flow curve of seed j; NaN
        marks a failed run, other values are finite.
    n_boot : int, optional
        Number of bootstrap replicates, >= 1 (default 2000).
    confidence : float, optional
        Level of the intervals, in (0, 1) (default 0.95).
    rng : None, int or numpy.random.Generator, optional
        Source of the resampling: None (fresh entropy), an integer seed >= 0 (reproducible), or a
        Generator (used, and advanced, as is).

    Returns
    -------
    FlowCurveFit

    Raises
    ------
    ValueError
        Naming the parameter, its value and the allowed range: ``rate`` not 1-D, non-finite or
        <= 0, ``stress`` not of shape (n_rates, n_seeds) or with ±inf, fewer than 3 distinct rates
        with a finite stress, a mean stress that does not increase with the rate, ``n_boot`` not
        an integer >= 1, ``confidence`` not in (0, 1), ``rng`` of another kind.

    Examples
    --------
    >>> import numpy as np
    >>> rate = np.logspace(-1, 2, 6)
    >>> noise = 1 + 0.05 * np.random.default_rng(0).standard_normal((6, 8))
    >>> res = herschel_bulkley_bootstrap(rate, (3.0 + rate ** 0.6)[:, None] * noise, n_boot=200, rng=1)
    >>> lo, hi = res.intervals["sigma_y"]
    >>> bool(lo <= res.yield_stress <= hi)
    True
    """
    r = _check_rates(rate)
    try:
        S = np.asarray(stress, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"stress is invalid: allowed a 2-D table of real numbers, got {type(stress).__name__}") \
            from None
    if S.ndim != 2 or S.shape[0] != len(r) or S.shape[1] < 1:
        raise ValueError(f"stress is invalid: allowed shape (n_rates, n_seeds) = ({len(r)}, >= 1), got shape "
                         f"{S.shape}")
    if np.isinf(S).any():
        i, j = np.argwhere(np.isinf(S))[0]
        raise ValueError(f"stress[{i}, {j}]={float(S[i, j])!r} is out of range: allowed finite numbers or NaN "
                         "(a failed run)")
    n_boot, confidence, gen = _check_resampling(n_boot, confidence, rng)
    present = np.isfinite(S).any(axis=1)
    distinct = len(np.unique(r[present]))
    if distinct < 3:
        raise ValueError(f"stress is out of range: {distinct} distinct rate(s) with a finite stress, allowed at "
                         "least 3")
    n_seeds = S.shape[1]
    if n_seeds == 1:
        warnings.warn("herschel_bulkley_bootstrap: one seed only: the bootstrap intervals have zero width",
                      UserWarning, stacklevel=2)
    point = _result(*(v[0] for v in _fit_rows(r, *_means(S[None]))))
    cols = gen.integers(0, n_seeds, size=(n_boot, n_seeds))
    reps = np.stack(_fit_rows(r, *_means(S[:, cols].transpose(1, 0, 2)))[:3], axis=1)   # (n_boot, 3)
    reps[~(reps[:, 1] > 0)] = np.nan                  # K = 0: no Herschel-Bulkley law (as the point fit)
    ci, _ = _percentile_interval(reps, confidence)
    intervals = {name: (float(ci[i, 0]), float(ci[i, 1])) for i, name in enumerate(_PARAMETERS)}
    return FlowCurveFit(fit=point, intervals=types.MappingProxyType(intervals), n_boot=n_boot,
                        confidence=confidence, n_seeds=n_seeds)


def _means(T):
    """Per-rate NaN-means of the tables ``T`` (B, n_rates, n_seeds) and their weights (1 where a
    mean exists, 0 where a rate has no finite entry, the mean there set to 0)."""
    finite = np.isfinite(T)
    count = finite.sum(axis=2)
    total = np.where(finite, T, 0.0).sum(axis=2)
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = np.where(count > 0, total / count, 0.0)
    return mean, (count > 0).astype(float)


def _records(results):
    """The rows of a results table: a pandas DataFrame (``load_results``) or a sequence of dicts."""
    if hasattr(results, "to_dict") and hasattr(results, "columns"):
        return results.to_dict("records")
    try:
        rows = list(results)
    except TypeError as exc:
        raise ValueError("results is invalid: a results table (load_results(DIR)) or a list of row dicts") from exc
    if not all(isinstance(r, dict) for r in rows):
        raise ValueError("results is invalid: a results table (load_results(DIR)) or a list of row dicts")
    return rows


def flow_curve_table(results, estimator="surface"):
    """The flow curve of a steady-shear sweep's table: rates and the stresses of each repetition.

    Rows of protocol "steady" are grouped by ``relative_rate`` (ascending); column j holds the
    steady stress of repetition j (NaN for a failed or missing run).  Every rate's rows must
    share one ``strain_rate`` in 1/s (one material: filter a table of several first).

    Parameters
    ----------
    results : pandas.DataFrame or sequence of dict
        A sweep's results table (:func:`particleShear.sweep.schema.load_results`, ``run_sweep``'s rows).
    estimator : {"surface", "internal"}, default "surface"
        Which stress: the plate-band estimator or the overall tensor's (docs/protocols.md).

    Returns
    -------
    rate : numpy.ndarray, shape (n_rates,)
        Shear rates γ̇ in 1/s.
    stress : numpy.ndarray, shape (n_rates, n_repetitions)
        Steady shear stresses in Pa, NaN where a run failed or is missing.

    Raises
    ------
    ValueError
        A bad ``estimator``, no steady rows, or one relative rate with two different rates in 1/s.
    """
    if estimator not in ("surface", "internal"):
        raise ValueError(f"estimator={estimator!r} is invalid: allowed 'surface', 'internal'")
    rows = [r for r in _records(results) if r.get("protocol") == "steady"]
    if not rows:
        raise ValueError("results has no rows of protocol 'steady': a flow curve needs a steady-shear sweep")
    rates, reps = {}, set()
    for r in rows:
        rel, rep = float(r["relative_rate"]), int(r.get("repetition") or 0)
        reps.add(rep)
        ok = r.get("status") == "ok" and r.get(f"stress_{estimator}") is not None
        if ok:
            g = float(r["strain_rate"])
            if rates.setdefault(rel, {}).setdefault("rate", g) != g:
                raise ValueError(f"results mixes materials: relative_rate={rel} is {rates[rel]['rate']} and {g} 1/s; "
                                 "select the rows of one material first")
            rates[rel][rep] = float(r[f"stress_{estimator}"])
        else:
            rates.setdefault(rel, {})
    order = sorted(k for k in rates if "rate" in rates[k])
    if not order:
        raise ValueError("results has no finished steady run")
    columns = sorted(reps)
    stress = np.array([[rates[k].get(j, np.nan) for j in columns] for k in order], dtype=float)
    return np.array([rates[k]["rate"] for k in order]), stress


def fit_flow_curve(results, estimator="surface", n_boot=2000, confidence=0.95, rng=None):
    """Herschel–Bulkley fit of a steady-shear sweep's flow curve with bootstrap intervals over seeds.

    :func:`herschel_bulkley_bootstrap` of :func:`flow_curve_table`; the yield stress it implies
    is ``fit.fit.sigma_y`` with the interval ``fit.intervals["sigma_y"]``.

    Parameters
    ----------
    results : pandas.DataFrame or sequence of dict
        A steady-shear sweep's results table (a grid over ``relative_rate``, repetitions as seeds).
    estimator : {"surface", "internal"}, default "surface"
        Which stress (see :func:`flow_curve_table`).
    n_boot, confidence, rng
        As :func:`herschel_bulkley_bootstrap`.

    Returns
    -------
    FlowCurveFit
    """
    rate, stress = flow_curve_table(results, estimator)
    return herschel_bulkley_bootstrap(rate, stress, n_boot=n_boot, confidence=confidence, rng=rng)
