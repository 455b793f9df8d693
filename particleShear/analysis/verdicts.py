"""Verdicts: does each reported number mean what its name says? (docs/analysis.md, "Verdicts").

Every run reports, beside its numbers, a set of checks — typed boolean columns of the results
table, True when the check passes, False when it fails, empty (None) when the run cannot be judged
— and a ``verdict``: ``"ok"`` when no check fails, else ``"flagged: name, name"``.  A flagged
number is kept (and drawn, marked) but must not be reported as what its name claims.

Each rule and threshold is stated here once (:data:`CHECKS`); the thresholds were chosen from the
spread of the model's own runs over seeds (``benchmarks/verdict_thresholds.py`` reproduces the
figures quoted in docs/analysis.md):

oscillatory runs and the steps of a one-packing sweep
    ``steady_state`` (no period-to-period drift, :mod:`particleShear.analysis.periods`);
    ``linear_response`` (I₃/I₁ of the internal stress ≤ :data:`LINEAR_I3_I1`);
    ``estimators_agree`` (surface and internal G′, G″ differ by ≤ :data:`AGREEMENT_TOLERANCE` of
    the larger |G*|); ``moduli_positive`` (G′, G″ ≥ 0 in both estimators); ``excitation_resolved``
    (the stress amplitude |G*|·γ₀ is ≥ :data:`SIGNAL_TO_NOISE_MIN` times the baseline noise).
steady
    ``plateau_reached`` (no significant, relevant trend of the stress over the last
    :data:`PLATEAU_FRACTION` of the record); ``strain_sufficient`` (total strain ≥
    :data:`STEADY_MIN_STRAIN`).
creep
    ``stress_held`` (|stress_tracking| ≤ :data:`CREEP_TRACKING_TOLERANCE`); ``rate_unsaturated``
    (the controller never sat at its rate limit in the second half of the hold); ``hold_sufficient``
    (hold ≥ :data:`CREEP_MIN_RESPONSE_TIMES` response times).
relaxation
    ``plateau_reached`` (as steady, on G(t)); ``strain_above_noise`` (the stress the step adds,
    γ₀·|G_plateau|, is ≥ :data:`RELAXATION_SIGNAL_MIN` times the residual stress the packing
    drifts from).
"""
__docformat__ = "numpy"
import math

import numpy as np

from ..protocols import PROTOCOLS
from .periods import t_critical
from .rheometry import final_rate, plateau as plateau_mean

__all__ = ["CHECKS", "PROTOCOL_CHECKS", "VERDICT_COLUMNS", "LINEAR_I3_I1", "AGREEMENT_TOLERANCE",
           "SIGNAL_TO_NOISE_MIN", "PLATEAU_FRACTION", "PLATEAU_RELATIVE_CHANGE", "PLATEAU_FALSE_ALARM",
           "STEADY_MIN_STRAIN", "CREEP_TRACKING_TOLERANCE", "CREEP_MIN_RESPONSE_TIMES", "RATE_LIMIT_FRACTION",
           "RELAXATION_SIGNAL_MIN", "verdict", "failed_checks", "baseline_noise", "oscillatory_checks",
           "plateau_check", "steady_checks", "creep_checks", "relaxation_checks", "verdict_lines", "is_flagged",
           "verdict_counts", "counts_note", "agreement_spread", "signal_to_noise"]

#: largest I₃/I₁ (internal stress) of a linear response: the default scene gives 0.01–0.07 over seeds
#: at γ₀ = 0.01 and 0.2 (noise and slip events), 0.04–0.18 at γ₀ = 1.  A weak test: in this model G′
#: falls with γ₀ well before the third harmonic grows (G′ at γ₀ = 0.2 is ≈ 30 % below its value at
#: 0.01), so it flags strongly nonlinear runs only; the linear range is an amplitude sweep's
#: (docs/analysis.md)
LINEAR_I3_I1 = 0.1
#: largest max(|ΔG′|, |ΔG″|) / max(|G*_surface|, |G*_internal|) of agreeing estimators: the default
#: scene gives 0.04–0.16 over seeds (the estimators measure different volumes), N = 50 at
#: f·τ = 0.1 gives 0.29–0.73
AGREEMENT_TOLERANCE = 0.25
#: smallest |G*|·γ₀ / (baseline noise) of a resolved excitation, each estimator: the default scene
#: gives 8–2,800 over seeds at γ₀ = 0.01 and 360–3,800 at 0.2; at γ₀ = 1e-9 the packings that are
#: quiet enough (up to 450) give moduli whose estimators agree, the others 0.15–0.9
SIGNAL_TO_NOISE_MIN = 3.0
#: the final part of a steady or relaxation record tested for a plateau (the part
#: :func:`~particleShear.analysis.rheometry.plateau` averages)
PLATEAU_FRACTION = 0.2
#: a trend over the plateau window smaller than this fraction of its mean is no failure, however
#: significant (a 5 % drift is within the spread of the model's runs over seeds)
PLATEAU_RELATIVE_CHANGE = 0.05
#: two-sided probability that a window without trend fails the plateau test
PLATEAU_FALSE_ALARM = 0.01
#: smallest total strain of a steady run: a flow curve needs the packing sheared past its
#: rearrangements, ≳ 1 (docs/protocols.md)
STEADY_MIN_STRAIN = 1.0
#: largest |mean plate stress over the second half of the hold − σ₀| / σ₀ of a held creep stress
CREEP_TRACKING_TOLERANCE = 0.1
#: fewest controller response times in a creep hold: the controller's error decays as
#: exp(−t/T), e⁻¹⁰ after 10 T
CREEP_MIN_RESPONSE_TIMES = 10.0
#: a creep rate at or above this fraction of the controller's rate limit is saturated
RATE_LIMIT_FRACTION = 0.99
#: smallest γ₀·|G_plateau| / |σ_res| of a resolved step strain: the packing's residual stress
#: σ_res drifts during the hold by a fraction of itself; at γ₀ = 1e-4 (added stress ≈ 0.02 σ_res)
#: the surface plateau is already 2.4× off the internal one
RELAXATION_SIGNAL_MIN = 0.5

#: check → (protocols, rule) — the rule as docs/analysis.md states it
CHECKS = {
    "steady_state": ("oscillatory", "no modulus drifts from period to period beyond its error (≥ 3 measured "
                                    "periods)"),
    "linear_response": ("oscillatory", f"I3/I1 of the internal stress <= {LINEAR_I3_I1}"),
    "estimators_agree": ("oscillatory", f"surface and internal G′, G″ differ by <= {AGREEMENT_TOLERANCE:.0%} of "
                                        "the larger |G*|"),
    "moduli_positive": ("oscillatory", "G′ >= 0 and G″ >= 0 in both estimators"),
    "excitation_resolved": ("oscillatory", f"stress amplitude |G*|·γ0 >= {SIGNAL_TO_NOISE_MIN:g} × the baseline "
                                           "noise (pre_periods > 0)"),
    "plateau_reached": ("steady, relaxation", f"no trend over the last {PLATEAU_FRACTION:.0%} of the record "
                                              f"that is both significant ({1 - PLATEAU_FALSE_ALARM:.0%}) and "
                                              f"> {PLATEAU_RELATIVE_CHANGE:.0%} of its mean"),
    "strain_sufficient": ("steady", f"total strain >= {STEADY_MIN_STRAIN:g}"),
    "stress_held": ("creep", f"|stress_tracking| <= {CREEP_TRACKING_TOLERANCE}"),
    "rate_unsaturated": ("creep", f"the strain rate stays below {RATE_LIMIT_FRACTION:.0%} of the controller's "
                                  "limit over the second half of the hold"),
    "hold_sufficient": ("creep", f"hold_time >= {CREEP_MIN_RESPONSE_TIMES:g} × creep_response_time"),
    "strain_above_noise": ("relaxation", f"γ0·|G_plateau| >= {RELAXATION_SIGNAL_MIN:g} × |residual_stress| "
                                         "(both estimators)"),
}
#: protocol → its checks, in table order (each protocol's ``checks``, :mod:`particleShear.protocols`)
PROTOCOL_CHECKS = {name: tuple(p.checks) for name, p in PROTOCOLS.items()}
#: the results-table columns of the verdicts: every check (bool, nullable), then ``verdict`` (string)
VERDICT_COLUMNS = tuple(CHECKS) + ("verdict",)


def _judged(x):
    """A check's value as the table holds it: True, False or None."""
    return None if x is None else bool(x)


def failed_checks(checks):
    """The names of the checks that failed (False), in the order given.

    Parameters
    ----------
    checks : dict
        Check name → True, False or None.

    Returns
    -------
    list of str
    """
    return [k for k, v in checks.items() if v is False]


def verdict(checks):
    """``"ok"`` when no check failed, else ``"flagged: a, b"`` naming the failed ones.

    Checks that could not be judged (None) do not flag a run: :func:`verdict_lines` names them.

    Parameters
    ----------
    checks : dict
        Check name → True, False or None.

    Returns
    -------
    str
    """
    bad = failed_checks(checks)
    return "flagged: " + ", ".join(bad) if bad else "ok"


def verdict_lines(row, protocol="oscillatory"):
    """The verdict of a run as text: ``verdict: ok`` or ``verdict: flagged: a, b``, then one line per
    failed check and per check that could not be judged, each with its rule.

    Parameters
    ----------
    row : dict
        A results row, a run's measures or a protocol summary holding the check columns.
    protocol : str, default "oscillatory"
        Which checks (:data:`PROTOCOL_CHECKS`).

    Returns
    -------
    list of str
    """
    names = PROTOCOL_CHECKS.get(protocol, ())
    checks = {n: row.get(n) for n in names}
    out = [f"verdict: {verdict(checks)}"]
    for name in names:
        if checks[name] is False:
            out.append(f"  failed {name}: needs {CHECKS[name][1]}")
    for name in names:
        if checks[name] is None:
            out.append(f"  not judged {name}: {CHECKS[name][1]}")
    return out


def baseline_noise(t, stress, f, pre_periods):
    """Root-mean-square fluctuation (Pa) of the stress about its linear trend before the excitation.

    The baseline is the ``"pre"`` phase, ``t < pre_periods/f``, where the strain is zero: what the
    stress does there is what the packing does without the excitation.

    Parameters
    ----------
    t, stress : array_like
        Sample times since the start of the protocol (s) and stress (Pa).
    f : float
        Excitation frequency (Hz).
    pre_periods : float
        Baseline periods.

    Returns
    -------
    float
        NaN with fewer than 8 baseline samples.
    """
    t = np.asarray(t, dtype=float)
    x = np.asarray(stress, dtype=float)
    pre = t < float(pre_periods) / float(f)
    if int(pre.sum()) < 8:
        return math.nan
    tt, xx = t[pre], x[pre]
    if not (np.all(np.isfinite(xx)) and tt[-1] > tt[0]):
        return math.nan
    fit = np.polyfit(tt - tt[0], xx, 1)
    res = xx - np.polyval(fit, tt - tt[0])
    return float(math.sqrt(float(res @ res) / (len(res) - 2)))


def oscillatory_checks(moduli, measures, strain_amplitude, noise):
    """The checks of an oscillatory run or sweep step (module docstring; True pass, None unjudged).

    Parameters
    ----------
    moduli : dict
        Estimator ("surface", "internal") → (G′, G″) in Pa; an estimator absent when not recorded.
    measures : dict
        The run's measures (``steady_state``, ``I3_I1_internal``, ``I3_I1_surface``).
    strain_amplitude : float
        γ₀.
    noise : dict
        Estimator → :func:`baseline_noise` (Pa; NaN when there is no baseline).

    Returns
    -------
    dict
        :data:`PROTOCOL_CHECKS` ["oscillatory"] → True, False or None.
    """
    g = _finite_moduli(moduli)
    out = {"steady_state": _judged(measures.get("steady_state"))}
    ratio = measures.get("I3_I1_internal")
    if ratio is None or not math.isfinite(ratio):
        ratio = measures.get("I3_I1_surface")
    out["linear_response"] = None if ratio is None or not math.isfinite(ratio) else bool(ratio <= LINEAR_I3_I1)
    spread = agreement_spread(g)
    out["estimators_agree"] = None if not math.isfinite(spread) else bool(spread <= AGREEMENT_TOLERANCE)
    out["moduli_positive"] = bool(all(a >= 0 and b >= 0 for a, b in g.values())) if g else None
    snr = signal_to_noise(g, strain_amplitude, noise)
    out["excitation_resolved"] = None if math.isnan(snr) else bool(snr >= SIGNAL_TO_NOISE_MIN)
    return out


def _finite_moduli(moduli):
    return {e: (float(a), float(b)) for e, (a, b) in moduli.items()
            if a is not None and b is not None and math.isfinite(a) and math.isfinite(b)}


def agreement_spread(moduli):
    """max(|G′_s − G′_i|, |G″_s − G″_i|) / max(|G*_s|, |G*_i|), the quantity ``estimators_agree`` bounds.

    Parameters
    ----------
    moduli : dict
        "surface" and "internal" → (G′, G″) in Pa.

    Returns
    -------
    float
        Dimensionless; NaN unless both estimators have finite moduli, not both zero.
    """
    g = _finite_moduli(moduli)
    if len(g) < 2 or "surface" not in g or "internal" not in g:
        return math.nan
    (a1, b1), (a2, b2) = g["surface"], g["internal"]
    scale = max(math.hypot(a1, b1), math.hypot(a2, b2))
    return max(abs(a1 - a2), abs(b1 - b2)) / scale if scale > 0 else math.nan


def signal_to_noise(moduli, strain_amplitude, noise):
    """The smaller over the estimators of |G*|·γ₀ / baseline noise, the quantity ``excitation_resolved`` bounds.

    Parameters
    ----------
    moduli : dict
        Estimator → (G′, G″) in Pa.
    strain_amplitude : float
        γ₀.
    noise : dict
        Estimator → :func:`baseline_noise` (Pa).

    Returns
    -------
    float
        Dimensionless; inf for a noiseless baseline, NaN when no estimator has a baseline.
    """
    snr = []
    for est, (a, b) in _finite_moduli(moduli).items():
        n = noise.get(est, math.nan)
        if n is not None and math.isfinite(n):
            snr.append(math.hypot(a, b) * float(strain_amplitude) / n if n > 0 else math.inf)
    return min(snr) if snr else math.nan


def plateau_check(t, y, fraction=PLATEAU_FRACTION):
    """True when ``y`` has no trend over the last ``fraction`` of the record that is both significant
    and larger than :data:`PLATEAU_RELATIVE_CHANGE` of its mean; None when it cannot be judged.

    The trend is the least-squares change across the window, its error the spread of the slopes of
    5 contiguous parts (:func:`~particleShear.analysis.rheometry.final_rate`, an error that holds for
    correlated noise); significant when |change| > t_c·error, t_c Student's t with 4 degrees of
    freedom at :data:`PLATEAU_FALSE_ALARM`.

    Parameters
    ----------
    t, y : array_like
        Times (s) or strains, and the values.
    fraction : float, default :data:`PLATEAU_FRACTION`
        The window, the last part of the span.

    Returns
    -------
    bool or None
        None for fewer than 10 finite samples in the window.
    """
    t = np.asarray(t, dtype=float)
    y = np.asarray(y, dtype=float)
    ok = np.isfinite(t) & np.isfinite(y)
    t, y = t[ok], y[ok]
    if len(t) < 2 or not t[-1] > t[0]:
        return None
    w = t >= t[-1] - fraction * (t[-1] - t[0])
    if int(w.sum()) < 10:
        return None
    slope, se = final_rate(t, y, fraction)
    if not math.isfinite(slope):
        return None
    span = float(t[w][-1] - t[w][0])
    change = abs(slope) * span
    relevant = change > PLATEAU_RELATIVE_CHANGE * abs(float(np.mean(y[w])))
    significant = not math.isfinite(se) or change > t_critical(4, PLATEAU_FALSE_ALARM) * se * span
    return not (relevant and significant)


def steady_checks(t, stress, total_strain):
    """The checks of a steady-shear run.

    Parameters
    ----------
    t : array_like
        Sample times (s).
    stress : dict
        Estimator → the shear stress record (Pa).
    total_strain : float
        The run's total strain.

    Returns
    -------
    dict
        ``plateau_reached`` (every estimator), ``strain_sufficient``.
    """
    flags = [plateau_check(t, s) for s in stress.values()]
    plateau = None if any(f is None for f in flags) or not flags else all(flags)
    return {"plateau_reached": plateau, "strain_sufficient": bool(float(total_strain) >= STEADY_MIN_STRAIN)}


def creep_checks(t, strain_rate, stress_tracking, rate_limit, hold_time, response_time):
    """The checks of a creep run.

    Parameters
    ----------
    t : array_like
        Sample times (s).
    strain_rate : array_like
        The controller's strain rate (1/s).
    stress_tracking : float
        (mean plate stress over the second half − σ₀)/σ₀.
    rate_limit : float
        The controller's largest strain rate (1/s).
    hold_time, response_time : float
        The hold and the controller's response time (any one unit).

    Returns
    -------
    dict
        ``stress_held``, ``rate_unsaturated``, ``hold_sufficient``.
    """
    t = np.asarray(t, dtype=float)
    r = np.abs(np.asarray(strain_rate, dtype=float))
    half = t >= t[-1] / 2 if len(t) else np.zeros(0, bool)
    held = None if stress_tracking is None or not math.isfinite(stress_tracking) else \
        bool(abs(stress_tracking) <= CREEP_TRACKING_TOLERANCE)
    unsat = None if not half.any() or not math.isfinite(rate_limit) else \
        bool(np.all(r[half] < RATE_LIMIT_FRACTION * rate_limit))
    return {"stress_held": held, "rate_unsaturated": unsat,
            "hold_sufficient": bool(float(hold_time) >= CREEP_MIN_RESPONSE_TIMES * float(response_time))}


def relaxation_checks(t_hold, G, strain, residual_stress):
    """The checks of a stress-relaxation run.

    Parameters
    ----------
    t_hold : array_like
        Times since the end of the ramp (s).
    G : dict
        Estimator → G(t) = (σ(t) − σ_res)/γ₀ over the hold (Pa).
    strain : float
        The step strain γ₀.
    residual_stress : dict
        Estimator → σ_res (Pa), its stress at rest before the step.

    Returns
    -------
    dict
        ``plateau_reached`` (every estimator), ``strain_above_noise`` (every estimator).
    """
    flags = [plateau_check(t_hold, g) for g in G.values()]
    plat = None if any(f is None for f in flags) or not flags else all(flags)
    above = []
    for est, g in G.items():
        g = np.asarray(g, dtype=float)
        if len(g) < 2 or not np.all(np.isfinite(g)):
            above.append(None)
            continue
        added = abs(float(strain) * plateau_mean(t_hold, g).mean)
        above.append(bool(added >= RELAXATION_SIGNAL_MIN * abs(float(residual_stress[est]))))
    noise = None if any(a is None for a in above) or not above else all(above)
    return {"plateau_reached": plat, "strain_above_noise": noise}


def is_flagged(row):
    """True when a results row's ``verdict`` cell says ``flagged`` (text or value; an old table
    without the column is never flagged).

    Parameters
    ----------
    row : dict

    Returns
    -------
    bool
    """
    return str(row.get("verdict") or "").strip().startswith("flagged")


def verdict_counts(rows):
    """How many rows failed to run, how many ran but are flagged, and by which checks.

    Parameters
    ----------
    rows : iterable of dict
        Results rows (text or typed cells).

    Returns
    -------
    n_failed : int
        Rows whose status is not "ok".
    n_flagged : int
        Rows with status "ok" whose verdict is flagged.
    by_check : dict
        Check name → number of flagged rows that failed it (most frequent first).
    """
    n_failed = n_flagged = 0
    by_check = {}
    for row in rows:
        if str(row.get("status", "")).strip() != "ok":
            n_failed += 1
        elif is_flagged(row):
            n_flagged += 1
            for name in str(row["verdict"]).split(":", 1)[1].split(","):
                if name.strip():
                    by_check[name.strip()] = by_check.get(name.strip(), 0) + 1
    return n_failed, n_flagged, dict(sorted(by_check.items(), key=lambda kv: (-kv[1], kv[0])))


def counts_note(n_runs, n_failed, n_flagged, by_check):
    """The note of a group's counts: ``"2 of 12 run(s) flagged (estimators_agree 2); 1 run(s) failed"``, or "".

    Parameters
    ----------
    n_runs : int
        The group's runs that count.
    n_failed, n_flagged : int
        Its failed and flagged runs (:func:`verdict_counts`).
    by_check : dict
        Check name → flagged runs that failed it.

    Returns
    -------
    str
    """
    parts = []
    if n_flagged:
        parts.append(f"{n_flagged} of {n_runs} run(s) flagged ("
                     + ", ".join(f"{k} {v}" for k, v in by_check.items()) + ")")
    if n_failed:
        parts.append(f"{n_failed} run(s) failed")
    return "; ".join(parts)
